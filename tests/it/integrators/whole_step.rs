//! The whole-step path (`hooke::core::whole_step`): a world of rigid bodies under constant forces
//! runs its substeps in the contact solver's arrays, and must give the substep schedule's
//! results bit for bit. It must stand aside whenever something else acts in the substeps,
//! and quarantine exactly as the schedule does.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::core::diagnostics::PhysicsDiagnostics;
use hooke::core::quarantine::{BodyQuarantined, QuarantineReason, Quarantined};
use hooke::core::schedule::{ForceSystems, add_force_systems};
use hooke::core::whole_step::WholeStep;
use hooke::prelude::*;
use hooke::rigid::{AngularMomentum, ExternalTorque, Torque};
use hooke::tools::scenes;

/// Bits of every body's x, q, v, L, ω and force and torque accumulators, by entity.
fn state(world: &mut World) -> Vec<(Entity, Vec<u32>)> {
    let mut q = world.query::<(
        Entity,
        &Position,
        &Rotation,
        &LinearVelocity,
        &AngularMomentum,
        &AngularVelocity,
        (&Force, &Torque),
    )>();
    let mut out: Vec<(Entity, Vec<u32>)> = q
        .iter(world)
        .map(|(e, x, r, v, l, w, (f, t))| {
            let bits = x
                .get()
                .to_array()
                .into_iter()
                .chain(r.0.to_array())
                .chain(v.get().to_array())
                .chain(l.get().to_array())
                .chain(w.get().to_array())
                .chain(f.0.to_array())
                .chain(t.0.to_array())
                .map(f32::to_bits)
                .collect();
            (e, bits)
        })
        .collect();
    out.sort_by_key(|(e, _)| *e);
    out
}

/// The same scene in two worlds, one with the whole-step path off.
fn pair(build: impl Fn(&mut World)) -> [World; 2] {
    [true, false].map(|on| {
        let mut world = World::new();
        world.add_physics(PhysicsPlugins);
        world.insert_resource(WholeStep(on));
        build(&mut world);
        world
    })
}

/// Steps both worlds `steps` times, comparing every state after every step; returns how
/// many steps the first world ran on the whole-step path.
fn run_pair(worlds: &mut [World; 2], steps: usize) -> usize {
    let mut fused = 0;
    for step in 0..steps {
        for w in worlds.iter_mut() {
            w.step_physics();
        }
        fused += usize::from(worlds[0].resource::<PhysicsDiagnostics>().whole_step);
        assert!(!worlds[1].resource::<PhysicsDiagnostics>().whole_step);
        let [a, b] = worlds;
        assert!(state(a) == state(b), "the paths differ after step {step}");
    }
    fused
}

#[test]
fn stacks_and_pyramids_match_the_schedule_bit_for_bit() {
    for specs in [scenes::box_stack_spec(4), scenes::pyramid_spec(8)] {
        let mut worlds = pair(|w| {
            scenes::spawn_boxes(w, &specs).unwrap();
        });
        // 4 s: the boxes land, settle and fall asleep island by island.
        assert_eq!(run_pair(&mut worlds, 240), 240);
    }
}

#[test]
fn constant_forces_torques_gravity_scales_and_kinematic_bodies_match_the_schedule() {
    let mut worlds = pair(|w| {
        scenes::ground(w).unwrap();
        let cube = Collider::cuboid(0.5, 0.5, 0.5).unwrap();
        for i in 0..6 {
            let x = Vec3::new(i as f32 * 1.5 - 4.0, 0.5 + 0.3 * i as f32, 0.0);
            let mut e = w.spawn((
                RigidBody::Dynamic,
                cube.clone(),
                Position::from(x),
                Rotation(Quat::from_rotation_z(0.1 * i as f32)),
            ));
            match i % 3 {
                0 => e.insert(ExternalForce::from(Vec3::new(3000.0, 0.0, 0.0))),
                1 => e.insert((GravityScale(0.5), ExternalTorque::from(Vec3::Y * 400.0))),
                _ => e.insert(AngularVelocity::from(Vec3::new(0.0, 2.0, 5.0))),
            };
        }
        // A long flat box, not a cube: the splitting turns it about three distinct axes.
        w.spawn((
            RigidBody::Dynamic,
            Collider::cuboid(1.0, 0.1, 0.3).unwrap(),
            Position::from(Vec3::new(0.0, 3.0, 2.0)),
            AngularVelocity::from(Vec3::new(1.0, 3.0, -2.0)),
        ));
        // A kinematic paddle sweeping through the boxes.
        w.spawn((
            RigidBody::Kinematic,
            Collider::cuboid(0.2, 0.5, 2.0).unwrap(),
            Position::from(Vec3::new(-6.0, 0.5, 0.0)),
            LinearVelocity::from(Vec3::new(2.0, 0.0, 0.0)),
            AngularVelocity::from(Vec3::Y * 0.3),
        ));
    });
    assert_eq!(run_pair(&mut worlds, 300), 300);
}

