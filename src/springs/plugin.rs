//! Spring systems.

use bevy_ecs::prelude::*;

use glam::{Vec3, Vec3A};

use super::{Spring, SpringNetwork, spring_energy, spring_force};
use crate::core::diagnostics::{PhysicsDiagnostics, energy_on};
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::core::schedule::{
    ForceSystems, MeasureSystems, PhysicsSchedule, PrepareSystems, add_own_force_systems,
    add_own_systems,
};
use crate::particles::{Force, LinearVelocity, Nodes, Position};
use crate::rigid::{AngularVelocity, Rotation, Torque};

/// Spring forces for [`Spring`] entities and [`SpringNetwork`] meshes. Each system runs only
/// while its kind of spring exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct SpringPlugin;

impl WorldPlugin for SpringPlugin {
    fn build(&self, world: &mut World) {
        crate::core::whole_step::block_on::<Spring>(world);
        crate::core::whole_step::block_on::<SpringNetwork>(world);
        crate::core::whole_step::block_on::<crate::integrator::ImplicitEuler>(world);
        crate::core::whole_step::block_on::<crate::integrator::LocalSubsteps>(world);
        add_own_force_systems(world, || {
            (
                apply_spring_forces.run_if(any_with_component::<Spring>),
                apply_network_forces.run_if(any_with_component::<SpringNetwork>),
            )
                .chain()
                .in_set(ForceSystems::Springs)
        });
        // Substeps only: the multistage integrators' stage re-evaluations never see it (its
        // ends kick then drift).
        add_own_systems(
            world,
            crate::core::schedule::SubstepSchedule,
            (
                super::local::substep_entity_springs,
                super::entity_implicit::solve_entity_springs,
                super::entity_implicit::correct_end_positions,
            )
                .chain()
                .run_if(any_with_component::<Spring>)
                .in_set(ForceSystems::ImplicitSprings),
        );
        add_own_systems(
            world,
            crate::core::schedule::SubstepSchedule,
            (
                super::implicit::solve_implicit_springs
                    .run_if(any_with_component::<crate::integrator::ImplicitEuler>),
                super::local::substep_meshes
                    .run_if(any_with_component::<crate::integrator::LocalSubsteps>),
            )
                .chain()
                .in_set(crate::core::schedule::ImplicitSystems::Springs),
        );
        add_own_systems(
            world,
            crate::core::schedule::SubstepSchedule,
            super::local::correct_local_poses
                .run_if(any_with_component::<Spring>)
                .in_set(crate::core::schedule::PositionSystems::Correct),
        );
        world.init_resource::<super::local::LocalCorrections>();
        crate::core::restore::init::<super::EntitySpringStability>(world);
        crate::core::restore::init::<super::entity_implicit::EntitySpringFactor>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            MeasureSystems::configure(measure_spring_energy.run_if(energy_on)),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                remove_broken_springs.run_if(any_with_component::<Spring>),
                crate::integrator::follow_implicit_dial::<SpringNetwork>
                    .run_if(any_with_component::<SpringNetwork>),
                // It reads only the meshes' masses (positions do not enter the limit), so its
                // order against other inputs that move nodes does not change any result.
                super::stability::check_stability
                    .run_if(
                        any_with_component::<Spring>.or_else(any_with_component::<SpringNetwork>),
                    )
                    .ambiguous_with_all(),
            )
                .chain()
                .in_set(PrepareSystems::Inputs),
        );
    }
}

/// The spring's view of a body: position and velocity.
pub(crate) type Endpoint<'a> = (&'a Position, &'a LinearVelocity);

/// What an anchored end also needs: orientation and spin.
pub(crate) type Spinning<'a> = (&'a Rotation, &'a AngularVelocity);

/// World anchor p, its velocity v + ω × r and the lever arm r = R a (a relative to the centre
/// of mass, body axes). A body without rotation uses a as a fixed world offset.
#[inline]
pub(crate) fn anchor_state(
    e: Endpoint,
    spin: Option<Spinning>,
    anchor: Vec3,
) -> (Vec3A, Vec3A, Vec3A) {
    let (x, v) = e;
    if anchor == Vec3::ZERO {
        return (x.0, v.0, Vec3A::ZERO);
    }
    match spin {
        Some((q, w)) => {
            let r = q.0 * Vec3A::from(anchor);
            (x.0 + r, v.0 + w.0.cross(r), r)
        }
        None => (x.0 + Vec3A::from(anchor), v.0, Vec3A::ZERO),
    }
}

