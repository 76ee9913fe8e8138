//! A world of joints continues bit for bit from its snapshot: every kind, with motors,
//! limits, a breaking threshold, a sleeping chain woken after the snapshot and contacts.

use bevy_ecs::prelude::*;
use hooke::prelude::*;

use super::continue_bit_identically::{round_trip, via_bytes, via_ron};
use crate::common::dynamic as body;

fn bar(w: &mut World, x: Vec3) -> Entity {
    body(w, Collider::cuboid(0.5, 0.1, 0.1).unwrap(), x)
}

/// Every joint kind at work beside the ground.
fn machine(w: &mut World) {
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(50.0, 0.5, 50.0).unwrap(),
        Position(Vec3A::new(0.0, -0.5, 0.0)),
    ));
    // A chain lying on the ground: it falls asleep before the snapshot.
    let links: Vec<Entity> = (0..4)
        .map(|i| bar(w, Vec3::new(i as f32 * 1.05, 0.1, 4.0)))
        .collect();
    for pair in links.windows(2) {
        w.spawn(
            SphericalJoint::new(pair[0], pair[1])
                .with_anchors(Vec3::new(0.525, 0.0, 0.0), Vec3::new(-0.525, 0.0, 0.0)),
        );
    }
    // A door on a motored, limited hinge.
    let door = body(
        w,
        Collider::cuboid(0.5, 1.0, 0.05).unwrap(),
        Vec3::new(-3.0, 1.2, 0.0),
    );
    w.spawn(
        RevoluteJoint::to_world(door, Vec3::Y)
            .with_anchors(Vec3::new(-3.5, 1.2, 0.0), Vec3::new(-0.5, 0.0, 0.0))
            .with_motor(2.0, 50.0)
            .with_limits(-1.0, 1.0),
    );
    // A pendulum of two bars on ball joints, the second welded to a box.
    let upper = bar(w, Vec3::new(3.5, 4.0, 0.0));
    let lower = bar(w, Vec3::new(4.55, 4.0, 0.0));
    let weight = body(
        w,
        Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
        Vec3::new(5.3, 4.0, 0.0),
    );
    w.spawn(
        SphericalJoint::to_world(upper)
            .with_anchors(Vec3::new(2.975, 4.0, 0.0), Vec3::new(-0.525, 0.0, 0.0)),
    );
    w.spawn(
        SphericalJoint::new(upper, lower)
            .with_anchors(Vec3::new(0.525, 0.0, 0.0), Vec3::new(-0.525, 0.0, 0.0)),
    );
    w.spawn(
        FixedJoint::new(lower, weight, Quat::IDENTITY)
            .with_anchors(Vec3::new(0.5, 0.0, 0.0), Vec3::new(-0.25, 0.0, 0.0)),
    );
    // A slider driven into its stop, and a ball dropped onto the end of a rope.
    let carriage = body(
        w,
        Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
        Vec3::new(0.0, 3.0, -3.0),
    );
    w.spawn(
        PrismaticJoint::to_world(carriage, Vec3::X)
            .with_anchors(Vec3::new(0.0, 3.0, -3.0), Vec3::ZERO)
            .with_motor(1.0, 40.0)
            .with_limits(-1.0, 1.5),
    );
    let ball = body(w, Collider::ball(0.2).unwrap(), Vec3::new(0.0, 5.0, 6.0));
    w.spawn(
        DistanceJoint::to_world(ball, 1.0)
            .with_anchors(Vec3::new(0.0, 5.5, 6.0), Vec3::ZERO)
            .with_limits(0.0, 1.0),
    );
    // A joint that breaks after the snapshot: a box hung by a thread that holds 1.5 times
    // its weight, pulled down harder from step 150 on by a box dropped onto it.
    let hung = body(
        w,
        Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
        Vec3::new(-3.0, 1.0, 5.0),
    );
    w.spawn((
        SphericalJoint::to_world(hung)
            .with_anchors(Vec3::new(-3.0, 1.5, 5.0), Vec3::new(0.0, 0.2, 0.0)),
        JointBreakForce::new(1.5 * 64.0 * 9.81),
    ));
    body(
        w,
        Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
        Vec3::new(-3.0, 16.0, 5.0),
    );
}

/// After the sleeping chain has slept: a ball rolled at it, to hit after the snapshot.
fn roll_a_ball(w: &mut World) {
    w.spawn((
        RigidBody::Dynamic,
        Collider::ball(0.1).unwrap(),
        Position(Vec3A::new(8.0, 0.1, 4.0)),
        LinearVelocity(Vec3A::new(-1.5, 0.0, 0.0)),
    ));
}

/// The scene does what the test says: the chain sleeps by the snapshot (step 100) and wakes
/// after it, the thread breaks after it, and every joint but the thread stays on.
#[test]
fn the_joint_machine_sleeps_wakes_and_breaks_after_the_snapshot() {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    machine(&mut w);
    let mut sleepers = w.query_filtered::<(), With<hooke::core::rest::Sleeping>>();
    let mut joints = w.query::<&JointImpulse>();
    let (mut asleep_at_100, mut woke_after, mut joints_at_100) = (0, false, 0);
    for step in 0..600 {
        if step == 50 {
            roll_a_ball(&mut w);
        }
        w.step_physics();
        let asleep = sleepers.iter(&w).count();
        if step == 99 {
            asleep_at_100 = asleep;
            joints_at_100 = joints.iter(&w).filter(|j| j.h > 0.0).count();
        }
        woke_after |= step > 99 && asleep < asleep_at_100;
    }
    let kinds = w
        .query_filtered::<(), Or<(With<SphericalJoint>, With<RevoluteJoint>)>>()
        .iter(&w)
        .count();
    assert!(
        asleep_at_100 >= 4,
        "{asleep_at_100} bodies asleep at the snapshot"
    );
    assert!(woke_after, "nothing woke after the snapshot");
    assert_eq!(joints_at_100, 10, "joints at work at the snapshot");
    assert_eq!(kinds, 6, "the thread should have broken and nothing else");
}

#[test]
fn every_joint_kind_continues_bit_identically_through_bytes_and_ron() {
    let (n, a) = round_trip(machine, roll_a_ball, via_bytes);
    assert!(n > 20, "{n} entities");
    let (_, b) = round_trip(machine, roll_a_ball, via_ron);
    assert_eq!(a, b, "the two formats restore the same state");
}
