//! One joint's passes: the warm start, and the soft (biased) or rigid (relax) solve of its
//! rows.
//!
//! With lever arms r_a, r_b from the centres of mass to the anchors (world frame), the
//! point rows keep Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a at zero, with the effective mass
//! K⁻¹, K = (1/m_a + 1/m_b) 𝟙 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×. The angular rows
//! keep the chosen components of ω_b − ω_a at zero with K = I_a⁻¹ + I_b⁻¹ projected on them:
//! both perpendiculars of the hinge axis for a hinge, all three for a weld. A biased pass
//! solves λ = −S_m K⁻¹ (Ċ + β C) − S_i λ_acc (the soft step's coefficients, see
//! [`crate::collision::solver::Softness`]); a relax pass λ = −K⁻¹ Ċ.

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

/// [r]× I⁻¹ [r]×ᵀ as a matrix: the angular part of the point rows' K.
#[inline]
fn lever_term(r: Vec3A, inv_i: &Mat3A) -> Mat3A {
    let s = Mat3A::from_cols(
        Vec3A::new(0.0, r.z, -r.y),
        Vec3A::new(-r.z, 0.0, r.x),
        Vec3A::new(r.y, -r.x, 0.0),
    );
    s * *inv_i * s.transpose()
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

/// Solves `a` from `b` with K⁻¹ when K is invertible (both sides immovable: nothing).
#[inline]
fn solve3(k: Mat3A, rhs: Vec3A) -> Vec3A {
    let det = k.determinant();
    if det.abs() > f32::MIN_POSITIVE && det.is_finite() {
        k.inverse() * rhs
    } else {
        Vec3A::ZERO
    }
}

/// One pass over a joint's rows: angular first, the anchors last (they matter most).
pub(super) fn solve(rows: &Rows, acc: &mut Accumulated, mode: Mode, a: &mut Side, b: &mut Side) {
    let k_ang = a.inv_i + b.inv_i;
    match rows.angular {
        Angular::Free => {}
        Angular::Hinge { axis_a, axis_b } => {
            let axis_a = a.q * Vec3A::from(axis_a);
            let axis_b = b.q * Vec3A::from(axis_b);
            let (u, v) = Vec3::from(axis_a).any_orthonormal_pair();
            let (u, v) = (Vec3A::from(u), Vec3A::from(v));
            // The turn taking a's axis onto b's is about a_a × a_b, by its length (sin θ).
            let c = axis_a.cross(axis_b);
            let dw = b.w - a.w;
            let (ku, kv) = (k_ang * u, k_ang * v);
            let (k11, k12, k22) = (u.dot(ku), u.dot(kv), v.dot(kv));
            let det = k11 * k22 - k12 * k12;
            if det > f32::MIN_POSITIVE && det.is_finite() {
                let rhs = [
                    u.dot(dw) + mode.bias_rate * u.dot(c),
                    v.dot(dw) + mode.bias_rate * v.dot(c),
                ];
                let inv = 1.0 / det;
                let x1 = inv * (k22 * rhs[0] - k12 * rhs[1]);
                let x2 = inv * (k11 * rhs[1] - k12 * rhs[0]);
                let held = u * u.dot(acc.angular) + v * v.dot(acc.angular);
                let l = -mode.mass_scale * (u * x1 + v * x2) - mode.impulse_scale * held;
                acc.angular += l;
                a.push(Vec3A::ZERO, Vec3A::ZERO, -l);
                b.push(Vec3A::ZERO, Vec3A::ZERO, l);
            }
        }
        Angular::Weld { relative } => {
            let mut e = b.q * (a.q * relative).inverse();
            if e.w < 0.0 {
                e = -e;
            }
            let c = 2.0 * Vec3A::new(e.x, e.y, e.z);
            let rhs = (b.w - a.w) + mode.bias_rate * c;
            let l = -mode.mass_scale * solve3(k_ang, rhs) - mode.impulse_scale * acc.angular;
            acc.angular += l;
            a.push(Vec3A::ZERO, Vec3A::ZERO, -l);
            b.push(Vec3A::ZERO, Vec3A::ZERO, l);
        }
    }
    let (r_a, r_b, c) = arms(rows, a, b);
    let k = Mat3A::from_diagonal(Vec3::splat(a.inv_m + b.inv_m))
        + lever_term(r_a, &a.inv_i)
        + lever_term(r_b, &b.inv_i);
    let dv = (b.v + b.w.cross(r_b)) - (a.v + a.w.cross(r_a));
    let p = -mode.mass_scale * solve3(k, dv + mode.bias_rate * c) - mode.impulse_scale * acc.linear;
    acc.linear += p;
    a.push(-p, r_a, Vec3A::ZERO);
    b.push(p, r_b, Vec3A::ZERO);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(x: Vec3A) -> Side {
        Side {
            x,
            inv_m: 1.0,
            inv_i: Mat3A::from_diagonal(Vec3::splat(6.0)),
            moves: true,
            ..Side::WORLD
        }
    }

    #[test]
    fn a_rigid_pass_leaves_the_anchors_without_relative_velocity() {
        let rows = Rows {
            local_a: Vec3A::new(0.5, 0.0, 0.0),
            local_b: Vec3A::new(-0.5, 0.0, 0.0),
            angular: Angular::Free,
        };
        let mut a = body(Vec3A::ZERO);
        let mut b = body(Vec3A::new(1.0, 0.0, 0.0));
        a.v = Vec3A::new(0.0, 1.0, 0.0);
        b.w = Vec3A::new(0.3, -2.0, 0.7);
        let mut acc = Accumulated::default();
        solve(&rows, &mut acc, Mode::RIGID, &mut a, &mut b);
        let (r_a, r_b, _) = arms(&rows, &a, &b);
        let dv = (b.v + b.w.cross(r_b)) - (a.v + a.w.cross(r_a));
        assert!(dv.length() < 1e-5, "{dv}");
        // Momentum is conserved: equal and opposite impulses.
        assert!((a.v + b.v - Vec3A::new(0.0, 1.0, 0.0)).length() < 1e-5);
    }

    #[test]
    fn a_rigid_hinge_pass_leaves_only_the_turn_about_its_axis() {
        let axis = Vec3::Z;
        let rows = Rows {
            local_a: Vec3A::ZERO,
            local_b: Vec3A::ZERO,
            angular: Angular::Hinge {
                axis_a: axis,
                axis_b: axis,
            },
        };
        let mut a = Side::WORLD;
        let mut b = body(Vec3A::ZERO);
        b.w = Vec3A::new(1.0, -2.0, 3.0);
        let mut acc = Accumulated::default();
        solve(&rows, &mut acc, Mode::RIGID, &mut a, &mut b);
        assert!((b.w - Vec3A::new(0.0, 0.0, 3.0)).length() < 1e-5, "{}", b.w);
    }
}
