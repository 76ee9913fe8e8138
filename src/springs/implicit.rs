//! Springs in the backward-Euler solve ([`crate::integrator::implicit`]): a
//! [`SpringNetwork`]'s springs as [`ImplicitElements`]. Add [`crate::integrator::ImplicitEuler`] to a
//! `Nodes` + `SpringNetwork` mesh (a cloth, a rope built as a mesh) to integrate it
//! implicitly; its spring forces then come from the solve, not from `ForceSystems::Springs`.
//!
//! For a spring (a, b) of rest length r, stiffness k and damping c, with l = |x_b − x_a| and
//! d̂ = (x_b − x_a)/l (Baraff and Witkin 1998):
//!
//! ```text
//! U = ½ k (l − r)²,     f_a = k (l − r) d̂ = −f_b
//! K = [[A, −A], [−A, A]],   A = k [ d̂ d̂ᵀ + (1 − r/l) (I − d̂ d̂ᵀ) ]
//! D = [[C, −C], [−C, C]],   C = c d̂ d̂ᵀ   (at the step's start)
//! ```
//!
//! A compressed spring (l < r) has 1 − r/l < 0: its transverse stiffness is negative (it
//! buckles). Where the exact matrix fails to give a descent direction the solve projects it,
//! which sets that term to zero (Choi and Ko 2002). A zero-length spring (r = 0) has A = k I;
//! coincident ends of a spring with r > 0 give no force and no stiffness (no NaN).

use bevy_ecs::prelude::*;
use glam::{DMat3, DVec3, Vec3A};

use super::SpringNetwork;
use crate::core::quarantine::{DivergenceGuard, QuarantineReason, Quarantined};
use crate::core::time::SubstepTime;
use crate::integrator::implicit::{ContactPlane, ImplicitElements, Scratch, step};
use crate::integrator::{ImplicitEuler, ImplicitState};
use crate::particles::Nodes;

/// A spring at an iterate: its unit direction (zero for coincident ends) and length (m).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SpringState {
    dir: DVec3,
    length: f64,
}

impl SpringNetwork {
    fn block(&self, k: usize, p: &SpringState, transverse_floor: f64) -> DMat3 {
        let (stiffness, rest) = (f64::from(self.k[k]), f64::from(self.rest[k]));
        if rest == 0.0 {
            return DMat3::from_diagonal(DVec3::splat(stiffness));
        }
        if p.length == 0.0 {
            return DMat3::ZERO;
        }
        let dd = outer(p.dir);
        let transverse = (1.0 - rest / p.length).max(transverse_floor);
        stiffness * (dd + transverse * (DMat3::IDENTITY - dd))
    }
}

fn outer(d: DVec3) -> DMat3 {
    DMat3::from_cols(d * d.x, d * d.y, d * d.z)
}

impl ImplicitElements for SpringNetwork {
    type Hess = DMat3;
    type Prep = SpringState;

    fn count(&self) -> usize {
        self.ends.len()
    }

    fn zero() -> DMat3 {
        DMat3::ZERO
    }

    fn nodes(&self, k: usize) -> &[u32] {
        &self.ends[k]
    }

    fn mass_damping(&self) -> f64 {
        0.0
    }

    fn has_damping(&self) -> bool {
        self.c.iter().any(|&c| c > 0.0)
    }

    fn planes(&self) -> &[ContactPlane] {
        &[]
    }

    fn prepare(&self, x: &[Vec3A], prep: &mut Vec<SpringState>) -> f64 {
        prep.clear();
        let mut energy = 0.0;
        for (k, &[a, b]) in self.ends.iter().enumerate() {
            let d = glam::Vec3::from(x[b as usize] - x[a as usize]).as_dvec3();
            let length = d.length();
            let dir = if length > 0.0 {
                d / length
            } else {
                DVec3::ZERO
            };
            let s = length - f64::from(self.rest[k]);
            energy += 0.5 * f64::from(self.k[k]) * s * s;
            prep.push(SpringState { dir, length });
        }
        energy
    }