#[allow(clippy::too_many_arguments, clippy::type_complexity)] // a system: one query or resource each
fn apply_spring_forces(
    mut commands: Commands,
    guard: Res<crate::core::quarantine::DivergenceGuard>,
    global: Res<crate::integrator::Integrator>,
    springs: Query<
        (
            Entity,
            &Spring,
            Has<crate::integrator::ImplicitEuler>,
            Has<crate::integrator::LocalSubsteps>,
        ),
        Without<Quarantined>,
    >,
    states: Query<Endpoint, Without<Quarantined>>,
    ends: Query<super::entity_implicit::EndBody, Without<Quarantined>>,
    spinning: Query<Spinning, Without<Quarantined>>,
    mut forces: Query<&mut Force, Without<Quarantined>>,
    mut torques: Query<&mut Torque, Without<Quarantined>>,
    masses: Query<&crate::particles::Mass>,
    positions: Query<&Position>,
    (archetypes, spring_id, mut order): (
        &bevy_ecs::archetype::Archetypes,
        bevy_ecs::component::ComponentIdFor<Spring>,
        Local<Vec<Entity>>,
    ),
) {
    let global = *global;
    // Forces on a shared end are summed in spring order (see `crate::core::order`).
    let all =
        crate::core::order::stable(&springs, archetypes, spring_id.get(), &mut order, |i| i.0);
    for (spring, s, flagged, local) in all {
        if local || super::entity_implicit::wants_implicit(global, flagged) {
            let accepts = |e: Entity| {
                ends.get(e)
                    .is_ok_and(|(_, _, m, o)| super::entity_implicit::end_accepts(global, m, o))
            };
            if accepts(s.a) && accepts(s.b) {
                continue;
            }
        }
        // A quarantined or missing endpoint drops out of the query, so NaN can't cross.
        let (Ok(ea), Ok(eb)) = (states.get(s.a), states.get(s.b)) else {
            orphaned(
                &mut commands,
                &guard,
                spring,
                s,
                &states,
                &positions,
                &masses,
            );
            continue;
        };
        // Rotation is looked up only for an anchored end: plain ropes pay for two lookups.
        let spin = |e: Entity, anchor: Vec3| {
            if anchor == Vec3::ZERO {
                None
            } else {
                spinning.get(e).ok()
            }
        };
        let (pa, va, ra) = anchor_state(ea, spin(s.a, s.anchor_a), s.anchor_a);
        let (pb, vb, rb) = anchor_state(eb, spin(s.b, s.anchor_b), s.anchor_b);
        let f = spring_force(pa, pb, va, vb, s.rest_length, s.stiffness, s.damping);
        // A stretch past the guard's strain (|l − r| > s_max r) or a force that is not finite
        // means the integration diverged: both ends leave, with the spring named, instead
        // of the force being dropped silently. The strain, not the force: a damper's force
        // (c v) says nothing of divergence, and a soft door spring (k = 1, c = 50) or a pure
        // damper (k = 0) pushed hard is no runaway. A damper alone has no strain to keep.
        let ends_finite = pa.is_finite() && pb.is_finite() && va.is_finite() && vb.is_finite();
        if !ends_finite {
            // A non-finite end (written by game code, say) is caught and named by the state
            // check after integration; its neighbours must not catch its NaN meanwhile.
            continue;
        }
        // Compared squared: no square root per spring in the hot loop.
        let torn = s.rest_length > 0.0 && s.stiffness > 0.0 && {
            let (r, d2) = (s.rest_length, (pb - pa).length_squared());
            let longest = r * (1.0 + guard.max_spring_strain);
            let shortest = (r * (1.0 - guard.max_spring_strain)).max(0.0);
            d2 > longest * longest || d2 < shortest * shortest
        };
        if !f.is_finite() || torn {
            let strain = if f.is_finite() {
                ((pb - pa).length() - s.rest_length) / s.rest_length
            } else {
                f32::NAN
            };
            // A pinned end (a hook in the ceiling) did not diverge and stays.
            for end in [s.a, s.b]
                .into_iter()
                .filter(|&e| masses.get(e).is_ok_and(|m| !m.is_pinned()))
            {
                commands.entity(end).insert(Quarantined {
                    reason: QuarantineReason::SpringFailed { spring, strain },
                });
            }
            continue;
        }
        if let Ok(mut fa) = forces.get_mut(s.a) {
            fa.bypass_change_detection().0 += f;
        }
        if let Ok(mut fb) = forces.get_mut(s.b) {
            fb.bypass_change_detection().0 -= f;
        }
        if ra != Vec3A::ZERO
            && let Ok(mut t) = torques.get_mut(s.a)
        {
            t.bypass_change_detection().0 += ra.cross(f);
        }
        if rb != Vec3A::ZERO
            && let Ok(mut t) = torques.get_mut(s.b)
        {
            t.bypass_change_detection().0 -= rb.cross(f);
        }
    }
}

