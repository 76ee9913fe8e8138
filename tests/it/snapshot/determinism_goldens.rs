//! Determinism goldens: fixed scenes stepped a fixed number of steps must reach exactly the
//! state digests checked into `tests/goldens/determinism.txt`, so any change that alters
//! results shows up here.
//!
//! **What invalidates them**: any change to the simulation's arithmetic (a new solver order,
//! a constant, a default setting), a different float environment — another CPU architecture
//! (aarch64's NEON instead of x86-64 SSE2), `-C target-cpu` flags that enable FMA — and a
//! different platform math library (sin, cos and exp come from it). The goldens were made on
//! x86-64 Linux, release profile, default target features. The digest counts entities by
//! storage order, not by id (a plugin's new resource shifts every id and used to move every
//! digest), but spawn order is storage order: build the scenes exactly as below. A change to
//! the snapshot format (a field added to a component) moves them too.
//!
//! **Updating them** after a change meant to alter results:
//! `HOOKE_UPDATE_GOLDENS=1 cargo test --release --test it determinism_goldens`, then commit the
//! file with a note of why the results moved.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenes;

const FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/goldens/determinism.txt");

type Scene = (&'static str, fn(&mut World), usize);

fn scenes() -> Vec<Scene> {
    vec![
        (
            "pile_30_boxes_10_balls",
            |w| {
                scenes::pile_scene(w, 30, 10).unwrap();
            },
            300,
        ),
        (
            "stack_4x4x4",
            |w| {
                scenes::box_stack(w, 4).unwrap();
            },
            300,
        ),
        (
            "rope_25_stiff_with_crate",
            |w| {
                scenes::rope_with_crate(w).unwrap();
            },
            300,
        ),
        (
            "cloth_12_on_ball",
            |w| {
                scenes::cloth_on_ball(w, 12).unwrap();
            },
            300,
        ),
        (
            "jelly_implicit_on_ground",
            |w| {
                scenes::ground(w).unwrap();
                scenes::jelly(w, Vec3::new(0.0, 1.0, 0.0), true).unwrap();
            },
            200,
        ),
    ]
}

fn digest(build: fn(&mut World), steps: usize) -> u64 {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    build(&mut world);
    for _ in 0..steps {
        world.step_physics();
    }
    Snapshot::capture(&world).unwrap().digest()
}

#[test]
fn fixed_scenes_reach_the_pinned_digests() {
    let found: Vec<(&str, u64)> = scenes()
        .into_iter()
        .map(|(name, build, steps)| (name, digest(build, steps)))
        .collect();
    // The same run twice gives the same digests (the goldens would be noise otherwise).
    assert_eq!(found[0].1, digest(scenes()[0].1, scenes()[0].2));
    let text: String = found
        .iter()
        .map(|(n, d)| format!("{n} {d:016x}\n"))
        .collect();
    if std::env::var_os("HOOKE_UPDATE_GOLDENS").is_some() {
        std::fs::write(FILE, &text).unwrap();
        return;
    }
    let pinned = std::fs::read_to_string(FILE).expect("tests/goldens/determinism.txt");
    let mut moved = Vec::new();
    for (name, d) in &found {
        let want = pinned
            .lines()
            .find_map(|l| l.strip_prefix(name)?.trim().parse::<String>().ok());
        if want.as_deref() != Some(&format!("{d:016x}")) {
            moved.push(format!("{name}: pinned {want:?}, now {d:016x}"));
        }
    }
    assert!(
        moved.is_empty(),
        "results changed (see the module docs to update the goldens):\n{}",
        moved.join("\n")
    );
}
