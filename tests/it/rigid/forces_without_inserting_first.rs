//! `BodyForces` pushes a body that has no `ExternalForce`, `ExternalTorque` or
//! `ExternalImpulse` yet, from `Commands` as from a `World`: the motion is F t / m, J / m
//! and τ t / I. (A `Query<&mut ExternalForce>` finds nothing on such a body.)

use bevy_ecs::prelude::*;
use hooke::prelude::*;

fn body(world: &mut World) -> Entity {
    world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Mass::new(2.0).unwrap(),
        ))
        .id()
}

#[derive(Resource)]
struct Target(Entity);

fn push_once(mut commands: Commands, target: Res<Target>, mut done: Local<bool>) {
    if !*done {
        *done = true;
        commands
            .entity(target.0)
            .set_force(Vec3::new(4.0, 0.0, 0.0))
            .set_torque(Vec3::new(0.0, 0.1, 0.0))
            .apply_impulse(Vec3::new(0.0, 0.0, 1.0))
            .apply_impulse(Vec3::new(0.0, 0.0, 1.0));
    }
}

#[test]
fn a_system_pushes_a_body_it_never_gave_forces() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    world.insert_resource(Gravity::ZERO);
    let e = body(&mut world);
    assert!(world.get::<ExternalForce>(e).is_none());
    world.insert_resource(Target(e));
    let mut schedule = Schedule::default();
    schedule.add_systems(push_once);
    schedule.run(&mut world);
    for _ in 0..60 {
        world.step_physics();
    }
    // One second: v = F t / m + J / m (two impulses of 1 N·s), ω = τ t / I with
    // I = 2/5 m r² = 0.2 kg·m².
    let v = world.get::<LinearVelocity>(e).unwrap().get();
    assert!((v - Vec3::new(2.0, 0.0, 1.0)).length() < 1e-3, "{v}");
    let w = Vec3::from(world.get::<AngularVelocity>(e).unwrap().0);
    assert!((w - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-3, "{w}");
}

#[test]
fn a_bad_force_is_a_typed_quarantine_not_a_panic() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    let e = body(&mut world);
    world.entity_mut(e).set_force(Vec3::new(f32::NAN, 0.0, 0.0));
    world.step_physics();
    let reason = &world.get::<Quarantined>(e).expect("quarantined").reason;
    assert!(
        format!("{reason:?}").contains("external force"),
        "{reason:?}"
    );
}
