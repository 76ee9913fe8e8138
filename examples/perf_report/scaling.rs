//! How the step's cost per body grows with the body count: a heap of boxes from 1,000 to
//! 100,000 (`hooke::tools::scenes::heap_spec`, as deep at every size) and a particle cloud
//! from 1,000 to 1,000,000. Each size is sampled interleaved with the 1,000-body world, and
//! the line's ratio is the cost per body against the 1,000-body one; the exponent p of
//! cost ∝ nᵖ follows from it (1 + ln ratio / ln(n / 1,000)).

use bevy_ecs::world::World;
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::timing::{Config, compare};

/// Steps each heap falls and settles before it is timed (1 s at 60 Hz).
const SETTLE_STEPS: usize = 60;

fn heap(n: usize) -> World {
    let mut w = scenes::world_with(
        1.0 / 60.0,
        4,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    scenes::spawn_boxes(&mut w, &scenes::heap_spec(n)).unwrap();
    w
}

fn particles(n: usize) -> World {
    let mut w = crate::quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    scenes::particle_cloud(&mut w, n).unwrap();
    w
}

/// One line: the cost per body of `n` bodies against 1,000, and the exponent.
fn scaling_line(cfg: &Config, name: &str, n: usize, build: fn(usize) -> World, settle: usize) {
    let base = 1_000;
    let (mut big, mut small) = (build(n), build(base));
    for _ in 0..settle {
        big.step_physics();
        small.step_physics();
    }
    let (ours, reference) = compare(cfg, || big.step_physics(), || small.step_physics());
    let (per_n, per_base) = (ours / n as f64, reference / base as f64);
    let exponent = 1.0 + (per_n / per_base).ln() / (n as f64 / base as f64).ln();
    crate::timing::line(
        &format!("scaling_{name}_{}k_per_body_vs_1k", n / 1000),
        per_n,
        per_base,
        &format!("ns per body per step; cost exponent {exponent:.3}"),
    );
}

/// The heap (goal: exponent ≤ 1.15) and the particles (≤ 1.05), at `PhysicsPlugins`'
/// defaults (the particles without the energy pass, as every particle line).
pub fn scaling_lines(cfg: &Config, quick: bool) {
    let heaps: &[usize] = if quick { &[10_000] } else { &[10_000, 100_000] };
    for &n in heaps {
        scaling_line(cfg, "heap", n, heap, SETTLE_STEPS);
    }
    let clouds: &[usize] = if quick {
        &[10_000, 100_000]
    } else {
        &[10_000, 100_000, 1_000_000]
    };
    for &n in clouds {
        scaling_line(cfg, "particles", n, particles, 0);
    }
}
