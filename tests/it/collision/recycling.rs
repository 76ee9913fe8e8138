//! Contact reuse (`ContactSettings::recycle_distance`): a pair that moved less than the
//! window since its manifolds were found keeps them and only updates their separations.
//! These tests check that reuse changes nothing a game can see beyond the window: what
//! moves far is found again, a replaced shape is found again, and results match a world
//! that finds every manifold every step.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common;

fn world(recycle: f32) -> World {
    let mut w = common::contact_world(4);
    w.resource_mut::<hooke::collision::ContactSettings>()
        .recycle_distance = recycle;
    w
}

/// Regression as well: parry reuses a manifold's points while the relative pose holds still,
/// so before the narrow phase told it of changed shapes, a box made taller while resting
/// stayed at its old height, with or without reuse of our own.
#[test]
fn a_collider_grown_while_resting_stands_up_on_its_new_size() {
    for recycle in [0.0, 0.005] {
        let mut w = world(recycle);
        scenes::ground(&mut w).unwrap();
        let cube = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
        for _ in 0..60 {
            w.step_physics();
        }
        // At rest the pair does not move at all, so only the change itself can tell the
        // narrow phase that its manifold is stale.
        w.entity_mut(cube)
            .insert(Collider::cuboid(0.5, 0.6, 0.5).unwrap());
        for _ in 0..60 {
            w.step_physics();
        }
        let y = common::x(&w, cube).y;
        println!("window {recycle} m: grown box rests at y = {y:.4} m (0.6 expected)");
        assert!((y - 0.6).abs() < 0.01, "held at y = {y} by the old shape");
    }
}

/// The time (s) at which a box pushed towards a ledge at `speed` drops below its top.
fn time_to_fall(recycle: f32, speed: f32) -> f32 {
    let mut w = world(recycle);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::new(0.0, -0.5, 0.0), Quat::IDENTITY).unwrap(),
        Collider::cuboid(2.0, 0.5, 2.0).unwrap(),
        Friction(0.0),
    ));
    let cube = scenes::dynamic_box(&mut w, Vec3::splat(0.25), Vec3::new(1.0, 0.25, 0.0)).unwrap();
    w.entity_mut(cube).insert(Friction(0.0));
    w.entity_mut(cube)
        .insert(LinearVelocity::try_new(Vec3::new(speed, 0.0, 0.0)).unwrap());
    for i in 1..=600 {
        w.step_physics();
        if common::x(&w, cube).y < 0.0 {
            return i as f32 / 60.0;
        }
    }
    f32::INFINITY
}

#[test]
fn a_box_sliding_off_a_ledge_falls_when_fully_updated_manifolds_say_it_does() {
    // At 0.12 m/s the box moves 2 mm a step, so the pair is reused for two steps in three.
    // Its centre passes the edge after 8.33 s, and then it tips and drops.
    let reused = time_to_fall(0.005, 0.12);
    let exact = time_to_fall(0.0, 0.12);
    println!("falls off the ledge at {reused:.3} s with reuse, {exact:.3} s without");
    assert!(exact > 8.33 && exact < 10.0, "{exact}");
    assert!((reused - exact).abs() <= 0.1, "{reused} vs {exact}");
}

#[test]
fn a_settled_column_stands_where_it_stands_without_reuse() {
    let top = |recycle: f32| {
        let mut w = world(recycle);
        let boxes = scenes::box_column(&mut w, 10).unwrap();
        for _ in 0..300 {
            w.step_physics();
        }
        common::x(&w, *boxes.last().unwrap())
    };
    let (reused, exact) = (top(0.005), top(0.0));
    println!("10-box column top after 5 s: {reused:?} with reuse, {exact:?} without");
    // The height is the stack's compression; sideways the top sways about 1.6 mm either way
    // (to opposite sides in these two runs).
    assert!((reused.y - exact.y).abs() < 2e-4, "{reused:?} vs {exact:?}");
    for x in [reused, exact] {
        assert!(x.x.hypot(x.z) < 5e-3, "the top leans to {x:?}");
    }
}

#[test]
fn without_a_window_every_step_finds_the_manifolds_again_and_stays_deterministic() {
    let run = |recycle: f32| {
        let mut w = world(recycle);
        let boxes = scenes::box_pile(&mut w, 60).unwrap();
        for _ in 0..120 {
            w.step_physics();
        }
        boxes
            .iter()
            .map(|&b| common::x(&w, b).to_array())
            .collect::<Vec<_>>()
    };
    assert_eq!(run(0.0), run(0.0));
    assert_eq!(run(0.005), run(0.005));
    // A negative or non-finite window means no reuse, the same as zero.
    assert_eq!(run(-1.0), run(0.0));
    assert_eq!(run(f32::NAN), run(0.0));
}

/// The broad phase keeps each moving box grown a little and skips its sweep while no box
/// left its grown box; a slow approach must still be seen on time.
#[test]
fn a_box_creeping_towards_another_touches_it_when_the_gap_closes() {
    let mut w = world(0.005);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::new(0.0, -0.5, 0.0), Quat::IDENTITY).unwrap(),
        Collider::cuboid(10.0, 0.5, 10.0).unwrap(),
        Friction(0.0),
    ));
    let a = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(1.1, 0.5, 0.0)).unwrap();
    for e in [a, b] {
        w.entity_mut(e).insert(Friction(0.0));
    }
    w.entity_mut(a)
        .insert(LinearVelocity::try_new(Vec3::new(0.07, 0.0, 0.0)).unwrap());
    // Touching means closer than a quarter of the 2 cm margin: at 0.07 m/s the 0.1 m gap
    // closes to 5 mm after 1.357 s, 81.4 steps. Contacts are found at the start of a step,
    // from the positions the step before left, so they show after step 83.
    let first = (1..=200).find(|_| {
        w.step_physics();
        w.resource::<Contacts>().are_touching(a, b)
    });
    println!("touching from step {first:?} (83 expected)");
    assert_eq!(first, Some(83));
}
