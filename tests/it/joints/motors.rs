//! A hinge's motor against the closed forms of a driven flywheel, at the defaults.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::rigid::{ExternalTorque, Rotation};

use crate::common::default_world;

/// A ball of radius 0.5 m (1000 kg/m³: m = 523.6 kg, I = 2/5 m r² = 52.36 kg·m²) hinged at
/// its centre to the world about z, its motor driving it to `target` rad/s with at most
/// `max_torque` N·m against a load torque `load` N·m about z. Returns the world, the ball,
/// the joint and the ball's moment of inertia about z.
fn flywheel(target: f32, max_torque: f32, load: f32) -> (World, Entity, Entity, f32) {
    let mut world = default_world();
    let ball = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position(Vec3A::new(0.0, 2.0, 0.0)),
            ExternalTorque(Vec3A::new(0.0, 0.0, -load)),
        ))
        .id();
    let joint = world
        .spawn(
            RevoluteJoint::to_world(ball, Vec3::Z)
                .with_anchors(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO)
                .with_motor(target, max_torque),
        )
        .id();
    world.step_physics();
    let inertia = world
        .get::<hooke::rigid::Inertia>(ball)
        .unwrap()
        .tensor()
        .z_axis
        .z;
    (world, ball, joint, inertia)
}

fn spin(world: &World, ball: Entity) -> f32 {
    world.get::<AngularVelocity>(ball).unwrap().0.z
}

#[test]
fn a_hinge_motor_spins_up_at_its_torque_and_holds_its_target_speed() {
    // Unloaded: ω = (τ_max / I) t until the target, then the target. 10 rad/s at 100 N·m on
    // I = 52.36 kg·m²: 5.236 s.
    let (target, max_torque) = (10.0_f32, 100.0_f32);
    let (mut world, ball, joint, inertia) = flywheel(target, max_torque, 0.0);
    let dt = 1.0 / 60.0;
    let mut t = dt;
    let reach = inertia * target / max_torque;
    while t < reach - 0.1 {
        world.step_physics();
        t += dt;
        let expected = max_torque / inertia * t;
        assert!(
            (spin(&world, ball) - expected).abs() < 1e-3 * target,
            "at {t} s: {} rad/s, closed form {expected}",
            spin(&world, ball)
        );
        let torque = world.get::<JointImpulse>(joint).unwrap().motor_torque();
        assert!(
            (torque - max_torque).abs() < 1e-3 * max_torque,
            "{torque} N·m"
        );
    }
    for _ in 0..60 {
        world.step_physics();
    }
    assert!(
        (spin(&world, ball) - target).abs() < 1e-4 * target,
        "{}",
        spin(&world, ball)
    );
    // At speed and unloaded, the motor has nothing left to push.
    let torque = world.get::<JointImpulse>(joint).unwrap().motor_torque();
    assert!(torque.abs() < 1e-2, "{torque} N·m");
}

#[test]
fn a_hinge_motor_holds_against_a_load_below_its_torque_and_stalls_above() {
    let (target, max_torque) = (10.0_f32, 100.0_f32);
    // Below: at speed after spinning up at (τ_max − τ_load) / I, the motor gives τ_load.
    let (mut world, ball, joint, _) = flywheel(target, max_torque, 60.0);
    for _ in 0..20 * 60 {
        world.step_physics();
    }
    assert!(
        (spin(&world, ball) - target).abs() < 1e-4 * target,
        "{}",
        spin(&world, ball)
    );
    let torque = world.get::<JointImpulse>(joint).unwrap().motor_torque();
    assert!((torque - 60.0).abs() < 0.1, "{torque} N·m");
    // Above: the load wins; the wheel turns backwards at α = (τ_max − τ_load) / I.
    let (mut world, ball, joint, inertia) = flywheel(target, max_torque, 150.0);
    let steps = 120;
    for _ in 0..steps {
        world.step_physics();
    }
    let t = (steps + 1) as f32 / 60.0;
    let expected = (max_torque - 150.0) / inertia * t;
    assert!(
        (spin(&world, ball) - expected).abs() < 1e-3 * expected.abs(),
        "{} rad/s, closed form {expected}",
        spin(&world, ball)
    );
    let torque = world.get::<JointImpulse>(joint).unwrap().motor_torque();
    assert!(
        (torque - max_torque).abs() < 1e-3 * max_torque,
        "{torque} N·m"
    );
}

