//! Soft-body systems: elastic forces, and their energy in the diagnostics.

use bevy_ecs::prelude::*;

use super::SoftBody;
use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::core::rest::Simulated;
use crate::core::schedule::{
    FinishSystems, ForceSystems, PhysicsSchedule, RelaxSystems, SubstepSchedule,
    add_own_force_systems, add_own_systems,
};
use crate::core::time::SubstepTime;
use crate::integrator::{ImplicitEuler, ImplicitState, LocalSubsteps};
use crate::particles::Nodes;

/// Elastic forces of [`SoftBody`] meshes. Its systems run only while a soft body exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct SoftBodyPlugin;

impl WorldPlugin for SoftBodyPlugin {
    fn build(&self, world: &mut World) {
        crate::core::whole_step::block_on::<SoftBody>(world);
        crate::core::whole_step::block_on::<super::NodeAttachments>(world);
        crate::core::whole_step::block_on::<super::NodeTargets>(world);
        crate::core::whole_step::block_on::<ImplicitEuler>(world);
        add_own_force_systems(world, || {
            apply_elastic_forces
                .run_if(any_with_component::<SoftBody>)
                .in_set(ForceSystems::Elasticity)
        });
        crate::core::whole_step::block_on::<LocalSubsteps>(world);
        add_own_systems(
            world,
            SubstepSchedule,
            (
                solve_implicit.run_if(any_with_component::<ImplicitEuler>),
                substep_soft_bodies.run_if(any_with_component::<LocalSubsteps>),
            )
                .chain()
                .in_set(crate::core::schedule::ImplicitSystems::SoftBodies),
        );
        // Attachments first (chained: both move nodes), so that the contacts have the last
        // word on where a node may be.
        add_own_systems(
            world,
            SubstepSchedule,
            (
                super::attach::solve_attachments
                    .run_if(any_with_component::<super::NodeAttachments>),
                crate::collision::nodes::collide_nodes::<SoftBody>
                    .run_if(any_with_component::<SoftBody>)
                    .run_if(any_with_component::<crate::collision::Collider>),
            )
                .chain()
                .in_set(RelaxSystems::Soft),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                refuse_misfit_bodies.run_if(any_with_component::<SoftBody>),
                crate::integrator::follow_implicit_dial::<SoftBody>
                    .run_if(any_with_component::<SoftBody>),
                super::targets::drive_node_targets.run_if(any_with_component::<super::NodeTargets>),
                super::attach::anchor_attachments
                    .run_if(any_with_component::<super::NodeAttachments>),
                super::stability::check_soft_stability.run_if(any_with_component::<SoftBody>),
            )
                .chain()
                .in_set(crate::core::schedule::PrepareSystems::Inputs),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            report_elastic_energy
                .run_if(any_with_component::<SoftBody>)
                .in_set(FinishSystems::Writeback),
        );
    }
}

/// f += −V P(F) Dm⁻ᵀ per tetrahedron; a body whose forces come out non-finite is quarantined.
fn apply_elastic_forces(
    mut commands: Commands,
    mut bodies: Query<(Entity, &mut Nodes, &mut SoftBody), ExplicitSoft>,
) {
    for (e, mut nodes, mut body) in &mut bodies {
        let n = nodes.bypass_change_detection();
        let ok = body
            .bypass_change_detection()
            .accumulate(&n.x, &n.v, &n.mass, &mut n.f);
        if !ok {
            commands.entity(e).insert(Quarantined {
                reason: QuarantineReason::NonFiniteState,
            });
        }
    }
}

/// A soft body whose `Nodes` or elements game code changed is checked before anything
/// indexes them: nodes emptied or cut short under the elements, or elements of a bigger mesh
/// put on a smaller one, quarantine the body, named, instead of indexing out of bounds. A
/// consistent replacement (new nodes and elements together) is adopted: the implicit solve
/// rebuilds its factor for the new sizes.
fn refuse_misfit_bodies(
    mut commands: Commands,
    bodies: Query<(Entity, Ref<Nodes>, Ref<SoftBody>), Without<Quarantined>>,
) {
    for (e, nodes, body) in &bodies {
        if !(nodes.is_changed() || body.is_changed()) {
            continue;
        }
        let len = nodes.len();
        if !nodes.consistent() || !body.fits(len) {
            let index = body.largest_node().map_or(0, |i| i as usize);
            commands.entity(e).insert(Quarantined {
                reason: QuarantineReason::InvalidInput(
                    crate::core::error::Error::IndexOutOfRange {
                        what: "soft body element node",
                        index,
                        len,
                    },
                ),
            });
        }
    }
}

