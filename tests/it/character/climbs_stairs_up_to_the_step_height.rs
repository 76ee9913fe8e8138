//! A staircase of 18 cm risers is walked up at the default 25 cm step height, at 30, 60 and
//! 120 Hz; 40 cm risers stop the character at the first one.

use super::*;

/// Six steps of `rise` (m) and 30 cm treads, the first riser at x = 1.
fn stairs(world: &mut World, rise: f32) {
    for i in 0..6 {
        let top = rise * (i + 1) as f32;
        let start = 1.0 + 0.3 * i as f32;
        // Each block runs from its riser to the top landing, so the treads join.
        let end = 1.0 + 0.3 * 6.0 + 2.0;
        fixed_box(
            world,
            Vec3::new((end - start) / 2.0, top / 2.0, 2.0),
            Vec3::new((start + end) / 2.0, top / 2.0, 0.0),
            Quat::IDENTITY,
        );
    }
}

#[test]
fn eighteen_centimetre_risers_are_climbed_at_every_rate() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        stairs(&mut world, 0.18);
        let who = character(&mut world, Vec3::ZERO);
        let mut deepest = 0.0f32;
        let mut stepped = 0;
        walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 3.0, |w| {
            stepped += state(w, who).stepped as usize;
        });
        for _ in 0..3 {
            deepest = deepest.max(overlap(&mut world, who));
        }
        let x = at(&world, who);
        let top = 6.0 * 0.18 + STANDING;
        assert!(x.x > 3.0, "{hz} Hz: reached the landing: {x}");
        assert!(
            (x.y - top).abs() < 0.02,
            "{hz} Hz: stands on the landing: y {} vs {top}",
            x.y
        );
        assert!(state(&world, who).grounded, "{hz} Hz");
        assert!(stepped >= 6, "{hz} Hz: stepped {stepped} times");
        assert!(deepest < 1e-3, "{hz} Hz: overlap {deepest}");
    }
}

#[test]
fn forty_centimetre_risers_block() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        stairs(&mut world, 0.4);
        let who = character(&mut world, Vec3::ZERO);
        walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 2.0, |_| {});
        let x = at(&world, who);
        assert!(
            (x.y - STANDING).abs() < 0.01,
            "{hz} Hz: still on the floor: {x}"
        );
        let against = 1.0 - RADIUS - 0.01;
        assert!(
            (x.x - against).abs() < 0.01,
            "{hz} Hz: stopped at the riser: {x}"
        );
        assert!(state(&world, who).grounded);
        assert!(!state(&world, who).stepped);
    }
}
