//! Jointed scenes side by side with rapier 0.36's impulse joints
//! (`hooke::tools::joint_scenes`, `examples/common/rapier_joints.rs`): the time per step
//! (median over interleaved runs of the mean step time) and, from one more run of each, the
//! widest any joint's anchors parted over the run. hooke runs at `PhysicsPlugins`.
//!
//! The `_at_equal_gap` lines hold the anchors to the same standard: rapier's iterations are
//! raised rung by rung ([`RAPIER_LADDER`]) until its widest gap over the run is no wider than
//! hooke's at its defaults, and the two are then timed side by side (the issue's "time at
//! equal or smaller anchor drift").

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::box3d::{self, Scene};
use hooke::tools::joint_scenes::{HangingChain, RagdollPile};

use crate::rapier_box3d::rapier_scene;
use crate::rapier_joints::{rapier_chain, rapier_ragdoll_pile, widest_gap};
use crate::timing::{line, mean_step_time, median};

/// Times `steps` steps of hooke's world from `hooke` against rapier's from `rapier` over
/// `runs` interleaved runs, then measures each one's widest joint gap over one more run, and
/// prints the line `name`.
fn side_by_side(
    name: &str,
    (runs, steps): (usize, usize),
    hooke: impl Fn() -> World,
    rapier: impl Fn() -> rapier3d::prelude::PhysicsWorld,
) {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let mut w = hooke();
        a.push(1e9 * mean_step_time(|| w.step_physics(), steps));
        drop(w);
        let mut r = rapier();
        b.push(1e9 * mean_step_time(|| r.step(), steps));
    }
    let (mut gap_a, mut gap_b) = (0.0f32, 0.0f32);
    let (mut w, mut r) = (hooke(), rapier());
    for _ in 0..steps {
        w.step_physics();
        gap_a = gap_a.max(w.resource::<JointDiagnostics>().largest_gap);
        r.step();
        gap_b = gap_b.max(widest_gap(&r));
    }
    line(
        name,
        median(a),
        median(b),
        &format!(
            "{steps} steps, {runs} runs; widest joint gap over the run: hooke {:.2} mm, rapier {:.2} mm",
            1e3 * gap_a,
            1e3 * gap_b
        ),
    );
}

/// The 100-link chain with its 8 kg load kicked at 3 m/s, for `steps` steps.
/// With `equal_gap`, also the line against rapier at the iterations that hold its anchors as
/// close as hooke's.
pub fn chain_vs_rapier(runs: usize, steps: usize, equal_gap: bool) {
    let chain = HangingChain { links: 100 };
    let hooke = || {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        chain.build(&mut w).expect("the chain");
        w
    };
    let rapier = || rapier_chain(chain).0;
    side_by_side(
        "chain_100_links_8kg_load_vs_rapier",
        (runs, steps),
        hooke,
        rapier,
    );
    if equal_gap {
        at_equal_gap(
            "chain_100_links_at_equal_gap",
            (runs, steps),
            hooke,
            rapier,
            8,
        );
    }
}

/// The pile of 20 ragdolls (`RagdollPile`) falling and settling, for `steps` steps.
/// With `equal_gap`, also the line at equal gap.
pub fn ragdolls_vs_rapier(runs: usize, steps: usize, equal_gap: bool) {
    let pile = RagdollPile { ragdolls: 20 };
    let hooke = || {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        pile.spawn(&mut w).expect("the pile");
        w
    };
    let rapier = || rapier_ragdoll_pile(pile);
    side_by_side("ragdoll_pile_20_vs_rapier", (runs, steps), hooke, rapier);
    if equal_gap {
        at_equal_gap(
            "ragdoll_pile_20_at_equal_gap",
            (runs, steps),
            hooke,
            rapier,
            8,
        );
    }
}

/// Box3D's joint_grid (100 × 100 spheres, 19,800 ball joints) at equal gap, over Box3D's
/// 100 steps. rapier's ladder stops at 64 iterations × 4 (about 0.2 s a step here).
pub fn joint_grid_at_equal_gap(runs: usize) {
    let hooke = || box3d::build(Scene::JointGrid, false).expect("the grid").0;
    let rapier = || rapier_scene(Scene::JointGrid, &Scene::JointGrid.bodies(false)).0;
    at_equal_gap(
        "box3d_joint_grid_at_equal_gap",
        (runs, 100),
        hooke,
        rapier,
        7,
    );
}

/// rapier's solver settings in order of cost: (solver iterations, internal PGS iterations
/// per iteration). Its default is the first; past it, raising the PGS iterations to 4 and
/// then doubling the solver iterations gave the narrowest gap for the time on the chain
/// (4 × 4: 15.8 mm in 195 µs a step against 8 × 1: 16.0 mm in 252 µs).
const RAPIER_LADDER: [(usize, usize); 8] = [
    (4, 1),
    (4, 2),
    (4, 4),
    (8, 4),
    (16, 4),
    (32, 4),
    (64, 4),
    (128, 4),
];

/// The widest joint gap (m) over `steps` steps of `step`, reading it with `gap`.
fn widest_over<W>(
    world: &mut W,
    steps: usize,
    step: impl Fn(&mut W),
    gap: impl Fn(&W) -> f32,
) -> f32 {
    let mut widest = 0.0f32;
    for _ in 0..steps {
        step(world);
        widest = widest.max(gap(world));
    }
    widest
}

/// hooke at its defaults against rapier at the first of the first `rungs` rungs of
/// [`RAPIER_LADDER`] whose widest joint gap over `steps` steps is no wider than hooke's (or
/// its last rung, and the line says rapier's gap is still wider), timed over `runs`
/// interleaved runs.
fn at_equal_gap(
    name: &str,
    (runs, steps): (usize, usize),
    hooke: impl Fn() -> World,
    rapier: impl Fn() -> rapier3d::prelude::PhysicsWorld,
    rungs: usize,
) {
    let target = widest_over(
        &mut hooke(),
        steps,
        |w| w.step_physics(),
        |w| w.resource::<JointDiagnostics>().largest_gap,
    );
    let with = |(iterations, pgs): (usize, usize)| {
        let mut r = rapier();
        r.integration_parameters.num_solver_iterations = iterations;
        r.integration_parameters.num_internal_pgs_iterations = pgs;
        r
    };
    let mut chosen = (RAPIER_LADDER[0], f32::INFINITY);
    for &rung in &RAPIER_LADDER[..rungs] {
        let gap = widest_over(&mut with(rung), steps, |r| r.step(), widest_gap);
        chosen = (rung, gap);
        if gap <= target {
            break;
        }
    }
    let ((iterations, pgs), gap) = chosen;
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let mut w = hooke();
        a.push(1e9 * mean_step_time(|| w.step_physics(), steps));
        drop(w);
        let mut r = with(chosen.0);
        b.push(1e9 * mean_step_time(|| r.step(), steps));
    }
    let verdict = if gap <= target {
        "no wider than hooke's"
    } else {
        "the last rung tried, still wider (the ratio is an upper bound) than hooke's"
    };
    line(
        &format!("{name}_vs_rapier"),
        median(a),
        median(b),
        &format!(
            "{steps} steps, {runs} runs; rapier at {iterations} iterations x {pgs} PGS: widest gap {:.4} mm, {verdict} {:.4} mm",
            1e3 * gap,
            1e3 * target
        ),
    );
}
