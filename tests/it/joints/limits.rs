//! Sliders, distance joints and joint limits against closed forms, at the defaults.

use bevy_ecs::prelude::*;
use hooke::prelude::*;

use crate::common::default_world;

const G: f32 = 9.81;

fn position(world: &World, e: Entity) -> Vec3A {
    world.get::<Position>(e).unwrap().0
}

fn velocity(world: &World, e: Entity) -> Vec3A {
    world.get::<LinearVelocity>(e).unwrap().0
}

fn assert_live(world: &World, entities: &[Entity]) {
    for &e in entities {
        assert!(world.get::<Quarantined>(e).is_none(), "{e} quarantined");
    }
}

/// A 0.5 m cube (1000 kg/m³: 125 kg) on a world rail tilted `slope` rad below the
/// horizontal (downhill positive) and limited to `-0.1..=stop` m, with Coulomb friction
/// `mu` on the rail: a motor held at zero speed whose force is capped at μ N, the rail's
/// normal force N = m g cos θ (the way Box2D's samples give a joint friction). Returns the
/// world, the cube and the joint.
fn slider_on_incline(slope: f32, mu: f32, stop: f32) -> (World, Entity, Entity) {
    let mut world = default_world();
    let tilt = Quat::from_rotation_z(slope);
    let start = Vec3::new(0.0, 3.0, 0.0);
    let cube = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
            Position(start.into()),
            Rotation(tilt),
        ))
        .id();
    let downhill = tilt * -Vec3::X;
    let friction = mu * 125.0 * G * slope.cos();
    let joint = world
        .spawn(
            PrismaticJoint::to_world(cube, downhill)
                .with_relative(tilt)
                .with_anchors(start, Vec3::ZERO)
                .with_limits(-0.1, stop)
                .with_motor(0.0, friction),
        )
        .id();
    (world, cube, joint)
}

#[test]
fn a_slider_on_an_incline_accelerates_at_g_sin_minus_mu_cos_and_stops_at_its_limit() {
    for (slope, mu) in [(0.5_f32, 0.0_f32), (0.5, 0.2), (1.0, 0.5)] {
        let stop = 2.0_f32;
        let accel = G * (slope.sin() - mu * slope.cos());
        let (mut world, cube, joint) = slider_on_incline(slope, mu, stop);
        let start = position(&world, cube);
        let downhill = Vec3A::from(Quat::from_rotation_z(slope) * -Vec3::X);
        // Free slide for 0.8 s: v = a t, s = a t² / 2 (the stop is at least 1 s away).
        for _ in 0..48 {
            world.step_physics();
        }
        let speed = velocity(&world, cube).dot(downhill);
        let offset = (position(&world, cube) - start).dot(downhill);
        let (t, what) = (0.8, format!("slope {slope} rad, μ {mu}"));
        assert!(
            (speed - accel * t).abs() < 1e-3 * accel,
            "{what}: speed {speed} m/s, closed form {}",
            accel * t
        );
        assert!(
            (offset - 0.5 * accel * t * t).abs() < 0.01 * accel,
            "{what}: offset {offset} m, closed form {}",
            0.5 * accel * t * t
        );
        // Then the limit stops it where it should, and holds it there.
        let mut furthest = offset;
        for _ in 0..150 {
            world.step_physics();
            furthest = furthest.max((position(&world, cube) - start).dot(downhill));
        }
        let offset = (position(&world, cube) - start).dot(downhill);
        assert!(
            furthest < stop + 0.01,
            "{what}: passed its stop: {furthest} m"
        );
        assert!((offset - stop).abs() < 0.005, "{what}: rests at {offset} m");
        assert!(velocity(&world, cube).length() < 0.01, "{what}");
        // At rest against the stop, the stop and the rail's friction together hold the
        // weight along the rail, m g sin θ; static friction may take any share up to μ N,
        // so the stop carries between m g (sin θ − μ cos θ) and m g (sin θ + μ cos θ).
        let impulse = world.get::<JointImpulse>(joint).unwrap();
        let (pull, rub) = (impulse.limit_force(), impulse.motor_force());
        let (weight, normal) = (125.0 * G * slope.sin(), 125.0 * G * slope.cos());
        assert!(
            (pull + rub + weight).abs() < 0.01 * weight,
            "{what}: stop {pull} N and friction {rub} N against the weight's {weight} N"
        );
        assert!(
            -pull > weight - mu * normal - 0.01 * weight
                && -pull < weight + mu * normal + 0.01 * weight,
            "{what}: stop {pull} N"
        );
        let d = world.resource::<JointDiagnostics>();
        assert!(
            d.largest_gap < 0.01 && d.largest_angle < 0.01,
            "{what}: {d:?}"
        );
        assert_live(&world, &[cube, joint]);
    }
}

