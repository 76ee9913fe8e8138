//! Box3D's benchmark scenes (`hooke::tools::box3d`), hooke and rapier 0.36 side by side,
//! timed as Box3D's own benchmark does: a fresh world, one untimed step, the scene's steps,
//! the fastest of the runs (and the median, which `perf_report` reports).
//!
//! ```text
//! cargo bench --bench box3d                                   # every scene, 4 runs each
//! cargo bench --bench box3d -- --scene convex_pile --runs 1 --engine hooke   # to profile
//! cargo bench --bench box3d -- --small                        # Box3D's debug sizes
//! cargo bench --bench box3d -- --scene large_pyramid --planar  # every body in its xy-plane
//! ```
//!
//! `--planar` locks every dynamic body to its xy-plane in both engines (hooke's
//! `LockedAxes::XY_PLANE`, rapier's z translation and x, y rotations): the pyramids stand in
//! that plane, so the scene is the same and what is timed is the locked path.

#[path = "../examples/common/rapier_box3d.rs"]
mod rapier_box3d;
#[path = "../examples/common/timing.rs"]
mod timing;

use hooke::prelude::*;
use hooke::tools::box3d::{self, Scene};

fn arg(name: &str) -> Option<String> {
    std::env::args().skip_while(|a| a != name).nth(1)
}

fn main() {
    let small = std::env::args().any(|a| a == "--small");
    let runs: usize = arg("--runs").and_then(|s| s.parse().ok()).unwrap_or(4);
    let engine = arg("--engine").unwrap_or_else(|| "both".into());
    let only = arg("--scene");
    let planar = std::env::args().any(|a| a == "--planar");
    println!("scene            engine  fastest ms/step  median ms/step");
    for scene in Scene::ALL {
        if only.as_deref().is_some_and(|o| o != scene.name()) {
            continue;
        }
        let steps = scene.steps();
        let (mut ours, mut theirs) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            if engine != "rapier" {
                let (mut w, bodies) = box3d::build(scene, small).unwrap();
                if planar {
                    for e in bodies {
                        w.entity_mut(e).insert(LockedAxes::XY_PLANE);
                    }
                }
                ours.push(1e3 * timing::mean_step_time(|| w.step_physics(), steps));
            }
            if engine != "hooke" {
                let (mut r, handles) = rapier_box3d::rapier_scene(scene, &scene.bodies(small));
                if planar {
                    use rapier3d::prelude::LockedAxes as Locks;
                    let locks = Locks::TRANSLATION_LOCKED_Z
                        | Locks::ROTATION_LOCKED_X
                        | Locks::ROTATION_LOCKED_Y;
                    for h in handles {
                        r.bodies[h].set_locked_axes(locks, false);
                    }
                }
                theirs.push(1e3 * timing::mean_step_time(|| r.step(), steps));
            }
        }
        for (name, t) in [("hooke", ours), ("rapier", theirs)] {
            if t.is_empty() {
                continue;
            }
            let fastest = t.iter().copied().fold(f64::INFINITY, f64::min);
            let median = timing::median(t);
            println!(
                "{:<16} {name:<7} {fastest:>15.2} {median:>15.2}",
                scene.name()
            );
        }
    }
}