    fn forces(&self, prep: &[SpringState], out: &mut [Vec3A]) -> bool {
        out.iter_mut().for_each(|f| *f = Vec3A::ZERO);
        let mut finite = true;
        for (k, &[a, b]) in self.ends.iter().enumerate() {
            let p = prep[k];
            let f = if self.rest[k] == 0.0 {
                f64::from(self.k[k]) * p.length * p.dir
            } else {
                f64::from(self.k[k]) * (p.length - f64::from(self.rest[k])) * p.dir
            };
            let f = Vec3A::from(f.as_vec3());
            finite &= f.is_finite();
            out[a as usize] += f;
            out[b as usize] -= f;
        }
        finite
    }

    fn hessian(&self, k: usize, p: &SpringState) -> (DMat3, bool) {
        let compressed = self.rest[k] > 0.0 && p.length > 0.0 && p.length < f64::from(self.rest[k]);
        (self.block(k, p, f64::NEG_INFINITY), compressed)
    }

    fn project(h: &DMat3) -> DMat3 {
        // A is symmetric with eigenvalues k (along d̂) and k(1 − r/l) twice; clamp them.
        let m = nalgebra::Matrix3::from_column_slice(&h.to_cols_array());
        let mut eig = m.symmetric_eigen();
        eig.eigenvalues.iter_mut().for_each(|l| *l = l.max(0.0));
        let r = eig.recompose();
        DMat3::from_cols_slice(r.as_slice())
    }

    fn damping(&self, k: usize, p: &SpringState, _projected: &DMat3) -> Option<DMat3> {
        let c = f64::from(self.c[k]);
        (c > 0.0).then(|| c * outer(p.dir))
    }

    fn apply(&self, k: usize, h: &DMat3, dx: &[DVec3], scale: f64, out: &mut [DVec3]) {
        let [a, b] = self.ends[k];
        let f = scale * (*h * (dx[b as usize] - dx[a as usize]));
        out[b as usize] += f;
        out[a as usize] -= f;
    }

    fn add_diagonal(&self, k: usize, h: &DMat3, scale: f64, out: &mut [DVec3]) {
        let [a, b] = self.ends[k];
        let d = scale * DVec3::new(h.x_axis.x, h.y_axis.y, h.z_axis.z);
        out[a as usize] += d;
        out[b as usize] += d;
    }

    fn in_factor(&self, k: usize) -> bool {
        // A cloth's bending springs (k/40 of its structural ones by default) join nodes two
        // apart: without them the factor's envelope is half as wide and a quarter the work.
        self.k[k] >= 0.1 * self.max_k
    }

    fn blocks(&self, k: usize, h: &DMat3, scale: f64, add: &mut dyn FnMut(u32, u32, DMat3)) {
        let [a, b] = self.ends[k];
        let m = scale * *h;
        add(a, a, m);
        add(b, b, m);
        add(a, b, -m);
        add(b, a, -m);
    }

    fn finish(&mut self, _prep: &[SpringState], _energy: f64) {}
}

/// Backward Euler for spring meshes with [`ImplicitEuler`]; one that turns non-finite, or
/// whose node runs past the divergence guard, is quarantined.
pub(crate) fn solve_implicit_springs(
    mut commands: Commands,
    guard: Res<DivergenceGuard>,
    time: Res<SubstepTime>,
    mut meshes: Query<
        (
            Entity,
            &mut Nodes,
            &mut SpringNetwork,
            &ImplicitEuler,
            &mut ImplicitState,
        ),
        Without<Quarantined>,
    >,
    mut scratch: Local<Scratch<SpringNetwork>>,
    diagnostics: Option<Res<crate::core::diagnostics::DiagnosticsSettings>>,
) {
    let account = diagnostics.is_none_or(|d| d.energy);
    for (e, mut nodes, mut network, settings, mut state) in &mut meshes {
        if nodes.is_changed() {
            // Moved from outside the step (spawned, teleported): no history to extrapolate.
            state.bypass_change_detection().history_h = 0.0;
        }
        let network = network.bypass_change_detection();
        let n = nodes.bypass_change_detection();
        if let Some(reason) = network.misfit(n) {
            commands.entity(e).insert(Quarantined { reason });
            continue;
        }
        let report = step(
            network,
            n,
            settings,
            state.bypass_change_detection(),
            time.h,
            &mut scratch,
            account,
        );
        let reason = match report {
            None => Some(QuarantineReason::NonFiniteState),
            Some(report) => {
                state.bypass_change_detection().last = report;
                crate::integrator::mesh_divergence(n, &guard)
            }
        };
        if let Some(reason) = reason {
            commands.entity(e).insert(Quarantined { reason });
        }
    }
}
