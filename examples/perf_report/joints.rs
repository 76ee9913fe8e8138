//! Jointed scenes side by side with rapier 0.36's impulse joints
//! (`hooke::tools::joint_scenes`, `examples/common/rapier_joints.rs`): the time per step
//! (median over interleaved runs of the mean step time) and, from one more run of each, the
//! widest any joint's anchors parted over the run. hooke runs at `PhysicsPlugins`.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{HangingChain, RagdollPile};

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
pub fn chain_vs_rapier(runs: usize, steps: usize) {
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
}

/// The pile of 20 ragdolls (`RagdollPile`) falling and settling, for `steps` steps.
pub fn ragdolls_vs_rapier(runs: usize, steps: usize) {
    let pile = RagdollPile { ragdolls: 20 };
    let hooke = || {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        pile.spawn(&mut w).expect("the pile");
        w
    };
    let rapier = || rapier_ragdoll_pile(pile);
    side_by_side("ragdoll_pile_20_vs_rapier", (runs, steps), hooke, rapier);
}
