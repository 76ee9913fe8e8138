//! Friction, one constraint per manifold: a 2D Coulomb friction at the manifold's centre
//! and a twist friction about the normal (the "simplified" model that rapier uses by
//! default).
//!
//! At the centre c, with lever arms r_a, r_b and tangents t₀ ⊥ t₁, the tangent impulse
//! λ ∈ ℝ² solves K Δλ = −(t·v_rel) with the full 2×2 effective mass
//!
//! ```text
//! K_ij = (1/m_a + 1/m_b) δ_ij + (r_a×t_i)·I_a⁻¹(r_a×t_j) + (r_b×t_i)·I_b⁻¹(r_b×t_j)
//! ```
//!
//! (its off-diagonal lever terms couple the two directions; solving them one at a time
//! leaves a residual that turns from pass to pass), then |λ| ≤ μ Σλ_n. The twist impulse τ
//! about n takes m_τ = 1/(n·I_a⁻¹n + n·I_b⁻¹n) and |τ| ≤ μ ρ Σλ_n, with ρ the points' mean
//! distance from the centre. One friction per manifold instead of one per point: a quarter
//! of the work, and the same limit for a sliding face (μ times the total normal force).

use glam::Vec3A;

use super::side::{LinearMass, Side};
use super::{Axis, Batch, F4, M3, ManifoldConstraint, V3};

/// The friction of four manifolds (one per lane).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Friction {
    r_a: V3,
    r_b: V3,
    /// I⁻¹(r × t) of each side, per tangent (the masses are in `k_inv`).
    tangent: [Axis; 2],
    /// K⁻¹ = [[k_inv[0], k_inv[1]], [k_inv[1], k_inv[2]]].
    k_inv: [F4; 3],
    /// I⁻¹ n of each side, and the twist mass.
    twist: Axis,
    radius: F4,
    imp: [F4; 2],
    twist_imp: F4,
    /// The relative tangential velocity aimed for, per tangent (zero but on a conveyor).
    target: [F4; 2],
}

impl Friction {
    /// The lanes' lever arms, radii and warm-start impulses (masses come with
    /// [`Self::compute`]); their surface velocities when some manifold of the step has one
    /// (`edited`).
    pub fn new(manifolds: &[ManifoldConstraint], chunk: &[u32], edited: bool) -> Self {
        let lane = |l: usize| chunk.get(l).map(|&mi| &manifolds[mi as usize]);
        let vector = |f: fn(&ManifoldConstraint) -> Vec3A| {
            V3::from_lanes(std::array::from_fn(|l| lane(l).map_or(Vec3A::ZERO, f)))
        };
        let scalar = |f: fn(&ManifoldConstraint) -> f32| {
            F4::new(std::array::from_fn(|l| lane(l).map_or(0.0, f)))
        };
        Self {
            r_a: vector(|m| m.centre_a),
            r_b: vector(|m| m.centre_b),
            radius: scalar(|m| m.radius),
            imp: [scalar(|m| m.t_imp[0]), scalar(|m| m.t_imp[1])],
            twist_imp: scalar(|m| m.twist),
            target: match edited {
                true => [scalar(|m| m.surface[0]), scalar(|m| m.surface[1])],
                false => [F4::ZERO; 2],
            },
            ..Self::default()
        }
    }

