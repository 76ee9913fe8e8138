//! Regression: the broad phase keeps static colliders in a tree it rebuilds only when told,
//! and it was told only of collider inserts and removals. A static collider moved by
//! inserting a new `Position` kept its old box (a ball falling onto it at its new place fell
//! through), and a body made static by removing its velocity stayed in the moving list.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common;

fn world() -> World {
    common::contact_world(4)
}

fn y(w: &World, e: Entity) -> f32 {
    w.get::<Position>(e).unwrap().get().y
}

#[test]
fn a_static_collider_moved_by_a_new_position_catches_what_falls_at_its_new_place() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let shelf = w
        .spawn((
            RigidBodyBundle::fixed(Vec3::new(0.0, 2.0, 0.0), Quat::IDENTITY).unwrap(),
            Collider::cuboid(1.0, 0.1, 1.0).unwrap(),
        ))
        .id();
    // A ball falls ten metres away from the shelf; while it falls, move the shelf under it.
    let ball = scenes::dynamic_ball(&mut w, 0.2, Vec3::new(10.0, 4.0, 0.0)).unwrap();
    for _ in 0..5 {
        w.step_physics();
    }
    w.entity_mut(shelf)
        .insert(Position::try_new(Vec3::new(10.0, 2.0, 0.0)).unwrap());
    for _ in 0..90 {
        w.step_physics();
    }
    let rest = y(&w, ball);
    println!("ball rests at y = {rest:.4} m (shelf top 2.1 m)");
    assert!(
        (rest - 2.3).abs() < 0.01,
        "fell through the moved shelf: {rest}"
    );
}

#[test]
fn a_body_made_static_by_removing_its_velocity_holds_what_lands_on_it() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let block = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    for _ in 0..30 {
        w.step_physics();
    }
    // Freeze it in place: without a velocity it is a static collider.
    w.entity_mut(block).remove::<LinearVelocity>();
    let ball = scenes::dynamic_ball(&mut w, 0.25, Vec3::new(0.0, 3.0, 0.0)).unwrap();
    let before = y(&w, block);
    for _ in 0..90 {
        w.step_physics();
    }
    assert_eq!(y(&w, block), before, "a static body moved");
    let rest = y(&w, ball);
    println!(
        "ball rests at y = {rest:.4} m on the frozen block (top {:.4})",
        before + 0.5
    );
    assert!((rest - (before + 0.75)).abs() < 0.01, "{rest}");
    // And back: with a velocity again it is dynamic. Put it a metre up, clear of the ball,
    // and it falls to the ground.
    w.entity_mut(block).insert((
        Position::try_new(Vec3::new(5.0, 1.5, 0.0)).unwrap(),
        LinearVelocity::default(),
    ));
    for _ in 0..90 {
        w.step_physics();
    }
    let landed = y(&w, block);
    println!("block made dynamic again lands at y = {landed:.4} m");
    assert!((landed - 0.5).abs() < 0.01, "{landed}");
}