/// A spring whose one end was quarantined acts no more; if it was torn past the guard's
/// strain, its live free end took part in the divergence (it was flung by that spring) and
/// leaves too, named by it, instead of flying on ballistic.
fn orphaned(
    commands: &mut Commands,
    guard: &crate::core::quarantine::DivergenceGuard,
    spring: Entity,
    s: &Spring,
    states: &Query<Endpoint, Without<Quarantined>>,
    positions: &Query<&Position>,
    masses: &Query<&crate::particles::Mass>,
) {
    let (Ok(pa), Ok(pb)) = (positions.get(s.a), positions.get(s.b)) else {
        return;
    };
    if s.rest_length == 0.0 {
        return;
    }
    let strain = ((pb.0 - pa.0).length() - s.rest_length) / s.rest_length;
    // A quarantined end that went non-finite (NaN written by game code) says nothing about
    // its neighbours: only a finite, torn spring does.
    if !strain.is_finite() || strain.abs() <= guard.max_spring_strain {
        return;
    }
    for end in [s.a, s.b] {
        if states.contains(end) && masses.get(end).is_ok_and(|m| !m.is_pinned()) {
            commands.entity(end).insert(Quarantined {
                reason: QuarantineReason::SpringFailed { spring, strain },
            });
        }
    }
}

type ExplicitNetwork = (
    Without<Quarantined>,
    Without<crate::integrator::ImplicitEuler>,
    Without<crate::integrator::LocalSubsteps>,
);

/// Explicit meshes only: an [`crate::integrator::ImplicitEuler`] mesh's springs act inside its
/// solve, a [`crate::integrator::LocalSubsteps`] mesh's inside its local steps.
fn apply_network_forces(
    mut commands: Commands,
    mut meshes: Query<(Entity, &mut Nodes, &SpringNetwork), ExplicitNetwork>,
) {
    for (e, mut nodes, network) in &mut meshes {
        if let Some(reason) = network.misfit(&nodes) {
            commands.entity(e).insert(Quarantined { reason });
        } else {
            network.accumulate(nodes.bypass_change_detection());
        }
    }
}

/// Despawns springs whose endpoint was despawned (or lost its `Position`). Scans only in a
/// step after some `Position` was removed.
fn remove_broken_springs(
    mut commands: Commands,
    mut removed: RemovedComponents<Position>,
    springs: Query<(Entity, &Spring)>,
    bodies: Query<(), With<Position>>,
) {
    if removed.read().next().is_none() {
        return;
    }
    removed.clear();
    for (e, s) in &springs {
        if !(bodies.contains(s.a) && bodies.contains(s.b)) {
            commands.entity(e).despawn();
        }
    }
}

/// U_s = Σ ½ k (l − r)² over spring networks, then entity springs (f64), and their counts.
fn measure_spring_energy(
    mut diag: ResMut<PhysicsDiagnostics>,
    meshes: Query<(&Nodes, &SpringNetwork), Without<Quarantined>>,
    springs: Query<&Spring, Without<Quarantined>>,
    states: Query<Endpoint, Without<Quarantined>>,
    spinning: Query<Spinning, Without<Quarantined>>,
) {
    let mut us = 0.0f64;
    diag.counts.mesh_springs = 0;
    diag.counts.springs = 0;
    for (nodes, net) in &meshes {
        diag.counts.mesh_springs += net.len();
        us += net.energy(nodes);
    }
    for s in &springs {
        diag.counts.springs += 1;
        if let (Ok(a), Ok(b)) = (states.get(s.a()), states.get(s.b())) {
            let (anchor_a, anchor_b) = s.anchors();
            let (pa, _, _) = anchor_state(a, spinning.get(s.a()).ok(), anchor_a);
            let (pb, _, _) = anchor_state(b, spinning.get(s.b()).ok(), anchor_b);
            us += spring_energy(pa, pb, s.rest_length(), s.stiffness());
        }
    }
    diag.spring_energy = us;
}