    /// Effective masses from the sides' inverse masses and inertias; `live` is all-ones in
    /// lanes that hold a manifold.
    pub fn compute<M: LinearMass>(
        &mut self,
        batch: &Batch,
        (ma, ia): (M, &M3),
        (mb, ib): (M, &M3),
        live: F4,
    ) {
        let axis = |d: V3| Axis::new(ma, ia, self.r_a, mb, ib, self.r_b, d, live);
        self.tangent = [axis(batch.t[0]), axis(batch.t[1])];
        let rd = |t: V3| (self.r_a.cross(t), self.r_b.cross(t));
        let ((a0, b0), (a1, b1)) = (rd(batch.t[0]), rd(batch.t[1]));
        let [t0, t1] = &self.tangent;
        let [d0, d1] = batch.t;
        let k00 = ma.along(d0) + mb.along(d0) + a0.dot(t0.ird_a) + b0.dot(t0.ird_b);
        let k11 = ma.along(d1) + mb.along(d1) + a1.dot(t1.ird_a) + b1.dot(t1.ird_b);
        // The tangents are orthogonal: their linear terms couple only through a locked axis.
        let k01 = a0.dot(t1.ird_a) + b0.dot(t1.ird_b) + (ma.across(d0, d1) + mb.across(d0, d1));
        let (k00, k11, k01) = if M::LOCKS {
            // A tangent that locks keep both sides from moving along, or nearly (a planar
            // body sliding in its plane: the other tangent is the locked axis), is vacuous
            // (see `VACUOUS`): solved with a unit mass and uncoupled, it takes an impulse
            // that moves nothing, and the other tangent is solved alone. (A singular K left
            // the manifold without friction; a nearly singular one overflowed.)
            let floor = F4::splat(super::VACUOUS) * (ma.largest() + mb.largest());
            let (vacuous_0, vacuous_1) = (k00.simd_le(floor), k11.simd_le(floor));
            (
                vacuous_0.select(F4::ONE, k00),
                vacuous_1.select(F4::ONE, k11),
                (vacuous_0 | vacuous_1).select(F4::ZERO, k01),
            )
        } else {
            (k00, k11, k01)
        };
        let det = k00 * k11 - k01 * k01;
        let usable = det.simd_gt(F4::ZERO) & live;
        let inv = |x: F4| usable.select(x / det, F4::ZERO);
        self.k_inv = [inv(k11), inv(-k01), inv(k00)];
        let (na, nb) = (ia.mul_vec(batch.n), ib.mul_vec(batch.n));
        let k = batch.n.dot(na) + batch.n.dot(nb);
        let usable = k.simd_gt(F4::ZERO) & live;
        self.twist = Axis {
            ird_a: na,
            ird_b: nb,
            mass: usable.select(F4::ONE / k, F4::ZERO),
        };
    }

    /// Applies the accumulated impulses once.
    pub fn warm_start<M: LinearMass>(&self, batch: &Batch, a: &mut Side<M>, b: &mut Side<M>) {
        Side::push(a, b, batch.t[0], &self.tangent[0], self.imp[0]);
        Side::push(a, b, batch.t[1], &self.tangent[1], self.imp[1]);
        Self::turn(a, b, &self.twist, self.twist_imp);
    }

    /// One friction pass; `normal` is each lane's total normal impulse.
    pub fn solve<M: LinearMass>(
        &mut self,
        batch: &Batch,
        normal: F4,
        a: &mut Side<M>,
        b: &mut Side<M>,
    ) {
        let limit = batch.friction * normal;
        let rel = Side::relative(a, b, self.r_a, self.r_b);
        let dv = [
            batch.t[0].dot(rel) - self.target[0],
            batch.t[1].dot(rel) - self.target[1],
        ];
        let old = self.imp;
        let [k0, k1, k2] = self.k_inv;
        let new = [
            old[0] - (k0 * dv[0] + k1 * dv[1]),
            old[1] - (k1 * dv[0] + k2 * dv[1]),
        ];
        let len2 = new[0] * new[0] + new[1] * new[1];
        let scale = len2
            .simd_gt(limit * limit)
            .select(limit / len2.sqrt(), F4::ONE);
        self.imp = [new[0] * scale, new[1] * scale];
        Side::push(a, b, batch.t[0], &self.tangent[0], self.imp[0] - old[0]);
        Side::push(a, b, batch.t[1], &self.tangent[1], self.imp[1] - old[1]);

        let spin = batch.n.dot(b.w - a.w);
        let reach = self.radius * limit;
        let old = self.twist_imp;
        let new = (old - self.twist.mass * spin)
            .fast_max(-reach)
            .fast_min(reach);
        self.twist_imp = new;
        Self::turn(a, b, &self.twist, new - old);
    }

    /// A pure angular impulse τ about n: −τ to a, +τ to b.
    #[inline]
    fn turn<M>(a: &mut Side<M>, b: &mut Side<M>, twist: &Axis, tau: F4) {
        a.w -= tau * twist.ird_a;
        b.w += tau * twist.ird_b;
    }

    /// Lane `l`'s tangent impulses and twist impulse.
    pub fn lane(&self, l: usize) -> ([f32; 2], f32) {
        (
            [self.imp[0].to_array()[l], self.imp[1].to_array()[l]],
            self.twist_imp.to_array()[l],
        )
    }
}
