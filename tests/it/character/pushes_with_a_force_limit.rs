//! Walking into a crate pushes it with at most the controller's force: a 10 kg crate
//! (friction 0.5 × 10 kg × g = 49 N < 500 N) is pushed along at walking speed, a 200 kg
//! one (981 N > 500 N) does not move and blocks the character.

use super::*;

/// A 1 m crate of `kg` resting on the floor at x = 2.
fn crate_of(world: &mut World, kg: f32) -> Entity {
    world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            hooke::collision::ColliderDensity::try_new(kg).unwrap(),
            Position::from(Vec3::new(2.0, 0.5, 0.0)),
        ))
        .id()
}

#[test]
fn a_light_crate_is_pushed_at_walking_speed() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        let crate_ = crate_of(&mut world, 10.0);
        let who = character(&mut world, Vec3::ZERO);
        let dt = 1.0 / hz;
        let mut strongest: f32 = 0.0;
        walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 3.0, |w| {
            let total: Vec3 = state(w, who).hits.iter().map(|h| h.impulse).sum();
            strongest = strongest.max(total.length() / dt);
        });
        let c = at(&world, crate_);
        // The character reaches the crate after (2 − 0.5 − 0.31)/1.5 ≈ 0.8 s, then pushes
        // it for about 2.2 s at 1.5 m/s.
        assert!(c.x > 2.0 + 0.8 * 1.5 * 2.2, "{hz} Hz: crate at {c}");
        let behind = c.x - 0.5 - at(&world, who).x;
        assert!(
            behind > RADIUS - 1e-3 && behind < RADIUS + 0.1,
            "{hz} Hz: gap {behind}"
        );
        assert!(
            strongest <= 500.0 * 1.0001,
            "{hz} Hz: pushed with {strongest} N"
        );
        assert!(strongest > 0.0);
        assert!(c.y > 0.49 && c.y < 0.52, "{hz} Hz: slid, not tipped: {c}");
    }
}

#[test]
fn a_heavy_crate_blocks_the_character() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        let crate_ = crate_of(&mut world, 200.0);
        let who = character(&mut world, Vec3::ZERO);
        walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 3.0, |_| {});
        let c = at(&world, crate_);
        assert!((c.x - 2.0).abs() < 0.01, "{hz} Hz: the crate moved to {c}");
        let x = at(&world, who);
        assert!(
            (x.x - (1.5 - RADIUS - 0.01)).abs() < 0.02,
            "{hz} Hz: the character stands at the crate: {x}"
        );
    }
}
