//! Tall and heavy stacks, hooke beside rapier 0.36, both at their default settings with
//! sleeping off, then hooke with the stiff-contact settings the README gives for them.
//!
//! `cargo run --release --example stacks` (about a minute). Prints one line per case: how far
//! the top sank, how far it strayed from where it stood (m), and whether it stood 20 s.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::scenes::{self, BoxSpec};
#[path = "common/rapier_boxes.rs"]
mod rapier_boxes;

const SECONDS: usize = 20;

/// The settings a run uses: substeps and contact frequency (Hz).
#[derive(Clone, Copy)]
struct Stiffness {
    substeps: u32,
    hertz: f32,
}

const DEFAULTS: Stiffness = Stiffness {
    substeps: 4,
    hertz: 60.0,
};

/// How far the top box sank, the farthest it strayed sideways and out of the scene's plane
/// (z), over the run (m).
struct Outcome {
    sink: f32,
    strayed: f32,
    out_of_plane: f32,
}

impl Outcome {
    /// `compressed`: how far the soft contacts alone let the top sink (m). The case stands
    /// when the top strayed less than half a box and sank less than that plus half a box.
    fn line(&self, engine: &str, case: &str, compressed: f32) {
        let stood = self.strayed < 0.5 && self.sink < compressed + 0.5;
        println!(
            "{case:<26} {engine:<27} sink {:>8.4} m  strayed {:>7.4} m  out of plane {:>7.4} m  {}",
            self.sink,
            self.strayed,
            self.out_of_plane,
            if stood { "stands" } else { "falls" }
        );
    }
}

fn ours(specs: &[BoxSpec], densities: &[f32], s: Stiffness) -> Outcome {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.insert_resource(hooke::core::time::PhysicsTime::new(1.0 / 60.0, s.substeps).unwrap());
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    w.resource_mut::<hooke::collision::ContactSettings>().hertz = s.hertz;
    let boxes = scenes::spawn_boxes_with_density(&mut w, specs, |i| densities[i]).unwrap();
    let top = top_of(specs);
    let start = specs.iter().filter(|b| !b.fixed).nth(top).unwrap().position;
    let (mut strayed, mut out_of_plane) = (0.0f32, 0.0f32);
    for _ in 0..SECONDS * 60 {
        w.step_physics();
        let p = w.get::<Position>(boxes[top]).unwrap().get();
        strayed = strayed.max(Vec3::new(p.x - start.x, 0.0, p.z - start.z).length());
        out_of_plane = out_of_plane.max((p.z - start.z).abs());
    }
    Outcome {
        sink: start.y - w.get::<Position>(boxes[top]).unwrap().get().y,
        strayed,
        out_of_plane,
    }
}

fn theirs(specs: &[BoxSpec], densities: &[f32]) -> Outcome {
    let (mut world, handles) = rapier_boxes::rapier_boxes(specs, |i| densities[i]);
    let top = top_of(specs);
    let start = specs.iter().filter(|b| !b.fixed).nth(top).unwrap().position;
    let (mut strayed, mut out_of_plane) = (0.0f32, 0.0f32);
    for _ in 0..SECONDS * 60 {
        world.step();
        let p = world.bodies[handles[top]].translation();
        strayed = strayed.max(Vec3::new(p.x - start.x, 0.0, p.z - start.z).length());
        out_of_plane = out_of_plane.max((p.z - start.z).abs());
    }
    Outcome {
        sink: start.y - world.bodies[handles[top]].translation().y,
        strayed,
        out_of_plane,
    }
}

/// A case: name, boxes, densities (ground first), how far its top sinks on the soft
/// contacts alone (m), and stiffer settings to try as well.
type Case = (String, Vec<BoxSpec>, Vec<f32>, f32, Option<Stiffness>);

/// Index among the dynamic boxes of the highest one.
fn top_of(specs: &[BoxSpec]) -> usize {
    specs
        .iter()
        .filter(|b| !b.fixed)
        .enumerate()
        .max_by(|a, b| a.1.position.y.total_cmp(&b.1.position.y))
        .map_or(0, |(i, _)| i)
}

fn main() {
    let stiff = |substeps: u32| Stiffness {
        substeps,
        hertz: 7.5 * substeps as f32,
    };
    // Each case: name, boxes, densities, the soft contacts' own sink at the defaults (30 Hz
    // between bodies, 60 Hz against the ground; see `tests/it/collision/tall_stacks.rs`), and the
    // stiffer settings to try as well.
    let mut cases: Vec<Case> = Vec::new();
    for n in [10, 20, 30, 50, 100, 200] {
        let specs = scenes::column_spec(n);
        let rho = vec![1000.0; specs.len()];
        let omega = std::f32::consts::TAU * 30.0;
        let nf = n as f32;
        let sink = 9.81 / (omega * omega) * (nf / 4.0 + nf * (nf - 1.0));
        let s = (n == 200).then(|| stiff(32));
        cases.push((format!("column of {n}"), specs, rho, sink, s));
    }
    let specs = scenes::squeeze_spec();
    let rho = scenes::squeeze_densities(1000.0).to_vec();
    cases.push((
        "1 t between two 1,000 t".into(),
        specs,
        rho,
        0.0,
        Some(stiff(64)),
    ));
    let specs = scenes::pyramid_spec(50);
    let rho = vec![1000.0; specs.len()];
    cases.push(("50-row pyramid, one deep".into(), specs, rho, 0.5, None));
    for (name, specs, rho, sink, stiffer) in &cases {
        ours(specs, rho, DEFAULTS).line("hooke, defaults", name, *sink);
        theirs(specs, rho).line("rapier, defaults", name, *sink);
        if let Some(s) = *stiffer {
            let label = format!("hooke, {} substeps {} Hz", s.substeps, s.hertz);
            ours(specs, rho, s).line(&label, name, 0.0);
        }
    }
}
