//! The impulses a step ends with, handed back to the narrow phase's manifolds so that the
//! next step starts warm.

use glam::Vec3A;

use super::{ContactSolver, ManifoldConstraint};
use crate::collision::narrow_phase::points::MAX_POINTS;

/// How many manifolds ahead [`ContactSolver::for_each_solved`] shows its caller.
const AHEAD: usize = 16;

/// One manifold's impulses, gathered from its batch's lane.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Solved {
    normals: [f32; MAX_POINTS],
    tangents: [f32; 2],
    twist: f32,
}

/// One manifold's impulses after the step (see [`ContactSolver::for_each_solved`]).
pub(crate) struct SolvedManifold<'a> {
    pub constraint: &'a ManifoldConstraint,
    /// (point index in the narrow phase's manifold, normal impulse); the first `count`.
    pub normals: [(u32, f32); MAX_POINTS],
    pub count: usize,
    /// The friction impulse at the manifold's centre (world frame, N·s).
    pub tangent: Vec3A,
    /// The twist impulse about the normal (N·m·s).
    pub twist: f32,
}

impl ContactSolver {
    /// Hands `f` each manifold's accumulated impulses, in the order of
    /// [`ContactSolver::manifolds`]: its constraint, the normal impulse of each solved point
    /// (by its index in the narrow phase's manifold), the friction impulse at its centre and
    /// the twist; and the pair slot of the manifold [`AHEAD`] places later, to start loading
    /// what `f` will write for it.
    ///
    /// Why two passes: the batches hold the manifolds in colour order, so reading the
    /// constraints and the narrow phase's manifolds from them jumps through memory for every
    /// lane. The lanes are first copied into a small array by manifold; the constraints, the
    /// point inputs and the pair table are then read in the order they were written, the
    /// broad phase's.
    pub fn for_each_solved(&mut self, mut f: impl FnMut(SolvedManifold<'_>, Option<u32>)) {
        self.solved.clear();
        self.solved.resize(self.manifolds.len(), Solved::default());
        for (batch, fr) in self.batches.iter().zip(&self.friction) {
            let points = &self.points[batch.first as usize..(batch.first + batch.count) as usize];
            for l in 0..4 {
                let Some(out) = self.solved.get_mut(batch.lanes[l] as usize) else {
                    continue;
                };
                for (n, p) in out.normals.iter_mut().zip(points) {
                    *n = p.n_imp.to_array()[l];
                }
                (out.tangents, out.twist) = fr.lane(l);
            }
        }
        for (i, (m, solved)) in self.manifolds.iter().zip(&self.solved).enumerate() {
            let inputs = &self.inputs[m.first as usize..(m.first + m.count) as usize];
            let mut normals = [(0, 0.0); MAX_POINTS];
            for ((slot, &n), input) in normals.iter_mut().zip(&solved.normals).zip(inputs) {
                *slot = (input.source, n);
            }
            let t = solved.tangents;
            let manifold = SolvedManifold {
                constraint: m,
                normals,
                count: inputs.len(),
                tangent: t[0] * m.t[0] + t[1] * m.t[1],
                twist: solved.twist,
            };
            f(manifold, self.manifolds.get(i + AHEAD).map(|m| m.pair));
        }
    }
}
