//! A character standing still on a kinematic platform moves with it: sideways, up and down
//! (a lift), at 30, 60 and 120 Hz.

use super::*;

/// A kinematic 3 × 0.2 × 3 m platform whose top is at y = 1, moving at `velocity`.
fn platform(world: &mut World, velocity: Vec3) -> Entity {
    world
        .spawn((
            RigidBody::Kinematic,
            Collider::cuboid(1.5, 0.1, 1.5).unwrap(),
            Position::from(Vec3::new(0.0, 0.9, 0.0)),
            LinearVelocity::from(velocity),
        ))
        .id()
}

#[test]
fn a_sliding_platform_carries_the_character() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        let deck = platform(&mut world, Vec3::new(2.0, 0.0, 1.0));
        let who = character(&mut world, Vec3::new(0.5, 1.0, 0.0));
        walk(&mut world, who, Vec3::ZERO, 0.25, |_| {});
        let offset = at(&world, who) - at(&world, deck);
        let mut drift: f32 = 0.0;
        walk(&mut world, who, Vec3::ZERO, 2.0, |w| {
            drift = drift.max((at(w, who) - at(w, deck) - offset).length());
        });
        assert!(drift < 0.01, "{hz} Hz: slid {drift} m on the platform");
        assert!(state(&world, who).grounded);
        assert_eq!(state(&world, who).ground.unwrap().entity, deck);
    }
}

#[test]
fn a_lift_carries_the_character_up_and_down() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        let lift = platform(&mut world, Vec3::new(0.0, 1.0, 0.0));
        let who = character(&mut world, Vec3::new(0.0, 1.0, 0.0));
        let mut gaps = (f32::MAX, f32::MIN);
        let mut track = |w: &World| {
            let gap = at(w, who).y - (at(w, lift).y + 0.1) - STANDING;
            gaps = (gaps.0.min(gap), gaps.1.max(gap));
        };
        walk(&mut world, who, Vec3::ZERO, 2.0, &mut track);
        world.get_mut::<LinearVelocity>(lift).unwrap().0 = Vec3::new(0.0, -1.0, 0.0).into();
        walk(&mut world, who, Vec3::ZERO, 2.0, &mut track);
        assert!(gaps.0 > -1e-3, "{hz} Hz: sank into the lift by {}", -gaps.0);
        assert!(gaps.1 < 0.01, "{hz} Hz: left the lift by {}", gaps.1);
        assert!(state(&world, who).grounded, "{hz} Hz");
    }
}