#[test]
fn a_slider_motor_pushes_at_its_force_then_holds_its_speed() {
    // A 125 kg cube on a horizontal world rail (the joint carries its weight), pushed
    // towards 2 m/s with at most 100 N: a = 0.8 m/s², the target after 2.5 s.
    let mut world = default_world();
    let cube = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
            Position(Vec3A::new(0.0, 3.0, 0.0)),
        ))
        .id();
    let joint = world
        .spawn(
            PrismaticJoint::to_world(cube, Vec3::X)
                .with_anchors(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO)
                .with_motor(2.0, 100.0),
        )
        .id();
    for step in 1..=120 {
        world.step_physics();
        let t = step as f32 / 60.0;
        let v = velocity(&world, cube).x;
        assert!((v - 0.8 * t).abs() < 1e-3, "at {t} s: {v} m/s");
        let force = world.get::<JointImpulse>(joint).unwrap().motor_force();
        assert!((force - 100.0).abs() < 0.1, "motor force {force} N");
    }
    for _ in 0..120 {
        world.step_physics();
    }
    let v = velocity(&world, cube);
    assert!((v.x - 2.0).abs() < 1e-3 && v.y.abs() < 1e-3, "{v}");
    // Its whole force: the weight held up, nothing along the rail at the target.
    let force = world.get::<JointImpulse>(joint).unwrap().force();
    assert!(
        (force - Vec3::new(0.0, 125.0 * G, 0.0)).length() < 0.5,
        "{force}"
    );
    assert_live(&world, &[cube, joint]);
}

/// A rod of 10 kg (0.1 × 1 × 0.1 m) hinged at its top end to the world about z with the
/// hinge limited to `limits`, released from rest at `angle` (rad from hanging).
fn limited_rod(angle: f32, limits: (f32, f32)) -> (World, Entity, Entity) {
    let mut world = default_world();
    let pivot = Vec3::new(0.0, 2.0, 0.0);
    let turn = Quat::from_rotation_z(angle);
    let rod = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.05, 0.5, 0.05).unwrap(),
            Position((pivot + turn * Vec3::new(0.0, -0.5, 0.0)).into()),
            Rotation(turn),
        ))
        .id();
    let joint = world
        .spawn(
            RevoluteJoint::to_world(rod, Vec3::Z)
                .with_anchors(pivot, Vec3::new(0.0, 0.5, 0.0))
                .with_limits(limits.0, limits.1),
        )
        .id();
    (world, rod, joint)
}

fn hinge_angle(world: &World, rod: Entity) -> f32 {
    let q = world.get::<Rotation>(rod).unwrap().0;
    let down = q * Vec3::NEG_Y;
    down.x.atan2(-down.y)
}

#[test]
fn a_hinge_limit_stops_a_falling_rod_and_holds_it_at_the_limit() {
    // Released level, the rod swings down and meets its limit 0.5 rad short of hanging, on
    // either side; it stops there and the limit carries m g d sin(0.5) = 23.5 N·m.
    let torque = 10.0 * G * 0.5 * 0.5_f32.sin();
    for (release, limits, stop) in [
        (1.5_f32, (0.5_f32, 2.0_f32), 0.5_f32),
        (-1.5, (-2.0, -0.5), -0.5),
    ] {
        let (mut world, rod, joint) = limited_rod(release, limits);
        let mut nearest = release.abs();
        for _ in 0..180 {
            world.step_physics();
            nearest = nearest.min(hinge_angle(&world, rod).abs());
            let d = world.resource::<JointDiagnostics>();
            assert!(d.largest_angle < 0.02, "{d:?}");
            assert!(d.largest_gap < 0.005, "{d:?}");
        }
        let angle = hinge_angle(&world, rod);
        assert!(nearest > 0.5 - 0.02, "passed its limit to {nearest} rad");
        assert!(
            (angle - stop).abs() < 0.01,
            "rests at {angle} rad, limit {stop}"
        );
        let spin = world.get::<AngularVelocity>(rod).unwrap().0.length();
        assert!(spin < 0.01, "{spin} rad/s");
        let held = world.get::<JointImpulse>(joint).unwrap().limit_force();
        assert!(
            (held.abs() - torque).abs() < 0.02 * torque && held.signum() == stop.signum(),
            "limit torque {held} N·m, closed form {torque}"
        );
        assert_live(&world, &[rod, joint]);
    }
}

