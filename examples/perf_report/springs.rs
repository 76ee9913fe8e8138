//! Spring meshes under backward Euler (one substep at 60 Hz) against symplectic Euler at the
//! substeps their stability needs: the price of stability, both ways.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::{ClothBuilder, ImplicitEuler, ImplicitState};

use crate::timing::{Config, compare, line};

fn world(substeps: u32) -> World {
    let mut w = crate::quiet_world(1.0 / 60.0, substeps, Integrator::SymplecticEuler);
    w.resource_mut::<hooke::SleepSettings>().enabled = false;
    w
}

/// `nodes` and `springs` of a mesh, stepped implicitly at 60 Hz × 1 and explicitly at the
/// substeps its limit asks for, each after 60 warm-up steps.
fn pair(cfg: &Config, name: &str, mesh: impl Fn() -> (Nodes, SpringNetwork)) {
    let (nodes, net) = mesh();
    let limit = net.critical_step(&nodes);
    let needed = ((1.0 / 60.0) / (0.9 * limit)).ceil() as u32;
    let springs = net.len();
    let mut implicit = world(1);
    let e = implicit.spawn((nodes, net, ImplicitEuler::default())).id();
    let (nodes, net) = mesh();
    let mut explicit = world(needed);
    explicit.spawn((nodes, net));
    for _ in 0..60 {
        implicit.step_physics();
        explicit.step_physics();
    }
    let (ours, reference) = compare(cfg, || implicit.step_physics(), || explicit.step_physics());
    let r = implicit.get::<ImplicitState>(e).unwrap().last_solve();
    line(
        name,
        ours,
        reference,
        &format!(
            "{springs} springs; implicit x1 ({} Newton, {} CG) vs symplectic x{needed} (its limit {limit:.1e} s)",
            r.newton_iterations, r.cg_iterations
        ),
    );
}

pub fn implicit_springs(cfg: &Config) {
    for n in [32usize, 64] {
        pair(
            cfg,
            &format!("springs_cloth{n}_implicit_x1_vs_symplectic_needed"),
            || {
                ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), n, n, 0.03)
                    .stiffness(5e3, 1e3, 1e2)
                    .build()
                    .unwrap()
            },
        );
    }
    pair(
        cfg,
        "springs_rope100_implicit_x1_vs_symplectic_needed",
        || {
            // 100 links of 1 cm, 10 g nodes, k = 1e4 N/m: stretches 1 % under its weight.
            let mut nodes = Nodes::new();
            nodes.push_pinned(Vec3::new(0.0, 2.0, 0.0)).unwrap();
            for i in 1..=100 {
                nodes
                    .push(Vec3::new(0.01 * i as f32, 2.0, 0.0), Vec3::ZERO, 0.01)
                    .unwrap();
            }
            let mut net = SpringNetwork::new();
            for i in 0..100 {
                net.push(i, i + 1, 0.01, 1e4, 0.1).unwrap();
            }
            (nodes, net)
        },
    );
}
