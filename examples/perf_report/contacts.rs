//! Contact scenes side by side with rapier 0.36: the same boxes from the same scene specs,
//! dt = 1/60, sleeping off. hooke: 4 substeps (solve + relax each); rapier: its defaults
//! (4 solver iterations, each one PGS and one stabilisation pass).

use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::scenes::{self, BoxSpec};
use rapier3d::prelude as rp;

use crate::timing::{Config, compare, line, median};

fn ours(specs: &[BoxSpec]) -> (World, Vec<Entity>) {
    let mut world = crate::quiet_world(1.0 / 60.0, 4, Integrator::SymplecticEuler);
    world.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let boxes = scenes::spawn_boxes(&mut world, specs).unwrap();
    (world, boxes)
}

fn theirs(specs: &[BoxSpec]) -> (rp::PhysicsWorld, Vec<rp::RigidBodyHandle>) {
    crate::rapier_boxes::rapier_boxes(specs, |_| 1000.0)
}

/// The top of a stack (highest box at the start) after 10 s, minus where it started (m).
fn drifts(specs: &[BoxSpec]) -> (f32, f32) {
    let top = specs
        .iter()
        .filter(|b| !b.fixed)
        .enumerate()
        .max_by(|a, b| a.1.position.y.total_cmp(&b.1.position.y))
        .map_or(0, |(i, _)| i);
    let start = specs.iter().filter(|b| !b.fixed).nth(top).unwrap().position;
    let (mut w, boxes) = ours(specs);
    let (mut r, handles) = theirs(specs);
    for _ in 0..600 {
        w.step_physics();
        r.step();
    }
    let a = (w.get::<Position>(boxes[top]).unwrap().get() - start).length();
    let b = (r.bodies[handles[top]].translation() - start).length();
    (a, b)
}

fn steady(cfg: &Config, name: &str, specs: &[BoxSpec], settle: usize, stability: bool) {
    let (mut w, _) = ours(specs);
    let (mut r, _) = theirs(specs);
    for _ in 0..settle {
        w.step_physics();
        r.step();
    }
    let (a, b) = compare(cfg, || w.step_physics(), || r.step());
    let note = if stability {
        let (da, db) = drifts(specs);
        format!(
            "top drift over 10 s: hooke {:.1} mm, rapier {:.1} mm",
            da * 1000.0,
            db * 1000.0
        )
    } else {
        format!("{} bodies", specs.len() - 1)
    };
    line(name, a, b, &note);
}

/// The falling window is finite, so every sample starts from fresh worlds.
fn falling_window(cfg: &Config, name: &str, specs: &[BoxSpec], steps: usize) {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..cfg.samples {
        let (mut w, _) = ours(specs);
        let (mut r, _) = theirs(specs);
        w.step_physics();
        r.step();
        let t = Instant::now();
        for _ in 0..steps {
            w.step_physics();
        }
        a.push(t.elapsed().as_secs_f64() * 1e9 / steps as f64);
        let t = Instant::now();
        for _ in 0..steps {
            r.step();
        }
        b.push(t.elapsed().as_secs_f64() * 1e9 / steps as f64);
    }
    line(
        name,
        median(a),
        median(b),
        "first 20 steps: boxes in the air",
    );
}

/// One box bouncing on the ground, with and without 10,000 static boxes around (none
/// within reach): what idle static geometry costs per step.
fn idle_statics(cfg: &Config) {
    let mut with = vec![BoxSpec::ground()];
    for i in 0..10_000 {
        let (a, b) = ((i % 100) as f32, (i / 100) as f32);
        with.push(BoxSpec {
            half: Vec3::splat(0.4),
            position: Vec3::new(a * 2.0 - 100.0, 0.4, b * 2.0 + 10.0),
            rotation: glam::Quat::IDENTITY,
            fixed: true,
        });
    }
    let body = BoxSpec {
        half: Vec3::splat(0.5),
        position: Vec3::new(0.0, 3.0, 0.0),
        rotation: glam::Quat::IDENTITY,
        fixed: false,
    };
    with.push(body);
    let without = vec![BoxSpec::ground(), body];
    let (mut a, _) = ours(&with);
    let (mut b, _) = ours(&without);
    let (x, y) = compare(cfg, || a.step_physics(), || b.step_physics());
    line(
        "contacts_idle_statics10k_vs_none",
        x,
        y,
        "one moving box; goal ≈ 1.0",
    );
}

pub fn contact_scenes(cfg: &Config, quick: bool) {
    idle_statics(cfg);
    let falling = scenes::falling_boxes_spec(1000);
    falling_window(cfg, "contacts_falling1000_freefall_vs_rapier", &falling, 20);
    steady(
        cfg,
        "contacts_falling1000_resting_vs_rapier",
        &falling,
        180,
        false,
    );
    steady(
        cfg,
        "contacts_stack10x10x10_vs_rapier",
        &scenes::box_stack_spec(10),
        0,
        true,
    );
    steady(
        cfg,
        "contacts_pyramid20_vs_rapier",
        &scenes::pyramid_spec(20),
        0,
        true,
    );
    if !quick {
        steady(
            cfg,
            "contacts_pyramid50_vs_rapier",
            &scenes::pyramid_spec(50),
            0,
            true,
        );
    }
}