#[test]
fn locked_bodies_match_the_schedule() {
    // A planar pile pushed out of its plane, and upright boxes spun about every axis.
    let mut worlds = pair(|w| {
        let (boxes, balls) = scenes::pile_scene(w, 16, 6).unwrap();
        for (i, e) in boxes.into_iter().chain(balls).enumerate() {
            let mut e = w.entity_mut(e);
            e.insert(ExternalForce::from(Vec3::new(0.0, 0.0, 500.0)));
            match i % 3 {
                0 => e.insert(LockedAxes::XY_PLANE),
                1 => e.insert((
                    LockedAxes::new().lock_rotation_x().lock_rotation_z(),
                    ExternalTorque::from(Vec3::new(50.0, 80.0, -30.0)),
                )),
                _ => e.insert((
                    LockedAxes::new().lock_rotation_y().lock_translation_x(),
                    AngularVelocity::from(Vec3::new(1.0, 2.0, -1.5)),
                )),
            };
        }
    });
    assert_eq!(run_pair(&mut worlds, 240), 240);
}

/// A force written every substep by a game system: the whole-step path would skip it.
#[derive(Component)]
struct Hover;

fn hover(mut bodies: Query<(&mut Force, &Mass), With<Hover>>) {
    for (mut f, m) in &mut bodies {
        f.0.y += 9.81 / m.inverse();
    }
}

#[test]
fn a_game_system_in_the_substeps_keeps_the_schedule() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::ground(&mut world).unwrap();
    add_force_systems(&mut world, || hover.in_set(ForceSystems::User));
    let body = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Position::from(Vec3::new(0.0, 3.0, 0.0)),
            Hover,
        ))
        .id();
    for _ in 0..60 {
        world.step_physics();
        assert!(!world.resource::<PhysicsDiagnostics>().whole_step);
    }
    // The hover force cancels gravity: the box has not moved.
    let y = world.get::<Position>(body).unwrap().get().y;
    assert!((y - 3.0).abs() < 1e-4, "{y}");
}

#[test]
fn effects_with_something_to_act_on_keep_the_schedule() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::spawn_boxes(&mut world, &scenes::box_stack_spec(2)).unwrap();
    world.step_physics();
    assert!(world.resource::<PhysicsDiagnostics>().whole_step);
    // Damping acts in the substeps.
    let damped = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Position::from(Vec3::new(5.0, 3.0, 0.0)),
            LinearDamping(0.5),
        ))
        .id();
    world.step_physics();
    assert!(!world.resource::<PhysicsDiagnostics>().whole_step);
    world.entity_mut(damped).remove::<LinearDamping>();
    world.step_physics();
    assert!(world.resource::<PhysicsDiagnostics>().whole_step);
    // A point particle is integrated by the linear integrator alone.
    world.spawn(ParticleBundle::new(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, 1.0).unwrap());
    world.step_physics();
    assert!(!world.resource::<PhysicsDiagnostics>().whole_step);
}

#[test]
fn one_substep_keeps_the_schedule() {
    let mut world = World::new();
    world.insert_resource(PhysicsTime::new(1.0 / 60.0, 1).unwrap());
    world.add_physics(PhysicsPlugins);
    scenes::spawn_boxes(&mut world, &scenes::box_stack_spec(2)).unwrap();
    world.step_physics();
    assert!(!world.resource::<PhysicsDiagnostics>().whole_step);
}

#[test]
fn other_integrators_keep_the_schedule() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::spawn_boxes(&mut world, &scenes::box_stack_spec(2)).unwrap();
    *world.resource_mut::<Integrator>() = Integrator::VelocityVerlet;
    world.step_physics();
    assert!(!world.resource::<PhysicsDiagnostics>().whole_step);
}

#[test]
fn quarantines_match_the_schedule() {
    let mut worlds = pair(|w| {
        scenes::spawn_boxes(w, &scenes::box_stack_spec(2)).unwrap();
        // Leaves the world's bounds within the first step, in its last substep.
        let guard = *w.resource::<hooke::core::quarantine::DivergenceGuard>();
        let edge = guard.max_distance - 1.0;
        w.spawn((
            RigidBody::Dynamic,
            Collider::ball(0.1).unwrap(),
            Position::from(Vec3::new(edge, 50.0, 0.0)),
            LinearVelocity::from(Vec3::new(200.0, 0.0, 0.0)),
        ));
    });
    let reasons = |w: &mut World| {
        let mut q = w.query::<(Entity, &Quarantined)>();
        let mut out: Vec<(Entity, QuarantineReason)> =
            q.iter(w).map(|(e, q)| (e, q.reason.clone())).collect();
        out.sort_by_key(|(e, _)| *e);
        out
    };
    run_pair(&mut worlds, 30);
    let [a, b] = &mut worlds;
    let found = reasons(a);
    assert_eq!(found.len(), 1);
    assert!(matches!(found[0].1, QuarantineReason::OutOfBounds { .. }));
    assert_eq!(found, reasons(b));
    let messages = |w: &World| w.resource::<Messages<BodyQuarantined>>().len();
    assert_eq!(messages(a), messages(b));
}

