//! `Reflect` on hooke's components and resources (feature `bevy`): an inspector and Bevy
//! scenes see them through the App's type registry.
#![cfg(feature = "bevy")]

use bevy_app::prelude::*;
use bevy_ecs::reflect::{AppTypeRegistry, ReflectComponent, ReflectResource};
use bevy_time::TimePlugin;
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use hooke::prelude::*;

/// hooke's crate-private components and resources (caches, schedules' bookkeeping): not
/// part of the API, not reflected. A public one missing from the registry fails the test.
const INTERNAL: &[&str] = &[
    "hooke::bevy::MessagesRegistered",
    "hooke::bevy::AppSchedule",
    "hooke::core::plugin::Installed",
    "hooke::core::restore::Restorers",
    "hooke::core::restore::Restoring",
    "hooke::core::diagnostics::SetClock",
    "hooke::core::schedule::OwnSubstepSystems",
    "hooke::core::whole_step::WholeStepBlockers",
    "hooke::core::whole_step::WholeStepRunner",
    "hooke::integrator::stages::Rk4Starts",
    "hooke::integrator::stages::Rk4TurnStarts",
    "hooke::integrator::stability::SharedNumericalDamping",
    "hooke::springs::local::LocalCorrections",
    "hooke::springs::entity_implicit::EntitySpringFactor",
    "hooke::particles::MassOptional",
    "hooke::collision::solver::ContactSolver",
    "hooke::collision::solver::whole_step::Cache",
    "hooke::collision::nodes::coupling::NodeImpulse",
    "hooke::collision::broad_phase::BroadPhase",
    "hooke::collision::coincident::RecentSpawns",
    "hooke::collision::attach::OwnShape",
    "hooke::joints::plugin::Scratch",
    "hooke::bevy::transform::TargetFromTransform",
    "hooke::bevy::transform::ScaleReported",
    "hooke::rigid::mass::ComputedMass",
];

fn app() -> App {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
    app.finish();
    app.cleanup();
    app
}

#[test]
fn every_hooke_component_and_resource_in_a_busy_world_is_registered_for_reflection() {
    let mut app = app();
    let world = app.world_mut();
    world.spawn((
        RigidBody::Static,
        Collider::cuboid(5.0, 0.5, 5.0).unwrap(),
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    let a = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.3).unwrap(),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    let b = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
            Transform::from_xyz(1.0, 2.0, 0.0),
        ))
        .id();
    world.spawn(
        RevoluteJoint::new(a, b, Vec3::Z)
            .with_anchors(Vec3::new(0.5, 0.0, 0.0), Vec3::new(-0.5, 0.0, 0.0)),
    );
    ClothBuilder::new(Vec3::new(3.0, 3.0, 0.0), 4, 4, 0.1)
        .spawn(world)
        .unwrap();
    ChainBuilder::rope(Vec3::new(-3.0, 3.0, 0.0), Vec3::new(-2.0, 3.0, 0.0), 5)
        .spawn(world)
        .unwrap();
    hooke::tools::scenes::jelly(world, Vec3::new(-3.0, 1.0, 3.0), true).unwrap();
    for _ in 0..5 {
        app.update();
    }
    let world = app.world();
    let registry = world.resource::<AppTypeRegistry>().read();
    let mut missing = Vec::new();
    let mut seen = 0;
    for (_, info) in world.components().iter_registered() {
        let name = info.name().to_string();
        if !name.starts_with("hooke::") || INTERNAL.contains(&name.as_str()) {
            continue;
        }
        let Some(id) = info.type_id() else { continue };
        seen += 1;
        let ok = registry.get(id).is_some_and(|r| {
            r.data::<ReflectComponent>().is_some() || r.data::<ReflectResource>().is_some()
        });
        if !ok {
            missing.push(name);
        }
    }
    assert!(seen > 40, "{seen} hooke components and resources");
    assert!(missing.is_empty(), "not reflected: {missing:#?}");
}

#[test]
fn an_inspector_edit_through_reflection_moves_the_body() {
    let mut app = app();
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.3).unwrap(),
            Transform::from_xyz(0.0, 5.0, 0.0),
        ))
        .id();
    app.update();
    // What an inspector does: find the component's reflection by type name, read it, write
    // a new value into it.
    let registry = app.world().resource::<AppTypeRegistry>().clone();
    let registry = registry.read();
    let registration = registry
        .get_with_short_type_path("Position")
        .expect("Position is registered");
    let reflect = registration
        .data::<ReflectComponent>()
        .expect("as a component");
    let mut entity = app.world_mut().entity_mut(body);
    let mut position = reflect.reflect_mut(&mut entity).expect("the body has one");
    let x = position.reflect_mut().as_tuple_struct().unwrap();
    let value = x.field_mut(0).unwrap();
    value.apply(&Vec3A::new(7.0, 5.0, -2.0));
    drop(registry);
    let at = app.world().get::<Position>(body).unwrap().get();
    assert_eq!(at, Vec3::new(7.0, 5.0, -2.0));
    // The collider's shape is reflected as an opaque value: an inspector shows it, and a
    // scene clones it.
    let collider = app.world().get::<Collider>(body).unwrap();
    let cloned = bevy_reflect::PartialReflect::reflect_clone(collider).unwrap();
    assert!(cloned.downcast_ref::<Collider>().is_some());
}
