//! What attachments and contacts between a soft body and a rigid body share: how each side
//! answers an impulse, and moving both by the impulses found.
//!
//! An impulse λ (N·s) along a unit direction d at node k moves the soft body's velocities
//! by W_soft λ and the body's point velocity at p by −W_body λ, so a constraint between
//! them sees the sum:
//!
//! ```text
//! G_kl = d_kᵀ (W_soft(k, l) + W_body(k, l)) d_l
//! W_soft = H⁻¹ / h²   (H the implicit solve's M/h² + K + D/h; M⁻¹ when there is no factor)
//! W_body(k, l) = I₃ / M − [r_k]× I⁻¹ [r_l]×,  r = p − x_B
//! ```
//!
//! A step of the soft side by the impulses Λ is Δx = H⁻¹ Λ / h (every node answers, not only
//! the ones pushed: a stiff body moves as a whole), v += Δx / h; the body's v, L, x and q move
//! by the opposite impulses as its integrator would have moved them.

use bevy_ecs::prelude::*;
use glam::{DVec3, Mat3, Quat, Vec3, Vec3A};
use nalgebra::DMatrix;

use crate::core::quarantine::Quarantined;
use crate::integrator::skyline::SkylineCholesky;
use crate::particles::{LinearVelocity, Mass, Nodes};
use crate::rigid::{AngularMomentum, AngularVelocity, Inertia, Rotation};

/// An impulse's row: the nodes it acts on with their weights (one node of weight 1, or a
/// triangle's corners at a point between them) and its unit direction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    pub parts: [(usize, f32); 3],
    pub count: usize,
    pub dir: Vec3,
}

impl Row {
    /// One node.
    #[must_use]
    pub fn node(i: usize, dir: Vec3) -> Self {
        Self {
            parts: [(i, 1.0); 3],
            count: 1,
            dir,
        }
    }

    fn parts(&self) -> &[(usize, f32)] {
        &self.parts[..self.count]
    }
}

/// The soft body's response G_soft for impulses along `rows` = (node, unit direction): one
/// solve with the factor per row, or the lumped inverse masses without one.
pub(crate) fn soft_response(
    n: &Nodes,
    factor: Option<&SkylineCholesky>,
    rows: &[(usize, Vec3)],
    h: f32,
) -> DMatrix<f64> {
    let rows: Vec<Row> = rows.iter().map(|&(i, d)| Row::node(i, d)).collect();
    soft_response_of(n, factor, &rows, h)
}

/// G_soft for weighted rows: G_kl = Σₐ Σ_b wₐ w_b d_kᵀ W_soft(a, b) d_l.
pub(crate) fn soft_response_of(
    n: &Nodes,
    factor: Option<&SkylineCholesky>,
    rows: &[Row],
    h: f32,
) -> DMatrix<f64> {
    let a = rows.len();
    let mut g = DMatrix::<f64>::zeros(a, a);
    let Some(factor) = factor else {
        for (k, r) in rows.iter().enumerate() {
            for (l, s) in rows.iter().enumerate() {
                let de = f64::from(r.dir.dot(s.dir));
                for &(i, wi) in r.parts() {
                    for &(j, wj) in s.parts() {
                        if i == j {
                            g[(k, l)] += f64::from(wi * wj) * f64::from(n.inv_mass[i]) * de;
                        }
                    }
                }
            }
        }
        return g;
    };
    let len = n.x.len();
    // The factor's own step: BDF2 solves with ⅔ of the substep. An impulse J changes the
    // velocities by H⁻¹ J / h_f² (whose total is exactly J: K moves no mass centre).
    let h = if factor.step > 0.0 { factor.step } else { h };
    let inv_h2 = 1.0 / (f64::from(h) * f64::from(h));
    let (mut e, mut z, mut work) = (vec![DVec3::ZERO; len], vec![DVec3::ZERO; len], vec![]);
    for (l, s) in rows.iter().enumerate() {
        for &(j, wj) in s.parts() {
            e[j] += (s.dir * wj).as_dvec3();
        }
        factor.solve(&e, &mut z, &mut work);
        for &(j, _) in s.parts() {
            e[j] = DVec3::ZERO;
        }
        for (k, r) in rows.iter().enumerate() {
            let d = r.dir.as_dvec3();
            g[(k, l)] = r
                .parts()
                .iter()
                .map(|&(i, wi)| f64::from(wi) * z[i].dot(d))
                .sum::<f64>()
                * inv_h2;
        }
    }
    g
}

/// Moves the soft body by the impulses (node, λ d) (N·s): through the factor, or node by node
/// with the lumped masses.
pub(crate) fn move_soft(
    n: &mut Nodes,
    factor: Option<&SkylineCholesky>,
    impulses: &[(usize, Vec3)],
    h: f32,
) {
    let Some(factor) = factor else {
        for &(i, j) in impulses {
            let dv = Vec3A::from(j * n.inv_mass[i]);
            n.v[i] += dv;
            n.x[i] += h * dv;
        }
        return;
    };
    let len = n.x.len();
    let hf = f64::from(if factor.step > 0.0 { factor.step } else { h });
    let mut rhs = vec![DVec3::ZERO; len];
    for &(i, j) in impulses {
        rhs[i] += j.as_dvec3() / (hf * hf);
    }
    let mut dv = vec![DVec3::ZERO; len];
    factor.solve(&rhs, &mut dv, &mut Vec::new());
    for (i, dv) in dv.iter().enumerate() {
        if n.inv_mass[i] > 0.0 {
            let d = Vec3A::from(dv.as_vec3());
            n.v[i] += d;
            n.x[i] += Vec3A::from((f64::from(h) * *dv).as_vec3());
        }
    }
}