/// Soft bodies the explicit integrators advance.
type ExplicitSoft = (Simulated, Without<ImplicitEuler>, Without<LocalSubsteps>);

/// What the local steps of a soft body use.
type LocalSoft<'a> = (Entity, &'a mut Nodes, &'a mut SoftBody, &'a LocalSubsteps);

/// Steps each soft body with [`LocalSubsteps`] (and no [`ImplicitEuler`]) n times per
/// substep on its own: its elastic and damping forces recomputed at each local step, the
/// other forces on its nodes held (see [`crate::integrator::stability`]).
fn substep_soft_bodies(
    mut commands: Commands,
    guard: Res<crate::core::quarantine::DivergenceGuard>,
    time: Res<SubstepTime>,
    mut bodies: Query<LocalSoft, (Simulated, Without<ImplicitEuler>)>,
    mut held: Local<Vec<glam::Vec3A>>,
) {
    for (e, mut nodes, mut body, local) in &mut bodies {
        let n = nodes.bypass_change_detection();
        let body = body.bypass_change_detection();
        let ok =
            crate::integrator::stability::step_locally(n, local.count(), time.h, &mut held, |n| {
                body.accumulate(&n.x, &n.v, &n.mass, &mut n.f)
            });
        let reason = if ok && n.is_finite() {
            crate::integrator::mesh_divergence(n, &guard)
        } else {
            Some(QuarantineReason::NonFiniteState)
        };
        if let Some(reason) = reason {
            commands.entity(e).insert(Quarantined { reason });
        }
    }
}

/// Backward Euler for soft bodies with [`ImplicitEuler`]; one that turns non-finite is
/// quarantined.
fn solve_implicit(
    mut commands: Commands,
    guard: Res<crate::core::quarantine::DivergenceGuard>,
    time: Res<SubstepTime>,
    mut bodies: Query<
        (
            Entity,
            &mut Nodes,
            &mut SoftBody,
            &ImplicitEuler,
            &mut ImplicitState,
        ),
        Simulated,
    >,
    mut scratch: Local<crate::integrator::implicit::Scratch<SoftBody>>,
    diagnostics: Option<Res<crate::core::diagnostics::DiagnosticsSettings>>,
) {
    let account = diagnostics.is_none_or(|d| d.energy);
    for (e, mut nodes, mut body, settings, mut state) in &mut bodies {
        if nodes.is_changed() {
            // Moved from outside the step (spawned, teleported): no history to extrapolate.
            state.bypass_change_detection().history_h = 0.0;
        }
        let body = body.bypass_change_detection();
        match crate::integrator::implicit::step(
            body,
            nodes.bypass_change_detection(),
            settings,
            state.bypass_change_detection(),
            time.h,
            &mut scratch,
            account,
        ) {
            Some(report) => {
                body.stats.implicit = report;
                state.bypass_change_detection().last = report;
                // Backward Euler does not diverge, but a bad input can still fling nodes.
                if let Some(reason) = crate::integrator::mesh_divergence(&nodes, &guard) {
                    commands.entity(e).insert(Quarantined { reason });
                }
            }
            None => {
                commands.entity(e).insert(Quarantined {
                    reason: QuarantineReason::NonFiniteState,
                });
            }
        }
    }
}

/// Σ elastic energy into [`PhysicsDiagnostics::elastic_energy`].
fn report_elastic_energy(
    bodies: Query<&SoftBody, Without<Quarantined>>,
    diag: Option<ResMut<PhysicsDiagnostics>>,
) {
    if let Some(mut diag) = diag {
        diag.elastic_energy = bodies.iter().map(|b| b.stats().elastic_energy).sum();
    }
}
