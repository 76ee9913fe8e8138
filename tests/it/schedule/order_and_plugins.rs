//! The schedule: no ambiguities, determinism, and effects that only run when needed.

use crate::common;

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use hooke::core::schedule::ForceSchedule;
use hooke::core::schedule::PhysicsSchedule;
use hooke::core::schedule::SubstepSchedule;
use hooke::prelude::*;
use hooke::tools::scenes;

fn assert_no_ambiguities(world: &mut World, label: impl ScheduleLabel + Clone) {
    let result = world.schedule_scope(label.clone(), |world, schedule| {
        schedule
            .initialize(world)
            .map(|_| schedule.graph().conflicting_systems().len())
            .map_err(|e| e.to_string(schedule.graph(), world))
    });
    assert_eq!(result, Ok(0), "{label:?}");
}

#[test]
fn schedules_have_no_ambiguities() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    // Built with ambiguity detection set to error, so initialize fails on any ambiguity.
    assert_no_ambiguities(&mut world, PhysicsSchedule);
    assert_no_ambiguities(&mut world, SubstepSchedule);
    assert_no_ambiguities(&mut world, ForceSchedule);
}

fn run_showcase(steps: usize) -> Vec<u32> {
    let mut world = common::gravity_world(4);
    scenes::showcase(&mut world).unwrap();
    scenes::cloth(&mut world, 10).unwrap();
    for _ in 0..steps {
        world.step_physics();
    }
    let mut bits: Vec<u32> = Vec::new();
    let mut q = world.query::<(Entity, &Position)>();
    let mut rows: Vec<_> = q.iter(&world).map(|(e, p)| (e, p.0)).collect();
    rows.sort_by_key(|r| r.0);
    for (_, p) in rows {
        bits.extend(p.to_array().map(f32::to_bits));
    }
    for nodes in world.query::<&Nodes>().iter(&world) {
        for x in nodes.positions() {
            bits.extend(x.to_array().map(f32::to_bits));
        }
    }
    bits
}

#[test]
fn same_inputs_give_bit_identical_results() {
    let a = run_showcase(300);
    let b = run_showcase(300);
    assert!(a.len() > 100);
    assert_eq!(a, b);
}

/// The pile scene with sleeping on: coloured SIMD contact batches, four-point manifolds,
/// islands falling asleep, and a late ball that wakes them within the step.
fn run_pile(steps: usize) -> (Vec<u32>, usize) {
    let mut world = common::gravity_world(4);
    let (boxes, _) = scenes::pile_scene(&mut world, 40, 10).unwrap();
    let mut slept = 0;
    for step in 0..steps {
        if step == steps / 2 {
            let ball = scenes::dynamic_ball(&mut world, 0.3, Vec3::new(-8.0, 0.3, 0.0)).unwrap();
            world.get_mut::<LinearVelocity>(ball).unwrap().0 = glam::Vec3A::new(12.0, 0.0, 0.0);
        }
        world.step_physics();
        slept = slept.max(
            boxes
                .iter()
                .filter(|&&b| world.get::<hooke::core::rest::Sleeping>(b).is_some())
                .count(),
        );
    }
    let mut bits: Vec<u32> = Vec::new();
    let mut q = world.query::<(Entity, &Position, &Rotation, &LinearVelocity)>();
    let mut rows: Vec<_> = q
        .iter(&world)
        .map(|(e, p, r, v)| (e, p.0, r.0, v.0))
        .collect();
    rows.sort_by_key(|r| r.0);
    for (_, p, r, v) in rows {
        bits.extend(p.to_array().map(f32::to_bits));
        bits.extend(r.to_array().map(f32::to_bits));
        bits.extend(v.to_array().map(f32::to_bits));
    }
    (bits, slept)
}

#[test]
fn contact_scenes_with_sleeping_are_bit_identical_from_run_to_run() {
    let (a, slept) = run_pile(600);
    let (b, _) = run_pile(600);
    assert!(
        slept > 0,
        "nothing fell asleep: the sleep and wake paths went untested"
    );
    assert_eq!(a, b);
}

#[test]
fn plugins_are_added_once_and_a_world_without_physics_steps_harmlessly() {
    let mut world = World::new();
    world.step_physics();
    assert!(world.advance_physics(1.0).unwrap().steps == 0);
    world
        .add_physics(PhysicsPlugins)
        .add_physics(PhysicsPlugins)
        .add_physics(hooke::particles::GravityPlugin);
    let e = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    world.step_physics();
    // Gravity added once: v = −g h, not −2 g h.
    let v = world.get::<LinearVelocity>(e).unwrap().0.y;
    assert!((v + 9.81 / 60.0).abs() < 1e-6, "{v}");
}

#[test]
fn a_scene_gets_only_the_plugins_it_asks_for() {
    // No gravity plugin: a particle with an external force moves, but doesn't fall.
    let mut world = World::new();
    world.add_physics(hooke::core::plugin::PhysicsCorePlugin);
    let e = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap(),
            ExternalForce(Vec3::X),
        ))
        .id();
    for _ in 0..60 {
        world.step_physics();
    }
    let p = world.get::<Position>(e).unwrap().0;
    assert!(p.x > 0.4 && p.y == 0.0, "{p}");
}

#[test]
fn diagnostics_report_energy_counts_and_set_timings() {
    let mut world = scenes::world_with(
        1.0 / 60.0,
        2,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let scene = scenes::showcase(&mut world).unwrap();
    scenes::cloth(&mut world, 8).unwrap();
    world.step_physics();
    let d = world.resource::<PhysicsDiagnostics>();
    let c = d.counts;
    assert_eq!(
        c.particles,
        scene.rope.nodes.len() + scene.hair.nodes.len() + scene.particles.len()
    );
    assert_eq!(c.tracers, scene.tracers.len());
    assert_eq!(
        c.springs,
        scene.rope.springs.len()
            + scene.rope.bend_springs.len()
            + scene.hair.springs.len()
            + scene.hair.bend_springs.len()
    );
    assert_eq!((c.meshes, c.mesh_nodes), (1, 64));
    assert!(c.mesh_springs > 0);
    assert!(d.kinetic_energy > 0.0 && d.spring_energy >= 0.0);
    assert!(d.step_time > std::time::Duration::ZERO);
    assert!(
        d.set_time(hooke::core::schedule::StepSystems::ApplyForces) > std::time::Duration::ZERO
    );
    assert!(
        d.set_time(hooke::core::schedule::StepSystems::IntegrateVelocities)
            > std::time::Duration::ZERO
    );
}
