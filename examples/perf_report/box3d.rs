//! Box3D's benchmark suite side by side with rapier 0.36 (`hooke::tools::box3d`,
//! `examples/common/rapier_box3d.rs`), timed Box3D's way: a fresh world, one untimed step,
//! then the scene's steps; hooke and rapier runs alternate, and each line is the median over
//! the runs of the mean step time. hooke runs at `PhysicsPlugins` and nothing else.

use hooke::prelude::*;
use hooke::tools::box3d::{self, Scene};

use crate::rapier_box3d::rapier_scene;
use crate::rapier_joints::widest_gap;
use crate::timing::{line, mean_step_time, median};

/// What the scene looks like after its steps: the highest body's height (m) in each engine.
fn scene_line(scene: Scene, small: bool, runs: usize, steps: usize) {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let (mut top_a, mut top_b) = (0.0f32, 0.0f32);
    let (mut gap_a, mut gap_b) = (0.0f32, 0.0f32);
    for _ in 0..runs {
        let (mut w, bodies) = box3d::build(scene, small).unwrap();
        a.push(1e9 * mean_step_time(|| w.step_physics(), steps));
        top_a = bodies
            .iter()
            .map(|&e| w.get::<Position>(e).unwrap().get().y)
            .fold(f32::NEG_INFINITY, f32::max);
        gap_a = w.resource::<JointDiagnostics>().largest_gap;
        drop(w);
        let (mut r, handles) = rapier_scene(scene, &scene.bodies(small));
        b.push(1e9 * mean_step_time(|| r.step(), steps));
        top_b = handles
            .iter()
            .map(|&h| r.bodies[h].translation().y)
            .fold(f32::NEG_INFINITY, f32::max);
        gap_b = widest_gap(&r);
    }
    let gaps = if gap_a > 0.0 || gap_b > 0.0 {
        format!(
            "; widest joint gap at the end: hooke {:.2} mm, rapier {:.2} mm",
            1e3 * gap_a,
            1e3 * gap_b
        )
    } else {
        String::new()
    };
    let size = if small { "_small" } else { "" };
    line(
        &format!("box3d_{}{size}_vs_rapier", scene.name()),
        median(a),
        median(b),
        &format!(
            "{steps} steps, {runs} runs; highest body at the end: hooke {top_a:.2} m, rapier {top_b:.2} m{gaps}"
        ),
    );
}

/// The suite at Box3D's full sizes (its debug sizes and a fifth of the steps in quick mode);
/// only the scene named `only` when it is not empty (`--scene joint_grid`).
pub fn box3d_suite(quick: bool, only: &str) {
    for scene in Scene::ALL
        .into_iter()
        .filter(|s| only.is_empty() || s.name() == only)
    {
        if quick {
            scene_line(scene, true, 3, scene.steps() / 5);
        } else {
            scene_line(scene, false, 5, scene.steps());
        }
    }
}
