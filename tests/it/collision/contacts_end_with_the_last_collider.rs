//! Regression: when the last collider left the world, the collision systems stopped
//! running (they run only while a collider exists) but the contact solver kept the last
//! step's constraints and went on solving them. A box resting on the ground went on resting
//! after both colliders were removed, held up by a ground that no longer existed.

use bevy_ecs::message::Messages;
use hooke::collision::ContactEnded;
use hooke::collision::Contacts;
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common;

#[test]
fn a_resting_box_falls_once_every_collider_is_gone() {
    let mut w = common::contact_world(4);
    let ground = scenes::ground(&mut w).unwrap();
    let cube = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    for _ in 0..60 {
        w.step_physics();
    }
    let rest = common::x(&w, cube).y;
    assert!((rest - 0.5).abs() < 1e-3, "rests at y = {rest}");

    let mut ended = w.resource::<Messages<ContactEnded>>().get_cursor();
    w.entity_mut(ground).remove::<Collider>();
    w.entity_mut(cube).remove::<Collider>();
    // Free fall from rest for 0.5 s: y drops by ½ g t² = 1.226 m (symplectic Euler at
    // h = 1/240 s drops h²g/2 per substep more: 1.236 m).
    let mut events = 0;
    for _ in 0..30 {
        w.step_physics();
        events += ended.read(w.resource::<Messages<ContactEnded>>()).count();
    }
    assert_eq!(events, 1, "the pair's contact ends once");
    assert!(!w.resource::<Contacts>().are_touching(ground, cube));
    let fallen = rest - common::x(&w, cube).y;
    println!("fell {fallen:.4} m in 0.5 s");
    assert!((fallen - 1.236).abs() < 0.01, "fell {fallen} m");
}
