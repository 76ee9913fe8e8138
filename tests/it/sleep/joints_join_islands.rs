//! Joints join islands: a jointed chain sleeps whole and wakes whole, a body hung on a moving
//! kinematic body stays with it, and taking a joint off wakes what it held. At the defaults.

use bevy_ecs::prelude::*;
use hooke::core::rest::Sleeping;
use hooke::prelude::*;

use crate::common::{default_world, dynamic, point_of};

fn asleep(w: &World, e: Entity) -> bool {
    w.get::<Sleeping>(e).is_some()
}

/// Links of the chain on the ground: bars 1 m × 0.2 m × 0.2 m, 5 cm apart along x.
const LINKS: usize = 5;
const PITCH: f32 = 1.05;

/// A chain of bars lying on the ground, ball-jointed end to end, its bars spawned in
/// `order`; returns the bars from the chain's start (x = 0) to its end.
fn chain_on_ground(w: &mut World, order: &[usize]) -> Vec<Entity> {
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(50.0, 0.5, 50.0).unwrap(),
        Position(Vec3A::new(0.0, -0.5, 0.0)),
    ));
    let mut bars = vec![Entity::PLACEHOLDER; LINKS];
    for &i in order {
        bars[i] = dynamic(
            w,
            Collider::cuboid(0.5, 0.1, 0.1).unwrap(),
            Vec3::new(i as f32 * PITCH, 0.1, 0.0),
        );
    }
    for &i in order.iter().filter(|&&i| i + 1 < LINKS) {
        w.spawn(SphericalJoint::new(bars[i], bars[i + 1]).with_anchors(
            Vec3::new(0.5 * PITCH, 0.0, 0.0),
            Vec3::new(-0.5 * PITCH, 0.0, 0.0),
        ));
    }
    bars
}

#[test]
fn a_jointed_chain_sleeps_and_wakes_whole_in_any_spawn_order() {
    for order in [[0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [2, 0, 4, 1, 3]] {
        let mut w = default_world();
        let bars = chain_on_ground(&mut w, &order);
        let all_or_none = |w: &World, when: &str| {
            let sleeping = bars.iter().filter(|&&e| asleep(w, e)).count();
            assert!(
                sleeping == 0 || sleeping == LINKS,
                "order {order:?}, {when}: {sleeping} of {LINKS} links asleep"
            );
            sleeping == LINKS
        };
        let mut slept = false;
        for _ in 0..120 {
            w.step_physics();
            slept = all_or_none(&w, "settling");
        }
        assert!(slept, "order {order:?}: the resting chain never slept");
        // A ball rolled at the chain's end: every link wakes in the same step as the one hit,
        // and the hit reaches the chain's start through the joints.
        let start = w.get::<Position>(bars[0]).unwrap().0;
        let end = (LINKS - 1) as f32 * PITCH;
        w.spawn((
            RigidBody::Dynamic,
            Collider::ball(0.1).unwrap(),
            Position(Vec3A::new(end + 1.5, 0.1, 0.0)),
            LinearVelocity(Vec3A::new(-10.0, 0.0, 0.0)),
        ));
        let mut woke = false;
        for _ in 0..30 {
            w.step_physics();
            woke |= !all_or_none(&w, "after the hit");
        }
        assert!(woke, "order {order:?}: the hit never woke the chain");
        let moved = (w.get::<Position>(bars[0]).unwrap().0 - start).length();
        assert!(
            moved > 1e-3,
            "order {order:?}: the chain's start moved {moved} m"
        );
    }
}

#[test]
fn a_body_hung_on_a_kinematic_body_follows_it_when_it_starts_moving() {
    // The carrier with and without a collider: an island member that never sleeps, and a
    // body outside the islands.
    for carrier_collides in [true, false] {
        let mut w = default_world();
        let top = Vec3A::new(0.0, 3.0, 0.0);
        let mut carrier = w.spawn((RigidBody::Kinematic, Position(top)));
        if carrier_collides {
            carrier.insert(Collider::ball(0.1).unwrap());
        }
        let carrier = carrier.id();
        let bob = dynamic(
            &mut w,
            Collider::cuboid(0.1, 0.5, 0.1).unwrap(),
            Vec3::from(top) - Vec3::new(0.0, 0.5, 0.0),
        );
        let (anchor_a, anchor_b) = (Vec3::ZERO, Vec3::new(0.0, 0.5, 0.0));
        w.spawn(SphericalJoint::new(carrier, bob).with_anchors(anchor_a, anchor_b));
        for _ in 0..90 {
            w.step_physics();
        }
        // Still carrier, still bob: nothing keeps it awake.
        assert!(asleep(&w, bob), "collider {carrier_collides}: never slept");
        w.get_mut::<LinearVelocity>(carrier).unwrap().0 = Vec3A::new(1.0, 0.0, 0.0);
        let mut widest = 0.0_f32;
        for _ in 0..120 {
            w.step_physics();
            assert!(!asleep(&w, bob), "collider {carrier_collides}: left behind");
            let (a, b) = (point_of(&w, carrier, anchor_a), point_of(&w, bob, anchor_b));
            widest = widest.max((a - b).length());
        }
        println!("collider {carrier_collides}: joint parted by at most {widest} m");
        // The joint solver follows the carrier's velocity: 0.2 mm (it once held the anchor
        // where the carrier was, a step's travel behind: 16.5 mm).
        assert!(
            widest < 1e-3,
            "collider {carrier_collides}: parted {widest} m"
        );
        assert!(w.get::<Position>(bob).unwrap().0.x > 1.5);
    }
}

#[test]
fn taking_a_joint_off_a_sleeping_body_wakes_it() {
    let mut w = default_world();
    let bob = dynamic(
        &mut w,
        Collider::cuboid(0.1, 0.5, 0.1).unwrap(),
        Vec3::new(0.0, 2.5, 0.0),
    );
    let joint = w
        .spawn(
            SphericalJoint::to_world(bob)
                .with_anchors(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 0.5, 0.0)),
        )
        .id();
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(asleep(&w, bob), "the hanging body never slept");
    let y = w.get::<Position>(bob).unwrap().0.y;
    w.despawn(joint);
    for _ in 0..30 {
        w.step_physics();
    }
    let fell = y - w.get::<Position>(bob).unwrap().0.y;
    // Half a second of free fall: g t² / 2 = 1.23 m.
    assert!((fell - 1.226).abs() < 0.05, "fell {fell} m");
}
