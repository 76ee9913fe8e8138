//! Contact axes that follow a turning body's inertia.

use super::ContactSolver;

impl ContactSolver {
    /// What follows a gather: [`Self::freeze`] for each of `frozen` (bodies it found
    /// non-finite), and the axes of every batch touching a body whose inertia it turned
    /// formed again.
    ///
    /// The axes hold I⁻¹(r × d) and the effective masses, formed at the start of the step.
    /// A body that is not isotropic and turns within the step changes its world inertia:
    /// with the step's tensor kept, an impulse the solver meant for a light axis lands on
    /// what has become a heavy one, or the reverse. A thin rod (0.1 × 0.1 × 1.09 m)
    /// spinning at 50 rad/s about the vertical that landed at 15 m/s left with 340 times
    /// its energy. Box3D keeps ω and the step's tensor together, so its bodies do not
    /// precess within a step; hooke keeps the angular momentum, whose ω follows the turn,
    /// so the contact axes follow it too.
    pub fn after_gather(&mut self, frozen: &[u32]) {
        for &body in frozen {
            self.freeze(body);
        }
        if self.turned.is_empty() {
            return;
        }
        self.turned_mark.clear();
        self.turned_mark.resize(self.bodies.len() + 1, false);
        for &i in &self.turned {
            self.turned_mark[i as usize] = true;
        }
        self.turned.clear();
        let marked = |mark: &[bool], ix: [u32; 4]| {
            ix.iter()
                .any(|&i| mark.get(i as usize).copied().unwrap_or(false))
        };
        for bi in 0..self.batches.len() {
            let batch = &self.batches[bi];
            if marked(&self.turned_mark, batch.a) || marked(&self.turned_mark, batch.b) {
                self.compute_axes(bi);
            }
        }
    }
}