/// Every system of the substep schedule in a world with every effect, with how the
/// whole-step path treats it. A new substep system fails this test until its effect decides:
/// either the runner (`src/collision/fused.rs`) does its work, or the effect registers the
/// components it acts on with `whole_step::block_on`.
#[test]
fn every_substep_system_is_replicated_or_blocks_the_path() {
    let replicated = [
        "hooke::integrator::plugin::clear_forces",
        "hooke::integrator::plugin::integrate_velocities",
        "hooke::integrator::plugin::integrate_positions",
        "hooke::integrator::rotation::integrate_angular_momenta",
        "hooke::integrator::rotation::integrate_orientations",
        "hooke::rigid::plugin::renormalize_rotations",
        "hooke::rigid::locked::hold_locked_translations",
        "hooke::collision::solver::plugin::solve_contacts",
        "hooke::collision::solver::plugin::relax_contacts",
        // The timing probes between the sets: nothing to replicate.
        "hooke::core::diagnostics::install::{{closure}}",
    ];
    // Each with the components its effect blocks the path on.
    let blocking = [
        "hooke::integrator::plugin::apply_impulses", // ExternalImpulse(AtPoint)
        "hooke::integrator::stages::complete_stages", // Verlet, RK4: the runner declines
        "hooke::particles::plugin::apply_damping",   // LinearDamping
        "hooke::particles::plugin::advect_tracers",  // Tracer
        "hooke::rigid::plugin::apply_angular_damping", // AngularDamping
        "hooke::rigid::plugin::apply_forces_at_points", // ExternalForceAtPoint
        "hooke::rigid::limits::limit_speeds",        // MaxLinearSpeed, MaxAngularSpeed
        "hooke::springs::plugin::apply_spring_forces", // Spring
        "hooke::springs::plugin::apply_network_forces", // SpringNetwork
        "hooke::springs::entity_implicit::solve_entity_springs", // Spring
        "hooke::springs::entity_implicit::correct_end_positions", // Spring
        "hooke::springs::local::substep_entity_springs", // Spring
        "hooke::springs::local::correct_local_poses", // Spring
        "hooke::springs::local::substep_meshes",     // SpringNetwork, LocalSubsteps
        "hooke::springs::implicit::solve_implicit_springs", // SpringNetwork, ImplicitEuler
        "hooke::soft::plugin::apply_elastic_forces", // SoftBody
        "hooke::soft::plugin::solve_implicit",       // SoftBody, ImplicitEuler
        "hooke::soft::plugin::substep_soft_bodies",  // SoftBody, LocalSubsteps
        "hooke::soft::attach::solve_attachments",    // NodeAttachments
        "hooke::collision::nodes::collide_nodes<hooke::soft::SoftBody>", // SoftBody
        "hooke::collision::nodes::coupling::apply_node_impulses", // NodeImpulse
        "hooke::cloth::plugin::apply_wind",          // Cloth
        "hooke::cloth::plugin::limit_strain",        // Cloth
        "hooke::joints::plugin::solve_joints",       // SphericalJoint, RevoluteJoint, FixedJoint
        "hooke::joints::plugin::relax_joints",       // SphericalJoint, RevoluteJoint, FixedJoint
        "hooke::collision::nodes::collide_nodes<hooke::cloth::Cloth>", // Cloth
    ];
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    world.schedule_scope(hooke::core::schedule::SubstepSchedule, |world, schedule| {
        schedule.initialize(world).unwrap();
    });
    let schedules = world.resource::<Schedules>();
    let schedule = schedules
        .get(hooke::core::schedule::SubstepSchedule)
        .unwrap();
    let names: Vec<String> = schedule
        .systems()
        .unwrap()
        .map(|(_, system)| system.name().to_string())
        .collect();
    let decided: Vec<&str> = replicated.iter().chain(&blocking).copied().collect();
    let unknown: Vec<&String> = names
        .iter()
        .filter(|n| !decided.contains(&n.as_str()))
        .collect();
    assert!(
        unknown.is_empty(),
        "substep systems nobody decided on: {unknown:#?}"
    );
    let gone: Vec<&&str> = decided
        .iter()
        .filter(|d| !names.iter().any(|n| n == *d))
        .collect();
    assert!(
        gone.is_empty(),
        "listed but no longer in the schedule: {gone:#?}"
    );
}
