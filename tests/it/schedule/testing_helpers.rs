//! `hooke::tools::testing`: runs counted in whole steps, and short reads of a body's state.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::testing::PhysicsTestExt;

fn world() -> World {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w
}

/// 180 steps read 3.0000001564621925 s on `PhysicsTime::elapsed` (the f32 step); the
/// helpers count 60 steps a second exactly.
#[test]
fn seconds_are_whole_steps() {
    let mut w = world();
    assert_eq!(w.steps_for(3.0).unwrap(), 180);
    assert_eq!(w.steps_for(1.0).unwrap(), 60);
    assert_eq!(w.steps_for(0.0).unwrap(), 0);
    assert_eq!(w.run_for_seconds(1.0).unwrap(), 60);
    assert_eq!(w.resource::<PhysicsTime>().steps(), 60);
    w.insert_resource(PhysicsTime::new(1.0 / 240.0, 1).unwrap());
    assert_eq!(w.steps_for(0.5).unwrap(), 120);
}

/// A thrown particle, symplectic Euler with 4 substeps: x and v after 1 s against the
/// closed form (v exact; x off by g h t / 2, h the substep).
#[test]
fn run_for_seconds_reaches_the_closed_form_projectile() {
    let mut w = world();
    let v0 = Vec3::new(3.0, 10.0, 0.0);
    let p = w
        .spawn(ParticleBundle::new(Vec3::ZERO, v0, 2.0).unwrap())
        .id();
    w.run_for_seconds(1.0).unwrap();
    let g = 9.81f32;
    let v = w.velocity_of(p).unwrap();
    assert!((v - (v0 - Vec3::Y * g)).length() < 1e-4, "{v}");
    let x = w.position_of(p).unwrap();
    let exact = v0 - Vec3::Y * (0.5 * g);
    let h = 1.0 / 240.0;
    assert!((x - exact).length() < 0.5 * g * h + 1e-4, "{x} vs {exact}");
    assert_eq!(w.rotation_of(p), None);
    assert_eq!(w.angular_velocity_of(p), None);
}

/// A particle dropped from 10 m crosses y = 0 at t = √(2h/g) = 1.428 s: step 86 at 60 Hz.
#[test]
fn run_until_returns_the_step_the_condition_first_held() {
    let mut w = world();
    let p = w
        .spawn(ParticleBundle::new(Vec3::Y * 10.0, Vec3::ZERO, 1.0).unwrap())
        .id();
    let below = |w: &World| w.position_of(p).is_some_and(|x| x.y < 0.0);
    let step = w.run_until(5.0, below).unwrap().expect("it lands in time");
    let t = (2.0 * 10.0 / 9.81f64).sqrt();
    assert!(
        (step as f64 - t * 60.0).abs() <= 1.0,
        "step {step} vs {:.1}",
        t * 60.0
    );
    // Already true: no step taken.
    assert_eq!(w.run_until(5.0, below).unwrap(), Some(0));
    // Never true within the time: None after exactly that many steps.
    let before = w.resource::<PhysicsTime>().steps();
    assert_eq!(w.run_until(0.5, |_| false).unwrap(), None);
    assert_eq!(w.resource::<PhysicsTime>().steps() - before, 30);
}

#[test]
fn bad_times_and_worlds_without_physics_are_errors() {
    let mut w = world();
    for bad in [f64::NAN, -1.0, f64::INFINITY, 1e300, 1e30] {
        assert!(w.run_for_seconds(bad).is_err(), "{bad}");
        assert!(w.run_until(bad, |_| true).is_err(), "{bad}");
    }
    let mut bare = World::new();
    let e = bare.run_for_seconds(1.0).unwrap_err();
    assert!(matches!(e, hooke::Error::NoPhysics), "{e}");
    let gone = w.spawn_empty().id();
    w.despawn(gone);
    assert_eq!(w.position_of(gone), None);
}

/// A spinning rigid body: the accessors read pose and angular velocity.
#[test]
fn rigid_accessors_read_pose_and_spin() {
    let mut w = world();
    w.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let b = hooke::tools::scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::Y).unwrap();
    w.get_mut::<AngularVelocity>(b).unwrap().0 = Vec3A::new(0.0, 1.0, 0.0);
    w.run_for_seconds(1.0).unwrap();
    let (angle_axis, angle) = w.rotation_of(b).unwrap().to_axis_angle();
    assert!(
        (angle - 1.0).abs() < 1e-3 && angle_axis.y > 0.999,
        "{angle}"
    );
    assert!((w.angular_velocity_of(b).unwrap() - Vec3::Y).length() < 1e-5);
    assert_eq!(w.position_of(b), Some(Vec3::Y));
}

/// Mass without digging the shape out of the collider: a 1 m cube at 1000 kg/m³ is a tonne,
/// a pinned particle infinite, a world entity without mass None.
#[test]
fn mass_of_reads_the_mass_the_colliders_gave() {
    let mut w = world();
    let b = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Position::from(Vec3::Y),
        ))
        .id();
    let pin = w.spawn(ParticleBundle::pinned(Vec3::ZERO).unwrap()).id();
    let nothing = w.spawn(()).id();
    assert!((w.mass_of(b).unwrap() - 1000.0).abs() < 0.01);
    assert_eq!(w.mass_of(pin), Some(f32::INFINITY));
    assert_eq!(w.mass_of(nothing), None);
}
