//! The explicit limit counts damping between two free nodes. `ChainBuilder::rope(..)
//! .stiffness(1000.).damping(20.)` at the defaults used to blow up (9 nodes quarantined, the
//! end thrown 21 m) without a warning: the old bound h < 2m/Σc ignored that a damper
//! between two free masses relaxes their relative motion twice as fast as a damper to a wall.
//! The limit is now h = (√(C² + 4K) − C)/K with both row sums counting the coupling, exact
//! for one damped spring between two free masses.

use crate::common;

use bevy_ecs::message::Messages;
use glam::Vec3;
use hooke::core::quarantine::Quarantined;
use hooke::integrator::{StabilityPolicy, StabilityWarning};
use hooke::prelude::*;
use hooke::springs::ChainBuilder;
use hooke::tools::scenes;

/// Whether two free masses `m` (kg) on a spring k (N/m), c (N·s/m), released 10% stretched, run
/// 3,000 explicit steps of `h` (s) without diverging; and whether they were warned.
fn run(m: f32, k: f32, c: f32, h: f32) -> (bool, u64) {
    let mut w = scenes::world_with(h, 1, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    w.insert_resource(StabilityPolicy::Warn);
    let mut nodes = Nodes::new();
    nodes.push(Vec3::ZERO, Vec3::ZERO, m).unwrap();
    nodes.push(Vec3::new(1.1, 0.0, 0.0), Vec3::ZERO, m).unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 1, 1.0, k, c).unwrap();
    let e = w.spawn((nodes, net)).id();
    let mut bounded = true;
    for _ in 0..3000 {
        w.step_physics();
        let n = w.get::<Nodes>(e).unwrap();
        if w.get::<Quarantined>(e).is_some() || (n.positions()[1] - n.positions()[0]).length() > 2.0
        {
            bounded = false;
            break;
        }
    }
    (
        bounded,
        w.resource::<PhysicsDiagnostics>().stability_warnings,
    )
}

#[test]
fn past_the_limit_is_told_and_inside_it_nothing_diverges_over_stiffness_damping_and_mass() {
    let mut cases = 0;
    for m in [0.01f32, 1.0, 100.0] {
        for k in [10.0f32, 1e3, 1e5] {
            // ζ of the pair's relative motion: c (2/m) = 2ζω with ω² = 2k/m.
            let omega = (2.0 * k / m).sqrt();
            for zeta in [0.0f32, 0.1, 1.0, 10.0] {
                let c = zeta * omega * m;
                let mut nodes = Nodes::new();
                nodes.push(Vec3::ZERO, Vec3::ZERO, m).unwrap();
                nodes.push(Vec3::new(1.1, 0.0, 0.0), Vec3::ZERO, m).unwrap();
                let mut net = SpringNetwork::new();
                net.push(0, 1, 1.0, k, c).unwrap();
                let h = net.critical_step(&nodes);
                // The damped oscillator's own edge, ωh = 2 (√(1 + ζ²) − ζ).
                let closed = 2.0 * ((1.0 + zeta * zeta).sqrt() - zeta) / omega;
                assert!(
                    (h / closed - 1.0).abs() < 1e-4,
                    "m {m} k {k} ζ {zeta}: {h} vs {closed}"
                );
                let (inside, told_inside) = run(m, k, c, 0.95 * h);
                let (outside, told_outside) = run(m, k, c, 1.05 * h);
                assert!(
                    inside && told_inside == 0,
                    "m {m} k {k} ζ {zeta}: diverged inside"
                );
                assert_eq!(
                    told_outside, 1,
                    "m {m} k {k} ζ {zeta}: not told past the limit"
                );
                assert!(!outside, "m {m} k {k} ζ {zeta}: the limit is not the edge");
                cases += 1;
            }
        }
    }
    println!("{cases} cases: stable at 0.95 h_crit and untold, divergent at 1.05 h_crit and told");
}

#[test]
fn the_damped_rope_of_the_report_is_switched_at_the_defaults_and_holds() {
    let mut w = common::default_world();
    let rope = ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), 20)
        .stiffness(1000.0)
        .damping(20.0)
        .spawn(&mut w)
        .unwrap();
    w.step_physics();
    let m = w.resource::<Messages<StabilityWarning>>();
    let told: Vec<_> = m.get_cursor().read(m).cloned().collect();
    assert_eq!(told.len(), 1, "{told:?}");
    // Twice the world's substeps suffice: the policy steps the rope on its own, 2 per substep.
    assert_eq!(
        told[0].rescue,
        Some(hooke::integrator::Rescue::LocalSubsteps(2))
    );
    println!("{}", told[0].advice());
    for _ in 0..300 {
        w.step_physics();
    }
    let end = common::x(&w, *rope.nodes.last().unwrap());
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    println!("after 5 s the end hangs at {end}");
    assert!(end.length() < 2.0 + 1.5 && end.is_finite(), "{end}");
}
