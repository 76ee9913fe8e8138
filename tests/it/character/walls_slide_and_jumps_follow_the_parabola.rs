//! Walking at an angle into a wall keeps the speed along it; a jump rises to the discrete
//! parabola's apex and lands grounded.

use super::*;

#[test]
fn a_wall_keeps_the_speed_along_it() {
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        fixed_box(
            &mut world,
            Vec3::new(0.5, 2.0, 20.0),
            Vec3::new(2.5, 2.0, 0.0),
            Quat::IDENTITY,
        );
        let who = character(&mut world, Vec3::ZERO);
        walk(&mut world, who, Vec3::new(1.0, 0.0, 1.0), 4.0, |_| {});
        let x = at(&world, who);
        assert!((x.x - (2.0 - RADIUS - 0.01)).abs() < 0.01, "{hz} Hz: {x}");
        assert!(
            (x.z - 4.0).abs() < 0.02,
            "{hz} Hz: kept its speed along the wall: {x}"
        );
        assert!((x.y - STANDING).abs() < 1e-3, "{hz} Hz: {x}");
        assert!(overlap(&mut world, who) < 1e-3);
    }
}

#[test]
fn a_jump_reaches_the_apex_and_lands() {
    let v0 = 5.0f32;
    let g = 9.81f32;
    for hz in [30.0, 60.0, 120.0] {
        let mut world = world(hz);
        let who = character(&mut world, Vec3::ZERO);
        walk(&mut world, who, Vec3::ZERO, 0.2, |_| {});
        world.get_mut::<CharacterInput>(who).unwrap().jump_speed = v0;
        let mut apex = f32::MIN;
        walk(&mut world, who, Vec3::ZERO, 2.0, |w| {
            apex = apex.max(at(w, who).y)
        });
        // The controller adds g dt to the speed before each move (symplectic Euler), so
        // the apex is Σ (v0 − k g dt) dt over the rising steps.
        let dt = 1.0 / hz;
        let discrete: f32 = (1..)
            .map(|k| v0 - k as f32 * g * dt)
            .take_while(|v| *v > 0.0)
            .map(|v| v * dt)
            .sum();
        let rise = apex - STANDING;
        assert!(
            (rise - discrete).abs() < 1e-3,
            "{hz} Hz: rose {rise}, discrete {discrete}"
        );
        assert!(
            (rise - v0 * v0 / (2.0 * g)).abs() < v0 * dt,
            "{hz} Hz: vs v²/2g"
        );
        assert!(state(&world, who).grounded, "{hz} Hz: landed");
        assert!((at(&world, who).y - STANDING).abs() < 1e-3);
        assert_eq!(state(&world, who).vertical_speed, 0.0);
    }
}

#[test]
fn bad_input_is_a_typed_error_not_a_panic() {
    let mut world = world(60.0);
    let who = character(&mut world, Vec3::ZERO);
    world.get_mut::<CharacterInput>(who).unwrap().velocity = Vec3::new(f32::NAN, 0.0, 0.0);
    world.step_physics();
    let reason = &world.get::<Quarantined>(who).expect("quarantined").reason;
    assert!(
        format!("{reason:?}").contains("character velocity"),
        "{reason:?}"
    );

    let steep = world
        .spawn((
            CharacterController {
                max_slope: 2.0,
                ..Default::default()
            },
            Collider::capsule_y(HALF, RADIUS).unwrap(),
            Position::from(Vec3::new(5.0, STANDING, 0.0)),
        ))
        .id();
    world.step_physics();
    let reason = &world.get::<Quarantined>(steep).expect("quarantined").reason;
    assert!(format!("{reason:?}").contains("max slope"), "{reason:?}");
}
