//! Columns of unit boxes, each box moved sideways by a small seeded amount, run at the
//! default settings with sleeping off: how many stand, and how far each top strayed from the
//! axis. One straight column standing can be luck; this asks how often.
//!
//! `cargo run --release --example column_trials -- [boxes] [seconds] [runs]` (defaults 100,
//! 20, 8). `RAPIER=1` runs rapier 0.36 on the same columns; `OFFSET=m` sets the largest
//! sideways move (default 0.0001 m). A column stands when its top stays within half a box of
//! the axis throughout.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::scenes::{self, BoxSpec};
#[path = "common/rapier_boxes.rs"]
mod rapier_boxes;

/// The farthest the top strayed from the axis over `steps` steps (m), in hooke.
fn hooke_stray(specs: &[BoxSpec], steps: usize) -> f32 {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let boxes = scenes::spawn_boxes(&mut w, specs).expect("valid boxes");
    let top = *boxes.last().expect("at least one box");
    let mut worst = 0.0f32;
    for _ in 0..steps {
        w.step_physics();
        let p = w.get::<Position>(top).map_or(Vec3::ZERO, |p| p.get());
        worst = worst.max(Vec3::new(p.x, 0.0, p.z).length());
    }
    worst
}

/// The same in rapier 0.36 at its defaults.
fn rapier_stray(specs: &[BoxSpec], steps: usize) -> f32 {
    let (mut r, handles) = rapier_boxes::rapier_boxes(specs, |_| 1000.0);
    let top = *handles.last().expect("at least one box");
    let mut worst = 0.0f32;
    for _ in 0..steps {
        r.step();
        let p = r.bodies[top].translation();
        worst = worst.max(Vec3::new(p.x, 0.0, p.z).length());
    }
    worst
}

fn main() {
    let arg = |i: usize, default: usize| {
        std::env::args()
            .nth(i)
            .and_then(|s| s.parse().ok())
            .unwrap_or(default)
    };
    let (n, seconds, runs) = (arg(1, 100).max(1), arg(2, 20), arg(3, 8).max(1));
    let offset: f32 = std::env::var("OFFSET")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1e-4);
    let rapier = std::env::var("RAPIER").is_ok();
    let steps = seconds * 60;
    let mut strays: Vec<f32> = (0..runs)
        .map(|run| {
            let specs = scenes::perturbed_column_spec(n, offset, run);
            if rapier {
                rapier_stray(&specs, steps)
            } else {
                hooke_stray(&specs, steps)
            }
        })
        .collect();
    strays.sort_by(f32::total_cmp);
    let stood = strays.iter().filter(|&&s| s < 0.5).count();
    let listed: Vec<String> = strays.iter().map(|s| format!("{s:.3}")).collect();
    println!(
        "{}: {n} boxes, moved up to {offset} m, {seconds} s: {stood} of {runs} stood; top strayed (m) {}",
        if rapier { "rapier 0.36" } else { "hooke" },
        listed.join(", ")
    );
}