/// A rigid body's side of an exchange: its state, and what it has taken so far.
#[derive(Debug, Clone)]
pub(crate) struct RigidSide {
    /// Centre of mass (m), velocity (m/s), angular velocity (rad/s).
    pub x: Vec3,
    pub v: Vec3,
    pub w: Vec3,
    /// Inverse mass per world axis (zero along a locked one, see
    /// [`crate::rigid::LockedAxes`]).
    pub inv_mass: Vec3,
    pub inv_inertia: Mat3,
    /// False for a static or kinematic body: it moves (or not) but takes no impulse.
    pub dynamic: bool,
    /// Σ of the impulses and angular impulses taken (N·s, kg·m²/s).
    pub linear: Vec3,
    pub angular: Vec3,
}

impl RigidSide {
    /// The velocity of the body's point at `p`.
    #[must_use]
    pub fn point_velocity(&self, p: Vec3) -> Vec3 {
        self.v + self.w.cross(p - self.x)
    }

    /// 1/m_eff at `p` along the unit `dir` (zero for a body that takes no impulse).
    #[must_use]
    pub fn inverse_mass_along(&self, p: Vec3, dir: Vec3) -> f32 {
        if !self.dynamic {
            return 0.0;
        }
        let rn = (p - self.x).cross(dir);
        dir.dot(self.inv_mass * dir) + rn.dot(self.inv_inertia * rn)
    }

    /// G_body for impulses along `rows` = (point, unit direction).
    #[must_use]
    pub fn response(&self, rows: &[(Vec3, Vec3)]) -> DMatrix<f64> {
        let a = rows.len();
        let mut g = DMatrix::<f64>::zeros(a, a);
        if !self.dynamic {
            return g;
        }
        for (k, &(p, d)) in rows.iter().enumerate() {
            let rd = (p - self.x).cross(d);
            for (l, &(q, e)) in rows.iter().enumerate() {
                let re = (q - self.x).cross(e);
                g[(k, l)] = f64::from(d.dot(self.inv_mass * e) + rd.dot(self.inv_inertia * re));
            }
        }
        g
    }

    /// Takes the impulse `j` (N·s) at `p`.
    pub fn take(&mut self, p: Vec3, j: Vec3) {
        if !self.dynamic {
            return;
        }
        let angular = (p - self.x).cross(j);
        self.v += self.inv_mass * j;
        self.w += self.inv_inertia * angular;
        self.linear += j;
        self.angular += angular;
    }

    /// Whether it took anything.
    #[must_use]
    pub fn touched(&self) -> bool {
        self.linear != Vec3::ZERO || self.angular != Vec3::ZERO
    }

    /// The pose change (Δx, new q) its taken impulses make over a substep h, as the
    /// integrator would have moved it with the new velocities.
    #[must_use]
    pub fn moved_pose(&self, q: Quat, h: f32) -> (Vec3, Quat) {
        let dv = self.inv_mass * self.linear;
        let dw = self.inv_inertia * self.angular;
        let turn = Quat::from_xyzw(dw.x, dw.y, dw.z, 0.0) * q;
        (h * dv, (q + turn * (0.5 * h)).normalize())
    }
}

/// The impulses soft bodies' nodes gave a dynamic body in a substep, for it to take at the
/// start of the next one, before its integrator and its rigid contacts: its velocity at the
/// end of a step is then what its rigid contacts left (a crate under a jelly reads at rest),
/// and whatever holds it up answers the push in the same substep.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, Default, PartialEq,
)]
pub(crate) struct NodeImpulse {
    /// N·s, world frame.
    pub(crate) linear: Vec3,
    /// About the centre of mass (kg·m²/s, world frame).
    pub(crate) angular: Vec3,
}

type Pending<'a> = (
    Option<&'a crate::rigid::LockedAxes>,
    &'a mut NodeImpulse,
    &'a mut LinearVelocity,
    &'a mut AngularMomentum,
    &'a mut AngularVelocity,
    &'a Mass,
    &'a Inertia,
    &'a Rotation,
);

/// Applies and clears [`NodeImpulse`]s: v += J/M, L += ΔL, ω = I⁻¹ L.
pub(crate) fn apply_node_impulses(mut bodies: Query<Pending, Without<Quarantined>>) {
    for (locks, mut pending, mut v, mut l, mut w, m, i, q) in &mut bodies {
        if *pending == NodeImpulse::default() {
            continue;
        }
        let p = std::mem::take(pending.bypass_change_detection());
        let inverse = crate::rigid::LockedAxes::inverse_mass_of(locks, m.inverse());
        v.0 += Vec3A::from(p.linear) * inverse;
        let l = l.bypass_change_detection();
        l.0 += Vec3A::from(p.angular);
        w.bypass_change_detection().0 = i.angular_velocity(q.0, l.0);
    }
}
