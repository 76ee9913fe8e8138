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

/// Hands `f` each lane's manifold index and impulses, batch by batch (empty lanes left
/// out).
fn for_each_lane(
    batches: &[super::Batch],
    friction: &[super::friction::Friction],
    points: &[super::Point],
    mut f: impl FnMut(usize, Solved),
) {
    for (batch, fr) in batches.iter().zip(friction) {
        let points = &points[batch.first as usize..(batch.first + batch.count) as usize];
        for (l, &mi) in batch.lanes.iter().enumerate() {
            if mi == u32::MAX {
                continue;
            }
            let mut lane = Solved::default();
            for (n, p) in lane.normals.iter_mut().zip(points) {
                *n = p.n_imp.to_array()[l];
            }
            (lane.tangents, lane.twist) = fr.lane(l);
            f(mi as usize, lane);
        }
    }
}

impl ContactSolver {
    /// Adds this substep's impulses to each manifold's totals for the step (see
    /// [`crate::collision::ContactReport`]): called after each substep's last pass, only
    /// while some collider asks for reports.
    pub fn add_substep_totals(&mut self) {
        if self.totals.len() != self.manifolds.len() {
            self.totals.clear();
            self.totals.resize(self.manifolds.len(), Solved::default());
        }
        let Self {
            batches,
            friction,
            points,
            totals,
            ..
        } = self;
        for_each_lane(batches, friction, points, |mi, lane| {
            if let Some(out) = totals.get_mut(mi) {
                for (n, l) in out.normals.iter_mut().zip(&lane.normals) {
                    *n += l;
                }
                out.tangents[0] += lane.tangents[0];
                out.tangents[1] += lane.tangents[1];
                out.twist += lane.twist;
            }
        });
    }

    /// The step's total impulses of manifold `i` (see [`Self::add_substep_totals`]): the
    /// normal impulse of each of its points in the order of its inputs, and the friction
    /// impulse at its centre (world frame, on `b`); none when no totals were kept.
    #[must_use]
    pub fn step_totals(&self, i: usize) -> Option<([f32; MAX_POINTS], Vec3A)> {
        let (m, t) = (self.manifolds.get(i)?, self.totals.get(i)?);
        Some((t.normals, t.tangents[0] * m.t[0] + t.tangents[1] * m.t[1]))
    }

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
        let Self {
            batches,
            friction,
            points,
            solved,
            ..
        } = self;
        for_each_lane(batches, friction, points, |mi, lane| {
            if let Some(out) = solved.get_mut(mi) {
                *out = lane;
            }
        });
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
