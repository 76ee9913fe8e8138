//! Restitution after the last substep (see [`ContactSolver::restitution`]).

use super::side::{LinearMass, Side};
use super::{Batch, ContactSolver, F4, Point, Track, work};

impl ContactSolver {
    /// After the last substep: contacts that hit faster than their threshold leave at −e times
    /// their approach speed (Newton's law), capped twice:
    /// - at the impulse that ends the compression plus e times the whole compression impulse
    ///   (Poisson's law): in a row of touching bodies the solve itself drives a contact that
    ///   was not hit, and bouncing it off its own push would create energy;
    /// - so that, over all points, the restitution gives back at most Σ e² times the kinetic
    ///   energy the step's normal impulses took out (and what the impact-speed extrapolation
    ///   adds to an impact). Impulses move energy between points (one
    ///   point of a row pushes what another stopped), so the budget is the step's, not each
    ///   point's; a point whose impulse would overdraw it is scaled down.
    pub fn restitution(&mut self) {
        let zero = F4::ZERO;
        let rest = self.rest();
        let Self {
            batches,
            points,
            tracks,
            states,
            lock_masses,
            ..
        } = self;
        // The budget: e² of the energy lost, and of what the impact-speed extrapolation adds
        // to an impact (the speed the substep's integration had not reached yet).
        let mut budget = 0.0f32;
        // A batch that does not bounce kept no record (see `Batch::bouncy`) and adds nothing.
        for batch in batches.iter().filter(|b| b.bouncy()) {
            let e2 = batch.restitution * batch.restitution;
            for t in &tracks[batch.tracks()] {
                let hit = t.approach.simd_lt(batch.threshold) & t.max_n.simd_gt(zero);
                let m = t
                    .half_w
                    .simd_gt(zero)
                    .select(F4::splat(0.25) / t.half_w, zero);
                let extra = m * t.gain;
                let extra = hit.select(extra.fast_max(zero), zero);
                budget += (e2 * (t.lost + extra)).reduce_add();
            }
        }
        for batch in batches.iter().filter(|b| b.bouncy()) {
            let range = batch.first as usize..(batch.first + batch.count) as usize;
            let (points, tracks) = (&mut points[range], &tracks[batch.tracks()]);
            if batch.locked == Batch::UNLOCKED {
                let sides = [
                    Self::load(states, batch.a, batch.inv_m_a),
                    Self::load(states, batch.b, batch.inv_m_b),
                ];
                bounce(batch, points, tracks, sides, states, &mut budget);
            } else {
                let [ma, mb] = lock_masses[batch.locked as usize];
                let sides = [
                    Self::load(states, batch.a, ma),
                    Self::load(states, batch.b, mb),
                ];
                bounce(batch, points, tracks, sides, states, &mut budget);
            }
            Self::settle_rest(states, rest);
        }
    }
}

/// One batch's restitution impulses, within what is left of the `budget`.
#[inline(always)]
fn bounce<M: LinearMass>(
    batch: &Batch,
    points: &mut [Point],
    tracks: &[Track],
    [mut a, mut b]: [Side<M>; 2],
    states: &mut [super::BodyState],
    budget: &mut f32,
) {
    let zero = F4::ZERO;
    let bouncy = batch.restitution.simd_gt(zero);
    for (p, t) in points.iter_mut().zip(tracks) {
        let hit = bouncy & t.approach.simd_lt(batch.threshold) & t.max_n.simd_gt(zero);
        if !hit.any() {
            continue;
        }
        let vn = batch.n.dot(Side::relative(&a, &b, p.r_a, p.r_b));
        let e = batch.restitution;
        // Poisson: the impulse still needed to end the compression (a soft contact may
        // not have stopped the approach by the step's end), then e times the whole
        // compression impulse.
        let finish = p.normal.mass * (-vn).fast_max(zero);
        let poisson = finish + e * (t.absorbed + finish);
        let wanted = (-p.normal.mass * (vn + e * t.approach)).fast_min(poisson);
        let total = hit.select((p.n_imp + wanted).fast_max(zero), p.n_imp);
        let mut imp = total - p.n_imp;
        // work(s λ) ≤ s work(λ) for s in [0, 1]: scaling by the budget's share keeps
        // the sum within it.
        let cost = work(imp, vn, t.half_w).reduce_add();
        imp *= F4::splat(budget_share(cost, *budget));
        *budget -= work(imp, vn, t.half_w).reduce_add();
        p.n_imp += imp;
        Side::push(&mut a, &mut b, batch.n, &p.normal, imp);
    }
    ContactSolver::store(states, batch.a, &a);
    ContactSolver::store(states, batch.b, &b);
}

/// How much of an impulse whose work is `cost` (J) the restitution may apply with `budget`
/// (J) left: all of it if it adds no more than the budget (or takes energy out), else the
/// share of it that spends what is left, none once the budget is spent.
///
/// Why the budget is clamped at zero first: it goes negative when the step's impulses added
/// energy (push-out), and `budget / cost` with both negative is more than one, which would
/// scale an impulse that takes a little energy out up to one that adds a lot.
#[must_use]
pub(super) fn budget_share(cost: f32, budget: f32) -> f32 {
    let left = budget.max(0.0);
    // Past the test, cost > left ≥ 0.
    if cost <= left { 1.0 } else { left / cost }
}
