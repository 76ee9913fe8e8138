//! `Dominance`: a 1 kg ball of a higher group rolling into a 100 kg crate on ice keeps its
//! speed and takes the crate along at it, as an infinitely heavy body would; in the same
//! group, momentum is shared as the closed form says. In both spawn orders (which decides
//! which body is `a` of the contact).

use crate::common;
use bevy_ecs::prelude::*;
use hooke::prelude::*;

/// Ball (1 kg, r = 0.2 m, 3 m/s along +x) and crate (100 kg, a 0.5 m cube) on a frictionless
/// floor; the ball in group `ball_group`. Returns their velocities after 1 s.
fn collide(ball_group: i8, ball_first: bool) -> (Vec3, Vec3) {
    let mut w = common::default_world();
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(20.0, 0.5, 5.0).unwrap(),
        Position::from(Vec3::new(0.0, -0.5, 0.0)),
        Friction(0.0),
    ));
    let ball = |w: &mut World| {
        w.spawn((
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Mass::new(1.0).unwrap(),
            Position::from(Vec3::new(-2.0, 0.2, 0.0)),
            LinearVelocity::from(Vec3::new(3.0, 0.0, 0.0)),
            Friction(0.0),
            Dominance(ball_group),
        ))
        .id()
    };
    let crate_ = |w: &mut World| {
        w.spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
            Mass::new(100.0).unwrap(),
            Position::from(Vec3::new(0.0, 0.25, 0.0)),
            Friction(0.0),
        ))
        .id()
    };
    let (b, c) = if ball_first {
        let b = ball(&mut w);
        (b, crate_(&mut w))
    } else {
        let c = crate_(&mut w);
        (ball(&mut w), c)
    };
    for _ in 0..60 {
        w.step_physics();
    }
    (common::v(&w, b), common::v(&w, c))
}

#[test]
fn a_dominant_ball_keeps_its_speed_and_carries_the_crate() {
    for ball_first in [true, false] {
        let (ball, crate_) = collide(1, ball_first);
        assert!(
            (ball.x - 3.0).abs() < 0.01 * 3.0,
            "the ball is not slowed: {ball}"
        );
        assert!(ball.y.abs() < 0.05, "and stays on the floor: {ball}");
        assert!(
            crate_.x >= 3.0 * 0.99 && crate_.x < 3.0 * 1.05,
            "the crate moves with it: {crate_}"
        );
    }
}

#[test]
fn a_lower_group_ball_bounces_off_as_if_the_crate_were_immovable() {
    // The crate dominates: the ball stops dead (restitution 0), the crate does not move.
    for ball_first in [true, false] {
        let (ball, crate_) = collide(-1, ball_first);
        assert!(ball.x.abs() < 0.01, "stopped against the crate: {ball}");
        assert!(crate_.length() < 1e-4, "the crate took nothing: {crate_}");
    }
}

#[test]
fn the_same_group_shares_momentum() {
    // A perfectly inelastic contact: both end at m v / (m + M) = 3/101 m/s.
    for ball_first in [true, false] {
        let (ball, crate_) = collide(0, ball_first);
        let shared = 3.0 / 101.0;
        assert!(
            (crate_.x - shared).abs() < 0.05 * shared,
            "crate {crate_} vs {shared}"
        );
        let momentum = ball.x + 100.0 * crate_.x;
        assert!(
            (momentum - 3.0).abs() < 0.01 * 3.0,
            "momentum {momentum} vs 3"
        );
    }
}
