//! Jointed scenes side by side with rapier 0.36's impulse joints
//! (`hooke::tools::joint_scenes`, `examples/common/rapier_joints.rs`): the time per step
//! (median over interleaved runs of the mean step time) and, from one more run of each, the
//! widest any joint's anchors parted over the run. hooke runs at `PhysicsPlugins`.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::joint_scenes::HangingChain;

use crate::rapier_joints::{rapier_chain, widest_gap};
use crate::timing::{line, mean_step_time, median};

/// The 100-link chain with its 8 kg load kicked at 3 m/s, for `steps` steps.
pub fn chain_vs_rapier(runs: usize, steps: usize) {
    let chain = HangingChain { links: 100 };
    let hooke_world = || {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        chain.build(&mut w).expect("the chain");
        w
    };
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let mut w = hooke_world();
        a.push(1e9 * mean_step_time(|| w.step_physics(), steps));
        drop(w);
        let (mut r, _) = rapier_chain(chain);
        b.push(1e9 * mean_step_time(|| r.step(), steps));
    }
    let (mut gap_a, mut gap_b) = (0.0f32, 0.0f32);
    let mut w = hooke_world();
    let (mut r, _) = rapier_chain(chain);
    for _ in 0..steps {
        w.step_physics();
        gap_a = gap_a.max(w.resource::<JointDiagnostics>().largest_gap);
        r.step();
        gap_b = gap_b.max(widest_gap(&r));
    }
    line(
        "chain_100_links_8kg_load_vs_rapier",
        median(a),
        median(b),
        &format!(
            "{steps} steps, {runs} runs; widest joint gap over the run: hooke {:.2} mm, rapier {:.2} mm",
            1e3 * gap_a,
            1e3 * gap_b
        ),
    );
}