/// K(k), the complete elliptic integral of the first kind.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

#[test]
fn a_ball_on_a_distance_rod_swings_at_the_simple_pendulums_period() {
    // The rod holds the ball's centre, which leaves its turn free: a point pendulum of 1 m,
    // T = 4 √(L/g) K(sin(θ₀/2)).
    for amplitude in [10_f32.to_radians(), 90_f32.to_radians()] {
        let mut world = default_world();
        let pivot = Vec3::new(0.0, 3.0, 0.0);
        let ball = world
            .spawn((
                RigidBody::Dynamic,
                Collider::ball(0.1).unwrap(),
                Position(
                    (pivot + Quat::from_rotation_z(amplitude) * Vec3::new(0.0, -1.0, 0.0)).into(),
                ),
            ))
            .id();
        let rod = world
            .spawn(DistanceJoint::to_world(ball, 1.0).with_anchors(pivot, Vec3::ZERO))
            .id();
        let closed =
            4.0 * (1.0 / f64::from(G)).sqrt() * elliptic_k(f64::from(amplitude / 2.0).sin());
        // Time the ball's crossings of the vertical through the pivot, moving the same way.
        let dt = 1.0 / 60.0;
        let (mut t, mut last_x, mut crossings) = (0.0_f64, position(&world, ball).x, Vec::new());
        while crossings.len() < 6 {
            world.step_physics();
            t += dt;
            let x = position(&world, ball).x;
            if last_x > 0.0 && x <= 0.0 {
                crossings.push(t - dt * f64::from(x / (x - last_x)));
            }
            last_x = x;
            let gap = world.resource::<JointDiagnostics>().largest_gap;
            assert!(gap < 0.005, "the rod stretched {gap} m");
        }
        let period = (crossings[5] - crossings[0]) / 5.0;
        assert!(
            (period / closed - 1.0).abs() < 0.005,
            "amplitude {amplitude}: period {period} s, closed form {closed}"
        );
        assert_live(&world, &[ball, rod]);
    }
}

#[test]
fn a_rope_lets_a_ball_fall_freely_until_taut_and_then_holds_it() {
    // Dropped from 0.2 m below the rope's anchor, the ball falls freely for 0.8 m
    // (0.404 s), then the rope of 1 m catches it and holds its weight.
    let mut world = default_world();
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let ball = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.1).unwrap(),
            Position(Vec3A::new(0.0, 2.8, 0.0)),
        ))
        .id();
    let rope = world
        .spawn(
            DistanceJoint::to_world(ball, 1.0)
                .with_limits(0.0, 1.0)
                .with_anchors(pivot, Vec3::ZERO),
        )
        .id();
    let mass = 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.001;
    let dt = 1.0 / 60.0;
    // The rope is taut within the 25th step: the first 24 are free fall.
    for step in 1..=23 {
        world.step_physics();
        let t = step as f32 * dt;
        let fall = 2.8 - position(&world, ball).y;
        assert!(
            (fall - 0.5 * G * t * t).abs() < 0.01,
            "at {t} s fell {fall} m"
        );
        assert_eq!(
            world.get::<JointImpulse>(rope).unwrap().force(),
            Vec3::ZERO,
            "{:?}",
            world.get::<JointImpulse>(rope)
        );
    }
    let mut longest = 0.0_f32;
    for _ in 0..120 {
        world.step_physics();
        longest = longest.max(pivot.y - position(&world, ball).y);
    }
    assert!(longest < 1.01, "the rope stretched to {longest} m");
    let y = position(&world, ball).y;
    assert!((y - 2.0).abs() < 0.005, "hangs at {y} m");
    let force = world.get::<JointImpulse>(rope).unwrap().force();
    assert!(
        (force.y - mass * G).abs() < 0.01 * mass * G && force.x.abs() < 0.01,
        "{force} N, weight {}",
        mass * G
    );
    assert_live(&world, &[ball, rope]);
}

