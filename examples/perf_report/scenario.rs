//! The scenario runner's overhead: a corpus file run through `Scenario::run` (reading the
//! file, building, stepping, checking every expectation each step, hashing the final state)
//! against the same scene built and stepped by hand through the public API, with the same
//! settings (every plugin, 60 Hz, 4 substeps, diagnostics on).

use std::hint::black_box;

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::scenario::Scenario;
use hooke::tools::scenes;

use crate::timing::{Config, compare, line};

fn corpus(name: &str) -> String {
    std::fs::read_to_string(format!("{}/scenarios/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

pub(crate) fn scenario_lines(cfg: &Config) {
    // The pyramid: 55 boxes for 10 s, a position check on one box and a speed check on all 55
    // at every step of 9 s.
    let text = corpus("pyramid.ron");
    let (ours, hand) = compare(
        cfg,
        || {
            let s = Scenario::from_str(&text, "pyramid.ron").unwrap();
            black_box(s.run().unwrap().passed());
        },
        || {
            let mut world = World::new();
            world.add_physics(PhysicsPlugins);
            scenes::pyramid(&mut world, 10).unwrap();
            for _ in 0..600 {
                world.step_physics();
            }
            black_box(&world);
        },
    );
    line(
        "scenario_pyramid55_vs_hand",
        ours,
        hand,
        "pyramid.ron (600 steps, 4 expectations, final hash) vs the scene stepped by hand",
    );
    // Knock over a tower: a spawn on the timeline, contact and position checks.
    let text = corpus("knock_over_tower.ron");
    let (ours, hand) = compare(
        cfg,
        || {
            let s = Scenario::from_str(&text, "knock_over_tower.ron").unwrap();
            black_box(s.run().unwrap().passed());
        },
        || {
            let mut world = World::new();
            world.add_physics(PhysicsPlugins);
            scenes::box_column(&mut world, 6).unwrap();
            for step in 1..=360 {
                world.step_physics();
                if step == 30 {
                    world.spawn((
                        RigidBody::Dynamic,
                        Collider::ball(0.3).unwrap(),
                        ColliderDensity::try_new(7800.0).unwrap(),
                        Position::from(Vec3::new(-6.0, 2.5, 0.0)),
                        LinearVelocity::from(Vec3::new(25.0, 1.0, 0.0)),
                    ));
                }
            }
            black_box(&world);
        },
    );
    line(
        "scenario_tower_vs_hand",
        ours,
        hand,
        "knock_over_tower.ron (360 steps, a spawn, 4 expectations, final hash) vs by hand",
    );
}
