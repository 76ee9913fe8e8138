//! Islands fall asleep at rest and wake when disturbed.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::rest::Sleeping;
use hooke::core::rest::SleepingDisabled;
use hooke::prelude::*;
use hooke::sleep::SleepSettings;
use hooke::tools::scenes;

use crate::common;

fn world() -> World {
    common::gravity_world(4)
}

fn asleep(w: &World, e: Entity) -> bool {
    w.get::<Sleeping>(e).is_some()
}

#[test]
fn a_resting_box_falls_asleep_and_is_left_alone() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.6, 0.0)).unwrap();
    let mut fell_asleep_at = None;
    for step in 0..120 {
        w.step_physics();
        if fell_asleep_at.is_none() && asleep(&w, b) {
            fell_asleep_at = Some(step);
        }
    }
    let at = fell_asleep_at.expect("never fell asleep");
    println!("resting box fell asleep after {at} steps");
    assert!(
        at >= 30,
        "slept before it could have been still for 0.5 s: step {at}"
    );
    let x = w.get::<Position>(b).unwrap().get();
    for _ in 0..60 {
        w.step_physics();
    }
    assert_eq!(
        w.get::<Position>(b).unwrap().get(),
        x,
        "a sleeping body moved"
    );
    assert_eq!(w.get::<LinearVelocity>(b).unwrap().get(), Vec3::ZERO);
}

#[test]
fn a_sleeping_stack_wakes_when_hit_and_when_touched_by_game_code() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let bottom = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    let top = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 1.5, 0.0)).unwrap();
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(
        asleep(&w, bottom) && asleep(&w, top),
        "the stack should sleep"
    );
    // A ball dropped onto the stack wakes the whole island.
    let ball = scenes::dynamic_ball(&mut w, 0.2, Vec3::new(0.0, 4.0, 0.0)).unwrap();
    let mut woke = false;
    for _ in 0..60 {
        w.step_physics();
        woke |= !asleep(&w, bottom) && !asleep(&w, top);
    }
    assert!(woke, "the hit never woke the stack");
    let _ = ball;
    // Once everything rests again it sleeps again; then a write from game code wakes a body.
    for _ in 0..120 {
        w.step_physics();
    }
    assert!(asleep(&w, top));
    w.get_mut::<LinearVelocity>(top).unwrap().0.x = 1.0;
    w.step_physics();
    assert!(!asleep(&w, top), "a written velocity did not wake the body");
    assert!(
        w.get::<Position>(top).unwrap().get().x > 0.0,
        "and the body did not move"
    );
}

#[test]
fn sleeping_can_be_disabled_per_body_and_per_world() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let restless = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    w.entity_mut(restless).insert(SleepingDisabled);
    let normal = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(3.0, 0.5, 0.0)).unwrap();
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(!asleep(&w, restless) && asleep(&w, normal));

    let mut w = world();
    w.resource_mut::<SleepSettings>().enabled = false;
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(!asleep(&w, b));
    // Switching sleeping off wakes whatever was asleep.
    w.resource_mut::<SleepSettings>().enabled = true;
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(asleep(&w, b));
    w.resource_mut::<SleepSettings>().enabled = false;
    w.step_physics();
    assert!(!asleep(&w, b));
}

#[test]
fn a_settled_pile_goes_to_sleep() {
    let mut w = world();
    let boxes = scenes::box_pile(&mut w, 125).unwrap();
    for _ in 0..600 {
        w.step_physics();
    }
    let sleeping = boxes.iter().filter(|&&b| asleep(&w, b)).count();
    println!("125-box pile: {sleeping} asleep after 10 s");
    assert_eq!(sleeping, boxes.len());
}
