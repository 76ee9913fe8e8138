//! Contacts against composite shapes (triangle meshes and heightfields), whose manifolds
//! parry builds per triangle: resting height and tilt, and a ball rolling down a mesh ramp
//! against the closed form for rolling without slipping.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common;

/// A flat square of two triangles, 2·`half` wide, in the xz plane, facing up.
fn square(half: f32) -> Collider {
    let v = vec![
        Vec3::new(-half, 0.0, -half),
        Vec3::new(half, 0.0, -half),
        Vec3::new(half, 0.0, half),
        Vec3::new(-half, 0.0, half),
    ];
    Collider::trimesh(v, vec![[0, 2, 1], [0, 3, 2]]).unwrap()
}

fn rests_flat(ground: Collider) -> (f32, f32) {
    let mut w = common::contact_world(4);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::ZERO, Quat::IDENTITY).unwrap(),
        ground,
    ));
    // Off centre, so that the box spans cells of the heightfield and both triangles.
    let cube = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.3, 0.55, -0.2)).unwrap();
    for _ in 0..180 {
        w.step_physics();
    }
    let y = common::x(&w, cube).y;
    let tilt = w
        .get::<Rotation>(cube)
        .unwrap()
        .0
        .angle_between(Quat::IDENTITY);
    (y, tilt)
}

#[test]
fn a_box_rests_flat_on_a_triangle_mesh_and_on_a_heightfield() {
    let field = Collider::heightfield(5, 5, vec![0.0; 25], Vec3::new(10.0, 1.0, 10.0)).unwrap();
    for (name, ground) in [("trimesh", square(5.0)), ("heightfield", field)] {
        let (y, tilt) = rests_flat(ground);
        println!("{name}: unit cube rests at y = {y:.4} m, tilted {tilt:.1e} rad");
        assert!((y - 0.5).abs() < 0.005, "{name}: y = {y}");
        assert!(tilt < 1e-3, "{name}: tilt {tilt}");
    }
}

#[test]
fn a_ball_rolls_down_a_mesh_ramp_at_five_sevenths_of_g_sin_theta() {
    let angle = 20f32.to_radians();
    let q = Quat::from_rotation_z(angle);
    let mut w = common::contact_world(4);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::ZERO, q).unwrap(),
        square(20.0),
        Friction(1.0),
    ));
    let r = 0.25;
    let start = q * Vec3::new(8.0, r, 0.0);
    let ball = scenes::dynamic_ball(&mut w, r, start).unwrap();
    w.entity_mut(ball).insert(Friction(1.0));
    // A solid ball rolling without slipping (μ = 1 ≫ 2/7 tan θ): a = 5/7 g sin θ.
    let down = q * Vec3::NEG_X;
    let speed = |w: &World| common::v(w, ball).dot(down);
    for _ in 0..60 {
        w.step_physics();
    }
    let v1 = speed(&w);
    for _ in 0..60 {
        w.step_physics();
    }
    let a = speed(&w) - v1;
    let expected = 5.0 / 7.0 * 9.81 * angle.sin();
    println!("ball on a 20° mesh ramp: a = {a:.4} m/s² (5/7 g sin θ = {expected:.4})");
    assert!((a - expected).abs() < 0.02 * expected, "a = {a}");
}
