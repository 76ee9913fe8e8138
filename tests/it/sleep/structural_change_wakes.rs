//! Issue 14, finding 2: sleeping stacks ignored structural changes. Despawning the middle box
//! or the ground under a sleeping 5-box stack, or removing or resizing a collider, left the
//! boxes floating, and `Contacts::touching()` still listed the despawned entity. Now every
//! collider change wakes the sleeping islands that touched it, and a removed collider's
//! pairs are forgotten.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::collision::Contacts;
use hooke::core::rest::Sleeping;
use hooke::prelude::*;
use hooke::tools::scenes;

/// A 5-box column of unit boxes on the ground at the defaults, asleep.
fn sleeping_stack() -> (World, Entity, Vec<Entity>) {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let ground = scenes::ground(&mut w).unwrap();
    let boxes: Vec<Entity> = (0..5)
        .map(|i| {
            scenes::dynamic_box(
                &mut w,
                Vec3::splat(0.5),
                Vec3::new(0.0, 0.5 + i as f32, 0.0),
            )
            .unwrap()
        })
        .collect();
    for _ in 0..600 {
        w.step_physics();
        if boxes.iter().all(|&b| w.get::<Sleeping>(b).is_some()) {
            break;
        }
    }
    assert!(
        boxes.iter().all(|&b| w.get::<Sleeping>(b).is_some()),
        "the stack falls asleep"
    );
    (w, ground, boxes)
}

fn y(w: &World, e: Entity) -> f32 {
    w.get::<Position>(e).unwrap().0.y
}

fn run(w: &mut World, seconds: f32) {
    for _ in 0..(seconds * 60.0) as usize {
        w.step_physics();
    }
}

#[test]
fn despawning_the_middle_box_lets_the_boxes_above_fall_onto_the_one_below() {
    let (mut w, _, boxes) = sleeping_stack();
    let top = y(&w, boxes[4]);
    w.despawn(boxes[2]);
    run(&mut w, 2.0);
    let fell = top - y(&w, boxes[4]);
    println!("top box fell {fell:.3} m (a box is 1 m)");
    assert!((fell - 1.0).abs() < 0.05, "{fell}");
    let listed = w
        .resource::<Contacts>()
        .touching()
        .iter()
        .any(|&(a, b)| a == boxes[2] || b == boxes[2]);
    assert!(!listed, "the despawned box is not touching anything");
}

#[test]
fn despawning_the_ground_lets_the_whole_stack_fall() {
    let (mut w, ground, boxes) = sleeping_stack();
    let bottom = y(&w, boxes[0]);
    w.despawn(ground);
    run(&mut w, 1.0);
    let fell = bottom - y(&w, boxes[0]);
    println!("bottom box fell {fell:.2} m in 1 s (free fall 4.9 m)");
    assert!(fell > 4.0, "{fell}");
    assert!(
        !w.resource::<Contacts>()
            .touching()
            .iter()
            .any(|&(a, b)| a == ground || b == ground)
    );
}

#[test]
fn removing_a_collider_lets_the_boxes_above_fall_through_it() {
    let (mut w, _, boxes) = sleeping_stack();
    let top = y(&w, boxes[4]);
    w.entity_mut(boxes[0]).remove::<Collider>();
    run(&mut w, 2.0);
    let fell = top - y(&w, boxes[4]);
    println!("with the bottom box's collider removed, the top fell {fell:.3} m");
    assert!(fell > 0.9, "{fell}");
}

#[test]
fn shrinking_a_collider_lets_the_stack_settle_on_its_new_size() {
    let (mut w, _, boxes) = sleeping_stack();
    let top = y(&w, boxes[4]);
    w.entity_mut(boxes[0])
        .insert(Collider::cuboid(0.5, 0.3, 0.5).unwrap());
    run(&mut w, 2.0);
    // The bottom box now rests on its 0.6 m tall collider: everything above drops 0.4 m.
    let fell = top - y(&w, boxes[4]);
    println!("with the bottom box 0.6 m tall, the top dropped {fell:.3} m (0.4 m)");
    assert!((fell - 0.4).abs() < 0.05, "{fell}");
}
