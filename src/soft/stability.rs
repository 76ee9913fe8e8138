//! A soft body's explicit stability limit, and the policy on it.
//!
//! By Irons' theorem the highest frequency of an assembled mesh is at most the highest of
//! its elements with their lumped masses (ρV/4 per corner). For a tetrahedron the strain
//! energy is V ψ(ε) with 2ψ ≤ (2μ + 3λ) |ε|² (the bulk mode's ratio, the largest for
//! λ ≥ 0) and |ε|² ≤ |∇u|² ≤ Σ|u_i|² Σ|∇N_i|², so
//!
//! ```text
//! ω_max² ≤ max over elements of 4 (2μ + 3λ) Σᵢ |∇Nᵢ|² / ρ,       2ζω ≤ α + β ω²
//! ```
//!
//! and h_crit follows from [`crate::integrator::stability::critical_step`]. The bound is
//! safe (never above the true limit) and on regular meshes 2–3 times below it, so a body
//! near its limit is solved implicitly rather than risked.
//!
//! A [`SoftBody`] integrated explicitly past its limit is handled by
//! [`crate::integrator::StabilityPolicy`], told once by a [`StabilityWarning`]: by default
//! stepped on its own a few times per substep ([`LocalSubsteps`]) while that is cheaper than
//! its implicit solve ([`LOCAL_SUBSTEPS_CHEAPER_UP_TO`]), solved by BDF2 beyond.

use bevy_ecs::prelude::*;
use glam::Vec3;

use super::SoftBody;
use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::quarantine::Quarantined;
use crate::core::time::PhysicsTime;
use crate::integrator::stability::{
    LocalSubsteps, StabilityPolicy, StabilityWarning, SystemLimit, apply_policy, critical_step,
    put_rescue,
};
use crate::integrator::{ImplicitEuler, ImplicitScheme, Integrator, IntegratorOverride, Rescue};
use crate::particles::Nodes;

/// Local substeps per substep at most that [`StabilityPolicy::Automatic`] takes for a soft
/// body before it solves it by BDF2 instead: the count at which they cost about what BDF2's
/// Newton solve does (`examples/perf_report`, `local_substeps_*_softbar480` lines).
pub const LOCAL_SUBSTEPS_CHEAPER_UP_TO: u32 = 12;

/// A soft body's explicit stability limit (see the module docs); added with [`SoftBody`].
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SoftStability {
    /// The largest substep (s) explicit integration is sure to be stable at.
    pub critical_step: f32,
    computed: bool,
    warned: bool,
}

impl SoftBody {
    /// The explicit stability limit h_crit (s) of this body at rest (see
    /// [`crate::soft::stability`]); infinite for a body without elements.
    #[must_use]
    pub fn critical_step(&self) -> f32 {
        let lame = self.lame;
        let modulus = 2.0 * lame.mu + 3.0 * lame.lambda.max(0.0);
        let (alpha, beta) = self.material.damping();
        let mut g_max = 0.0f32;
        for dm_inv in &self.dm_inv {
            let rows = [dm_inv.row(0), dm_inv.row(1), dm_inv.row(2)];
            let first: Vec3 = -(rows[0] + rows[1] + rows[2]);
            let g = first.length_squared() + rows.iter().map(|r| r.length_squared()).sum::<f32>();
            g_max = g_max.max(g);
        }
        let k = 4.0 * modulus * g_max / self.material.density();
        critical_step(k, alpha + beta * k)
    }
}

/// Computes each soft body's limit once, and applies the policy to one past it.
#[allow(clippy::type_complexity)] // the filters are the point
pub(crate) fn check_soft_stability(
    mut commands: Commands,
    time: Res<PhysicsTime>,
    global: Res<Integrator>,
    policy: Option<Res<StabilityPolicy>>,
    mut bodies: Query<
        (
            Entity,
            Ref<SoftBody>,
            Option<&Nodes>,
            &mut SoftStability,
            Has<ImplicitEuler>,
            Option<&IntegratorOverride>,
            Option<&LocalSubsteps>,
        ),
        Without<Quarantined>,
    >,
    mut warnings: MessageWriter<StabilityWarning>,
    mut diag: Option<ResMut<PhysicsDiagnostics>>,
) {
    let policy = policy.map_or_else(StabilityPolicy::default, |p| *p);
    let substep = time.dt() / time.substeps() as f32;
    let mut smallest = f32::INFINITY;
    for (e, body, nodes, mut stability, implicit, o, local) in &mut bodies {
        let fresh = !stability.computed || body.is_changed();
        if fresh {
            stability.critical_step = body.critical_step();
            stability.computed = true;
        }
        smallest = smallest.min(stability.critical_step);
        let method = o.map_or(*global, |o| o.0);
        if implicit || method == Integrator::ImplicitEuler {
            continue;
        }
        // A body with inverted elements is far from the rest state its limit was judged at
        // (stable Neo-Hookean stiffens with the cofactor of F, past any substep count taken
        // at rest), and explicit steps without damping keep the energy an inversion stores
        // ringing through inversion for ever (a jelly started mirrored stayed half inside
        // out): BDF2 brings it back.
        let started_inverted = fresh && nodes.is_some_and(|n| has_inverted_elements(&body, n));
        if body.stats.inverted > 0 || started_inverted {
            if policy.rescue(method).is_some() {
                put_rescue(&mut commands, e, Rescue::Implicit(ImplicitScheme::Bdf2));
            }
            continue;
        }
        // Rescued by local substeps, it is solved by BDF2 once it presses on a dynamic body
        // (which takes its impulses once per substep, not per local step: the body would
        // sink into it by millimetres).
        if local.is_some() && body.touched_a_body {
            if policy.rescue(method).is_some() {
                put_rescue(&mut commands, e, Rescue::Implicit(ImplicitScheme::Bdf2));
            }
            continue;
        }
        let system = SystemLimit {
            entity: e,
            critical_step: stability.critical_step,
            method,
            cheaper_up_to: LOCAL_SUBSTEPS_CHEAPER_UP_TO,
            fresh,
            local: local.copied(),
        };
        let SoftStability { warned, .. } = &mut *stability;
        apply_policy(
            &mut commands,
            &mut warnings,
            diag.as_deref_mut(),
            policy,
            (time.dt(), substep),
            &system,
            warned,
        );
    }
    if let Some(d) = diag.as_mut() {
        d.soft_critical_step = smallest;
    }
}

/// True if an element of `body` is inverted (det F ≤ 0) at `nodes`; elements naming a node
/// past them are left to the step's own check.
fn has_inverted_elements(body: &SoftBody, nodes: &Nodes) -> bool {
    let x = nodes.positions();
    (0..body.tets.len()).any(|k| {
        body.tets[k].iter().all(|&i| (i as usize) < x.len())
            && body.deformation_gradient(x, k).determinant() <= 0.0
    })
}
