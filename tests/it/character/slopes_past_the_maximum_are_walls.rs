//! Ramps below the default 45° maximum are walked up, following the plane's closed form;
//! ramps above it stop the character, and one dropped on such a ramp slides down it.

use super::*;

/// A 10 m ramp at `degrees` whose top face starts on the floor at x = 1, rising towards +x.
fn ramp(world: &mut World, degrees: f32) {
    let theta = degrees.to_radians();
    let (half_length, half_thickness) = (5.0, 0.5);
    let rotation = Quat::from_rotation_z(theta);
    let foot = Vec3::new(1.0, 0.0, 0.0);
    let centre = foot - rotation * Vec3::new(-half_length, half_thickness, 0.0);
    fixed_box(
        world,
        Vec3::new(half_length, half_thickness, 3.0),
        centre,
        rotation,
    );
}

/// The centre height of a capsule resting on the ramp at horizontal position `x` (m).
fn on_ramp(x: f32, degrees: f32) -> f32 {
    let theta = degrees.to_radians();
    HALF + theta.tan() * (x - 1.0) + (RADIUS + 0.01) / theta.cos()
}

#[test]
fn walkable_ramps_are_climbed_on_the_plane() {
    for degrees in [20.0, 30.0, 40.0] {
        for hz in [30.0, 60.0, 120.0] {
            let mut world = world(hz);
            ramp(&mut world, degrees);
            let who = character(&mut world, Vec3::ZERO);
            let mut worst: f32 = 0.0;
            walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 3.0, |w| {
                let x = at(w, who);
                if x.x > 2.0 {
                    worst = worst.max((x.y - on_ramp(x.x, degrees)).abs());
                }
            });
            let x = at(&world, who);
            assert!(x.x > 2.5, "{degrees}° at {hz} Hz: climbed to {x}");
            assert!(
                worst < 0.01,
                "{degrees}° at {hz} Hz: off the plane by {worst}"
            );
            assert!(state(&world, who).grounded, "{degrees}° at {hz} Hz");
        }
    }
}

#[test]
fn steep_ramps_are_not_climbed() {
    for degrees in [50.0, 60.0, 75.0] {
        for hz in [30.0, 60.0, 120.0] {
            let mut world = world(hz);
            ramp(&mut world, degrees);
            let who = character(&mut world, Vec3::ZERO);
            let mut highest = f32::MIN;
            walk(&mut world, who, Vec3::new(1.5, 0.0, 0.0), 3.0, |w| {
                highest = highest.max(at(w, who).y);
            });
            assert!(
                highest < STANDING + 0.05,
                "{degrees}° at {hz} Hz: rose to {highest}"
            );
            let x = at(&world, who);
            assert!(x.x < 1.0, "{degrees}° at {hz} Hz: {x}");
        }
    }
}

#[test]
fn a_character_dropped_on_a_steep_ramp_slides_down() {
    let mut world = world(60.0);
    ramp(&mut world, 60.0);
    let start = Vec3::new(3.0, on_ramp(3.0, 60.0) + 0.5, 0.0);
    let who = world
        .spawn((
            CharacterController::default(),
            Collider::capsule_y(HALF, RADIUS).unwrap(),
            Position::from(start),
        ))
        .id();
    let mut on_slope_grounded = 0;
    walk(&mut world, who, Vec3::ZERO, 1.0, |w| {
        if at(w, who).x > 1.5 && state(w, who).grounded {
            on_slope_grounded += 1;
        }
    });
    let x = at(&world, who);
    assert!(x.x < 1.5, "slid down to the foot: {x}");
    assert_eq!(on_slope_grounded, 0, "a 60° slope is not ground");
    assert!(overlap(&mut world, who) < 1e-3);
}