#[test]
fn a_joint_with_bad_limits_or_axes_is_quarantined_with_its_reason() {
    let mut world = default_world();
    let body = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position(Vec3A::ZERO),
        ))
        .id();
    let cases = [
        (
            world
                .spawn(RevoluteJoint::to_world(body, Vec3::Z).with_limits(1.0, -1.0))
                .id(),
            "min ≤ max",
        ),
        (
            world
                .spawn(RevoluteJoint::to_world(body, Vec3::Z).with_limits(-4.0, 0.0))
                .id(),
            "hinge limits",
        ),
        (
            world.spawn(PrismaticJoint::to_world(body, Vec3::ZERO)).id(),
            "slider axis",
        ),
        (
            world
                .spawn(PrismaticJoint::to_world(body, Vec3::X).with_motor(f32::NAN, 1.0))
                .id(),
            "motor target velocity",
        ),
        (
            world.spawn(DistanceJoint::to_world(body, -1.0)).id(),
            "distance limits",
        ),
    ];
    world.step_physics();
    for (joint, expected) in cases {
        let reason = super::quarantine_reason(&world, joint);
        assert!(reason.contains(expected), "{reason}: expected {expected}");
    }
    assert_live(&world, &[body]);
}

#[test]
fn a_joint_breaks_past_its_force_says_so_once_and_lets_go() {
    // A 10 kg ball (r 0.134 m) hangs on a ball joint rated 150 N: its weight (98.1 N) holds.
    // After 1 s a 100 N pull down is added (198.1 N): the joint breaks in that step, says so
    // once, and the ball falls at g + 10 m/s².
    let mut world = default_world();
    let radius = (10.0 / (1000.0 * 4.0 / 3.0 * std::f32::consts::PI)).cbrt();
    let ball = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(radius).unwrap(),
            Position(Vec3A::new(0.0, 3.0, 0.0)),
        ))
        .id();
    let joint = world
        .spawn((
            SphericalJoint::to_world(ball).with_anchors(Vec3::new(0.0, 3.5, 0.0), Vec3::Y * 0.5),
            JointBreakForce::new(150.0),
        ))
        .id();
    let mut reports = Vec::new();
    let read = |world: &World, reports: &mut Vec<JointBroken>| {
        let messages = world.resource::<Messages<JointBroken>>();
        reports.extend(messages.iter_current_update_messages().copied());
    };
    for _ in 0..60 {
        world.step_physics();
        read(&world, &mut reports);
    }
    assert!(reports.is_empty(), "{reports:?}");
    assert!(world.get::<SphericalJoint>(joint).is_some());
    world
        .entity_mut(ball)
        .insert(hooke::particles::ExternalForce(Vec3::new(0.0, -100.0, 0.0)));
    world.step_physics();
    read(&world, &mut reports);
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert_eq!(reports[0].joint, joint);
    let pull = reports[0].force.y;
    assert!((pull - 198.1).abs() < 2.0, "broke carrying {pull} N");
    assert!(world.get::<SphericalJoint>(joint).is_none());
    let v0 = velocity(&world, ball).y;
    for _ in 0..30 {
        world.step_physics();
        read(&world, &mut reports);
    }
    assert_eq!(reports.len(), 1, "reported again: {reports:?}");
    let fall = v0 - velocity(&world, ball).y;
    assert!(
        (fall - (G + 10.0) * 0.5).abs() < 1e-3,
        "gained {fall} m/s in 0.5 s"
    );
    assert_live(&world, &[ball, joint]);
    // A bad threshold is a typed error, not a joint that never (or always) breaks.
    let bad = world
        .spawn((
            SphericalJoint::to_world(ball),
            JointBreakForce::new(f32::NAN),
        ))
        .id();
    world.step_physics();
    let reason = super::quarantine_reason(&world, bad);
    assert!(reason.contains("joint break force"), "{reason}");
}