#[test]
fn a_motor_spins_a_wheel_at_a_hundred_radians_a_second_on_a_swinging_arm() {
    // An arm (0.1 × 1 × 0.1 m) hung from the world on a ball joint, let swing from 0.5 rad,
    // with a wheel (a ball of 0.3 m, 113 kg) on a hinge at its lower end driven to 100 rad/s
    // (at most 2,000 N·m) about the arm's x axis: the spinning wheel turns with the arm, so
    // the hinge carries gyroscopic torques of hundreds of N·m. Measured over 5 s: the speed
    // within 0.25 rad/s of the target, the widest gap 8.0 mm (in the first step, the motor at
    // full torque), the hinge axes at most 0.052 rad apart. Before the warm start dropped
    // the hinge's old angular impulse along the turned axis, the wheel ran away past 1,000
    // rad/s.
    let mut world = default_world();
    let tilt = Quat::from_rotation_z(0.5);
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let arm = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.05, 0.5, 0.05).unwrap(),
            Position((pivot + tilt * Vec3::new(0.0, -0.5, 0.0)).into()),
            Rotation(tilt),
        ))
        .id();
    let wheel = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.3).unwrap(),
            Position((pivot + tilt * Vec3::new(0.0, -1.0, 0.0)).into()),
            Rotation(tilt),
        ))
        .id();
    world.spawn(SphericalJoint::to_world(arm).with_anchors(pivot, Vec3::new(0.0, 0.5, 0.0)));
    world.spawn(
        RevoluteJoint::new(arm, wheel, Vec3::X)
            .with_anchors(Vec3::new(0.0, -0.5, 0.0), Vec3::ZERO)
            .with_motor(100.0, 2_000.0),
    );
    let (mut widest, mut angle) = (0.0_f32, 0.0_f32);
    for _ in 0..5 * 60 {
        world.step_physics();
        let d = *world.resource::<JointDiagnostics>();
        widest = widest.max(d.largest_gap);
        angle = angle.max(d.largest_angle);
    }
    for e in [arm, wheel] {
        assert!(world.get::<Quarantined>(e).is_none());
    }
    let w = |e| world.get::<AngularVelocity>(e).unwrap().0;
    let axis = world.get::<Rotation>(arm).unwrap().0 * Vec3A::X;
    let rate = (w(wheel) - w(arm)).dot(axis);
    assert!((rate - 100.0).abs() < 1.0, "{rate} rad/s");
    assert!(widest < 0.01, "the joints parted by {widest} m");
    assert!(angle < 0.1, "the hinge axes came {angle} rad apart");
}

/// The flywheel's turn about its hinge (rad).
fn turn(world: &World, ball: Entity) -> f32 {
    let q = world.get::<Rotation>(ball).unwrap().0;
    2.0 * q.z.atan2(q.w)
}

#[test]
fn a_position_motor_swings_a_flywheel_to_its_angle_as_a_damped_spring() {
    // A servo on the flywheel (I = 52.36 kg·m²): stiffness k = I (2π)² (1 Hz), damping ratio
    // ζ = 0.1, towards 1 rad from rest at 0. Closed form: the first peak at π / ω_d
    // (ω_d = 2π √(1 − ζ²)) overshooting by exp(−ζ π / √(1 − ζ²)) = 72.9 %, then rest at 1 rad.
    // At the defaults (60 Hz × 4) and over frame rates and substeps.
    for (dt, substeps) in [
        (1.0 / 60.0, 4),
        (1.0 / 60.0, 1),
        (1.0 / 30.0, 4),
        (1.0 / 144.0, 2),
    ] {
        let (mut world, ball, joint, inertia) = flywheel(0.0, 0.0, 0.0);
        world.insert_resource(PhysicsTime::new(dt, substeps).unwrap());
        let h = dt / substeps as f32;
        let omega = std::f32::consts::TAU;
        let (k, zeta) = (inertia * omega * omega, 0.1_f32);
        let c = 2.0 * zeta * (k * inertia).sqrt();
        world.get_mut::<RevoluteJoint>(joint).unwrap().motor =
            RevoluteJoint::to_world(ball, Vec3::Z)
                .with_position_motor(1.0, k, c, 1e6)
                .motor;
        let (mut t, mut peak, mut peak_at) = (0.0_f32, 0.0_f32, 0.0_f32);
        let (mut prev, mut falling) = (turn(&world, ball), false);
        let damped = omega * (1.0 - zeta * zeta).sqrt();
        let closed = |t: f32| {
            let ratio = zeta / (1.0 - zeta * zeta).sqrt();
            1.0 - (-zeta * omega * t).exp() * ((damped * t).cos() + ratio * (damped * t).sin())
        };
        let mut worst = 0.0_f32;
        while t < 10.0 {
            world.step_physics();
            t += dt;
            let theta = turn(&world, ball);
            worst = worst.max((theta - closed(t)).abs());
            if !falling && theta < prev {
                falling = true;
                (peak, peak_at) = (prev, t - dt);
            }
            prev = theta;
        }
        let (closed_at, closed_peak) = (
            std::f32::consts::PI / damped,
            1.0 + (-zeta * std::f32::consts::PI / (1.0 - zeta * zeta).sqrt()).exp(),
        );
        println!(
            "1/{:.0} s × {substeps}: first peak {peak:.4} rad at {peak_at:.4} s (closed form {closed_peak:.4} rad at {closed_at:.4} s); at 10 s {:.5} rad; off the closed form by at most {worst:.4} rad",
            1.0 / dt,
            turn(&world, ball)
        );
        assert!(
            (peak_at - closed_at).abs() < 1.5 * dt,
            "peak at {peak_at} s"
        );
        assert!((peak - closed_peak).abs() < 0.005, "peak {peak} rad");
        // Mostly the substep's stagger, h / 2 ahead of the closed form's clock (4.6 rad/s × h/2).
        assert!(
            worst < 0.005 + 2.4 * h,
            "off the closed form by {worst} rad"
        );
    }
}
