//! A ball joint's cone and twist limits: a limb swung into its cone stops dead on the rim and
//! falls back from it as from rest, a limb leaning on its cone rests on the rim with the
//! torque gravity puts there, a twisted limb stops at its twist limit; at the defaults and
//! over frame rates and substeps.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common::{default_world, dynamic, point_of};

/// A world's name and how to make it.
type Setup = (&'static str, fn() -> World);

fn with(dt: f32, substeps: u32) -> World {
    let g = Vec3::new(0.0, -9.81, 0.0);
    scenes::world_with(dt, substeps, Integrator::SymplecticEuler, g).unwrap()
}

fn settings() -> [Setup; 5] {
    [
        ("defaults", default_world),
        ("60 Hz x 1", || with(1.0 / 60.0, 1)),
        ("30 Hz x 4", || with(1.0 / 30.0, 4)),
        ("120 Hz x 2", || with(1.0 / 120.0, 2)),
        ("60 Hz x 8", || with(1.0 / 60.0, 8)),
    ]
}

/// The pivot (m) a 10 kg rod (0.1 × 1 × 0.1 m) hangs from by its top end.
const PIVOT: Vec3 = Vec3::new(0.0, 2.0, 0.0);
const TOP: Vec3 = Vec3::new(0.0, 0.5, 0.0);

/// A rod hung by a ball joint at its top end from [`PIVOT`], turned by `tilt` about z,
/// turning at `omega` about z.
fn rod(world: &mut World, tilt: f32, omega: f32) -> Entity {
    let turn = Quat::from_rotation_z(tilt);
    let centre = PIVOT - turn * TOP;
    let rod = dynamic(world, Collider::cuboid(0.05, 0.5, 0.05).unwrap(), centre);
    let w = Vec3::new(0.0, 0.0, omega);
    let mut e = world.entity_mut(rod);
    e.insert(Rotation(turn));
    e.insert(AngularVelocity(w.into()));
    e.insert(LinearVelocity(w.cross(centre - PIVOT).into()));
    rod
}

/// The angle (rad) between the rod's axis, pivot to tip, and `axis` (world).
fn swing(world: &World, rod: Entity, axis: Vec3) -> f32 {
    let down = world.get::<Rotation>(rod).unwrap().0 * Vec3::NEG_Y;
    down.angle_between(axis)
}

#[test]
fn a_rod_swung_into_its_cone_stops_on_the_rim_and_falls_back_as_from_rest() {
    // The rod hangs straight down in a cone of 30° about −y and is set swinging at 3 rad/s:
    // it would rise to 50°. Stopped dead on the rim at 30°, it falls back from rest there and
    // passes the bottom at ω = √(2 m g (L/2)(1 − cos 30°) / I_pivot) = 1.983 rad/s
    // (I_pivot = m (L² + w²)/12 + m (L/2)²); a rim that bounced would send it back at up to
    // 3 rad/s, one that held it would keep it there.
    let cone = 30f32.to_radians();
    let inertia = (1.01 / 12.0 + 0.25) * 10.0;
    let expected = (2.0 * 10.0 * 9.81 * 0.5 * (1.0 - cone.cos()) / inertia).sqrt();
    for (name, make) in settings() {
        let mut world = make();
        let bar = rod(&mut world, 0.0, 3.0);
        world.spawn(
            SphericalJoint::to_world(bar)
                .with_anchors(PIVOT, TOP)
                .with_axis(Vec3::NEG_Y)
                .with_swing_limit(cone),
        );
        let dt = world.resource::<PhysicsTime>().dt();
        let (mut widest, mut touched, mut fastest_after) = (0.0_f32, false, 0.0_f32);
        let mut drift = 0.0_f32;
        for _ in 0..(2.0 / dt).round() as usize {
            world.step_physics();
            let angle = swing(&world, bar, Vec3::NEG_Y);
            widest = widest.max(angle);
            touched |= angle > cone - 0.01;
            if touched {
                let w = world.get::<AngularVelocity>(bar).unwrap().0;
                fastest_after = fastest_after.max(w.length());
            }
            drift = drift.max(point_of(&world, bar, TOP).distance(PIVOT.into()));
        }
        println!(
            "{name}: widest {:.2}°, fastest after the rim {fastest_after:.3} rad/s (closed form {expected:.3}), drift {:.2} mm",
            widest.to_degrees(),
            drift * 1e3
        );
        assert!(world.get::<Quarantined>(bar).is_none());
        assert!(touched, "{name}: never reached the rim");
        assert!(
            widest < cone + 0.5f32.to_radians(),
            "{name}: swung {:.2}° past a 30° cone",
            widest.to_degrees()
        );
        assert!(
            (fastest_after / expected - 1.0).abs() < 0.03,
            "{name}: {fastest_after} rad/s after the rim against {expected}"
        );
        assert!(drift < 0.01, "{name}: the anchors parted by {drift} m");
    }
}

#[test]
fn a_rod_leaning_on_its_cone_rests_on_the_rim_with_gravitys_torque() {
    // The cone's axis leans 60° from the vertical and opens 20°: the rod, released on the
    // axis, falls onto the rim nearest the vertical and rests there at 40°, the cone holding
    // gravity's torque about the pivot, m g (L/2) sin 40° = 31.53 N·m, and the joint its
    // weight, 98.1 N.
    let (lean, cone) = (60f32.to_radians(), 20f32.to_radians());
    let axis = Quat::from_rotation_z(lean) * Vec3::NEG_Y;
    for (name, make) in settings() {
        let mut world = make();
        let bar = rod(&mut world, lean, 0.0);
        let mut joint = SphericalJoint::to_world(bar)
            .with_anchors(PIVOT, TOP)
            .with_axis(Vec3::NEG_Y)
            .with_swing_limit(cone);
        joint.axis_a = axis;
        let joint = world.spawn(joint).id();
        let dt = world.resource::<PhysicsTime>().dt();
        for _ in 0..(3.0 / dt).round() as usize {
            world.step_physics();
        }
        let rest = swing(&world, bar, Vec3::NEG_Y);
        let impulse = world.get::<JointImpulse>(joint).unwrap();
        let (torque, force) = (impulse.torque(), impulse.force());
        let expected = 10.0 * 9.81 * 0.5 * (lean - cone).sin();
        println!(
            "{name}: rests at {:.3}° from the vertical, torque {torque}, force {force}",
            rest.to_degrees()
        );
        assert!(world.get::<Quarantined>(bar).is_none());
        assert!(
            (rest - (lean - cone)).abs() < 0.2f32.to_radians(),
            "{name}: rests at {}°",
            rest.to_degrees()
        );
        assert!(
            (torque.z / expected - 1.0).abs() < 0.02 && torque.truncate().length() < 0.5,
            "{name}: the cone holds {torque} N·m against {expected}"
        );
        assert!((force.y - 98.1).abs() < 1.0, "{name}: force {force}");
    }
}

#[test]
fn a_spun_bar_stops_dead_at_its_twist_limit() {
    // A 10 kg bar (1 × 0.1 × 0.1 m) hangs level below a ball joint, twisting ±0.3 rad about
    // the vertical at most, and is spun about it at ±2 rad/s: it stops at the limit and stays.
    let limit = 0.3;
    for (name, make) in settings() {
        for spin in [2.0, -2.0] {
            let mut world = make();
            let anchor = Vec3::new(0.0, 0.1, 0.0);
            let bar = dynamic(
                &mut world,
                Collider::cuboid(0.5, 0.05, 0.05).unwrap(),
                PIVOT - anchor,
            );
            world
                .entity_mut(bar)
                .insert(AngularVelocity(Vec3A::new(0.0, spin, 0.0)));
            world.spawn(
                SphericalJoint::to_world(bar)
                    .with_anchors(PIVOT, anchor)
                    .with_axis(Vec3::NEG_Y)
                    .with_twist_limits(-limit, limit),
            );
            let dt = world.resource::<PhysicsTime>().dt();
            let (mut past, mut tilt) = (0.0_f32, 0.0_f32);
            for _ in 0..(1.5 / dt).round() as usize {
                world.step_physics();
                let q = world.get::<Rotation>(bar).unwrap().0;
                let twist = 2.0 * q.y.atan2(q.w);
                past = past.max(twist.abs() - limit);
                tilt = tilt.max(swing(&world, bar, Vec3::NEG_Y));
            }
            let q = world.get::<Rotation>(bar).unwrap().0;
            let twist = 2.0 * q.y.atan2(q.w);
            let w = world.get::<AngularVelocity>(bar).unwrap().0;
            println!(
                "{name}, {spin} rad/s: past the limit by {past:.4} rad, rests at {twist:.4} rad turning at {w}"
            );
            assert!(world.get::<Quarantined>(bar).is_none());
            assert!(past < 0.005, "{name}, {spin}: past the limit by {past} rad");
            assert!(
                (twist - limit * spin.signum()).abs() < 0.002,
                "{name}, {spin}: rests at {twist} rad"
            );
            assert!(w.length() < 0.01, "{name}, {spin}: still turning at {w}");
            assert!(tilt < 1e-3, "{name}, {spin}: tilted {tilt} rad");
        }
    }
}

#[test]
fn a_ball_joint_with_bad_limits_is_quarantined_with_its_reason() {
    let mut world = default_world();
    let body = dynamic(&mut world, Collider::ball(0.5).unwrap(), Vec3::ZERO);
    let mut bad = |joint: SphericalJoint, names| (world.spawn(joint).id(), names);
    let ball = SphericalJoint::to_world(body);
    let cases = [
        bad(ball.with_swing_limit(0.0), "swing limit"),
        bad(ball.with_swing_limit(f32::NAN), "swing limit"),
        bad(ball.with_twist_limits(0.5, -0.5), "twist limits"),
        bad(ball.with_axis(Vec3::ZERO), "ball joint axis a"),
        bad(ball.with_friction(-1.0), "joint friction torque"),
    ];
    world.step_physics();
    super::assert_quarantined_for(&world, &cases);
    assert!(world.get::<Quarantined>(body).is_none());
}

#[test]
fn a_ball_joints_friction_slows_a_spin_at_its_torque_over_the_inertia() {
    // A 523.6 kg ball (r = 0.5 m, I = 2/5 m r² = 52.36 kg·m²) held at its centre by a ball
    // joint with 10 N·m of friction, spun at 2 rad/s: ω(t) = 2 − (10 / I) t, still at 10.47 s.
    let inertia = 0.4 * 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.125 * 0.25;
    for (name, make) in settings() {
        let mut world = make();
        let ball = dynamic(&mut world, Collider::ball(0.5).unwrap(), PIVOT);
        let axis = Vec3::new(1.0, 1.0, 0.0).normalize();
        world
            .entity_mut(ball)
            .insert(AngularVelocity((2.0 * axis).into()));
        world.spawn(
            SphericalJoint::to_world(ball)
                .with_anchors(PIVOT, Vec3::ZERO)
                .with_friction(10.0),
        );
        let dt = world.resource::<PhysicsTime>().dt();
        for _ in 0..(5.0 / dt).round() as usize {
            world.step_physics();
        }
        let w = Vec3::from(world.get::<AngularVelocity>(ball).unwrap().0);
        let expected = 2.0 - 10.0 / inertia * 5.0;
        println!("{name}: {w} at 5 s, closed form {expected} along {axis}");
        assert!(
            (w.length() / expected - 1.0).abs() < 0.01 && w.normalize().dot(axis) > 0.9999,
            "{name}: {w} against {expected}"
        );
        for _ in 0..(7.0 / dt).round() as usize {
            world.step_physics();
        }
        let w = world.get::<AngularVelocity>(ball).unwrap().0;
        assert!(w.length() < 1e-3, "{name}: still turning at {w} at 12 s");
    }
}
