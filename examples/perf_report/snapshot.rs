//! Snapshots of the 1,000-box heap (10 × 10 columns of 10 boxes, settled for 2 s, contacts
//! and warm starts included): saving against one step of the same world, restoring against
//! building the same scene afresh through the public API.

use std::hint::black_box;

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenes;

use crate::timing::{Config, compare, line};

fn heap() -> World {
    let mut world = crate::quiet_world(1.0 / 60.0, 4, Integrator::SymplecticEuler);
    scenes::box_stack(&mut world, 10).unwrap();
    world
}

pub(crate) fn snapshot_lines(cfg: &Config) {
    let mut world = heap();
    for _ in 0..120 {
        world.step_physics();
    }
    let bytes = Snapshot::capture(&world).unwrap().to_bytes();
    let ron = Snapshot::capture(&world).unwrap().to_ron().unwrap();
    let pairs = world.resource::<Contacts>().touching().len();
    let mut stepped = heap();
    for _ in 0..120 {
        stepped.step_physics();
    }
    let (save, step) = compare(
        cfg,
        || {
            black_box(Snapshot::capture(&world).unwrap().to_bytes());
        },
        || stepped.step_physics(),
    );
    line(
        "snapshot_save_heap1000_vs_step",
        save,
        step,
        &format!(
            "capture + to_bytes: {} bytes ({:.0} per box), RON {} bytes; {pairs} touching pairs",
            bytes.len(),
            bytes.len() as f64 / 1000.0,
            ron.len()
        ),
    );
    let (restore, build) = compare(
        cfg,
        || {
            let mut w = crate::quiet_world(1.0 / 60.0, 4, Integrator::SymplecticEuler);
            Snapshot::from_bytes(&bytes)
                .unwrap()
                .restore(&mut w)
                .unwrap();
            black_box(w);
        },
        || {
            black_box(heap());
        },
    );
    line(
        "snapshot_restore_heap1000_vs_spawn",
        restore,
        build,
        "from_bytes + restore into a fresh world vs spawning the scene into one",
    );
}
