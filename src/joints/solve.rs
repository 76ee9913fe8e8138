//! A joint's sides, geometry and accumulated impulses during a pass, and its warm start (the
//! rows and their solve are in [`super::block`]).
//!
//! With lever arms r_a, r_b from the centres of mass to the anchors (world frame), the
//! point rows keep Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a at zero. The angular rows keep the
//! chosen components of ω_b − ω_a at zero: both perpendiculars of the hinge axis for a hinge,
//! all three for a weld. A biased pass solves λ = −S_m K⁻¹ (Ċ + β C) − S_i λ_acc (the soft
//! step's coefficients, see [`crate::collision::solver::Softness`]); a relax pass
//! λ = −K⁻¹ Ċ.

use glam::{Mat3A, Quat, Vec3, Vec3A};

use crate::collision::solver::Softness;

/// One side of a joint during a pass.
#[derive(Debug, Clone, Copy)]
pub(super) struct Side {
    pub x: Vec3A,
    pub q: Quat,
    pub v: Vec3A,
    pub w: Vec3A,
    pub inv_m: f32,
    pub inv_i: Mat3A,
    /// The angular impulse the pass gave it (N·m·s): L += this.
    pub dl: Vec3A,
    /// It takes impulses (a dynamic body awake).
    pub moves: bool,
}

impl Side {
    /// The world, or a body that takes no impulse: unmoved, immovable.
    pub const WORLD: Self = Self {
        x: Vec3A::ZERO,
        q: Quat::IDENTITY,
        v: Vec3A::ZERO,
        w: Vec3A::ZERO,
        inv_m: 0.0,
        inv_i: Mat3A::ZERO,
        dl: Vec3A::ZERO,
        moves: false,
    };

    /// Takes the linear impulse `p` at lever arm `r` and the angular impulse `l`.
    #[inline]
    fn push(&mut self, p: Vec3A, r: Vec3A, l: Vec3A) {
        if !self.moves {
            return;
        }
        let dl = r.cross(p) + l;
        self.v += self.inv_m * p;
        self.w += self.inv_i * dl;
        self.dl += dl;
    }
}

/// What a joint holds besides its anchors.
#[derive(Debug, Clone, Copy)]
pub(super) enum Angular {
    /// Nothing: a ball joint.
    Free,
    /// The hinge axes (each side's shape frame) aligned.
    Hinge { axis_a: Vec3, axis_b: Vec3 },
    /// q_b = q_a · relative.
    Weld { relative: Quat },
}

/// A joint's geometry for one pass: lever arms in the world frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rows {
    /// Anchor minus centre of mass, each side's shape frame (a world point for the world).
    pub local_a: Vec3A,
    pub local_b: Vec3A,
    pub angular: Angular,
}

/// The accumulated impulses applied to `b` (and their opposite to `a`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Accumulated {
    pub linear: Vec3A,
    pub angular: Vec3A,
}

/// [`Softness`] for a biased pass, or the rigid solve of a relax pass.
#[derive(Debug, Clone, Copy)]
pub(super) struct Mode {
    pub bias_rate: f32,
    pub mass_scale: f32,
    pub impulse_scale: f32,
}

impl Mode {
    pub const RIGID: Self = Self {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    pub fn soft(s: Softness) -> Self {
        Self {
            bias_rate: s.bias_rate,
            mass_scale: s.mass_scale,
            impulse_scale: s.impulse_scale,
        }
    }
}

/// The arms r_a, r_b (world frame) and the anchors' separation p_b − p_a.
#[inline]
fn arms(rows: &Rows, a: &Side, b: &Side) -> (Vec3A, Vec3A, Vec3A) {
    let r_a = a.q * rows.local_a;
    let r_b = b.q * rows.local_b;
    (r_a, r_b, (b.x + r_b) - (a.x + r_a))
}

/// Applies the accumulated impulses again (the warm start of a substep).
pub(super) fn warm_start(rows: &Rows, acc: &Accumulated, a: &mut Side, b: &mut Side) {
    let (r_a, r_b, _) = arms(rows, a, b);
    a.push(-acc.linear, r_a, -acc.angular);
    b.push(acc.linear, r_b, acc.angular);
}
