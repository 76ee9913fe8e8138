//! Backward Euler for spring meshes (`Nodes` + `SpringNetwork` + `ImplicitEuler`), the same
//! solve as soft bodies', against closed forms: the unit oscillator's energy ×1/(1+ω²h²) per
//! step (DESIGN.md: ×0.0014 after 10 periods) and order 1; a stiff hanging rope at 60 Hz with
//! one substep, each spring carrying the weight below it; a stiff cloth stable where
//! symplectic Euler needs many substeps; momentum kept.

use crate::common;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::cloth::ClothBuilder;
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::integrator::ImplicitState;
use hooke::prelude::*;

use common::awake_world as world;

/// m = 1 kg on a zero-length spring k = 4π² to a pinned node: period 1 s, x₀ = 1.
fn oscillator(w: &mut World) -> Entity {
    let mut nodes = Nodes::new();
    nodes.push_pinned(Vec3::ZERO).unwrap();
    nodes.push(Vec3::X, Vec3::ZERO, 1.0).unwrap();
    let mut net = SpringNetwork::new();
    let k = 4.0 * std::f32::consts::PI.powi(2);
    net.push(0, 1, 0.0, k, 0.0).unwrap();
    w.spawn((nodes, net, ImplicitEuler::default())).id()
}

fn energy(w: &World, e: Entity) -> f32 {
    let n = w.get::<Nodes>(e).unwrap();
    let (x, v) = (n.positions()[1], n.velocities()[1]);
    let k = 4.0 * std::f32::consts::PI.powi(2);
    0.5 * v.length_squared() + 0.5 * k * x.length_squared()
}

#[test]
fn implicit_euler_on_the_unit_oscillator_loses_energy_as_the_closed_form_and_is_first_order() {
    let h = 1.0 / 60.0;
    let mut w = world(h, 1, Vec3::ZERO);
    let e = oscillator(&mut w);
    let e0 = energy(&w, e);
    for _ in 0..600 {
        w.step_physics();
    }
    let ratio = energy(&w, e) / e0;
    let omega2 = 4.0 * std::f64::consts::PI.powi(2);
    let closed = (1.0 / (1.0 + omega2 * f64::from(h).powi(2))).powi(600) as f32;
    println!("energy after 10 periods ×{ratio:.5} (closed form ×{closed:.5}; DESIGN.md ×0.0014)");
    assert!((ratio / closed - 1.0).abs() < 0.02, "{ratio} vs {closed}");
    assert!((ratio - 0.0014).abs() < 0.0002);
    let s = w.get::<ImplicitState>(e).unwrap().last_solve();
    assert!(s.newton_iterations >= 1);

    // Order at t = 0.3 s (not a multiple of the period): x(t) = cos 2πt.
    let error_at = |h: f32| {
        let mut w = world(h, 1, Vec3::ZERO);
        let e = oscillator(&mut w);
        let steps = (0.3 / h).round() as usize;
        for _ in 0..steps {
            w.step_physics();
        }
        let x = w.get::<Nodes>(e).unwrap().positions()[1].x;
        (x - (2.0 * std::f32::consts::PI * 0.3).cos()).abs()
    };
    let (coarse, fine) = (error_at(0.3 / 60.0), error_at(0.3 / 120.0));
    let order = (coarse / fine).log2();
    println!("error at t = 0.3 s: {coarse:.2e} -> {fine:.2e}, order {order:.2}");
    assert!((order - 1.0).abs() < 0.15, "{order}");
}

/// A rope of `count` nodes built as a mesh, hanging from a pin at its top.
fn hanging_rope(count: usize, k: f32, c: f32) -> (Nodes, SpringNetwork) {
    let segment = 1.0 / (count - 1) as f32;
    let mut nodes = Nodes::new();
    nodes.push_pinned(Vec3::new(0.0, 2.0, 0.0)).unwrap();
    for i in 1..count {
        nodes
            .push(
                Vec3::new(0.0, 2.0 - segment * i as f32, 0.0),
                Vec3::ZERO,
                0.1,
            )
            .unwrap();
    }
    let mut net = SpringNetwork::new();
    for i in 0..count - 1 {
        net.push(i, i + 1, segment, k, c).unwrap();
    }
    (nodes, net)
}

#[test]
fn a_stiff_rope_at_60_hz_with_one_substep_hangs_with_each_spring_carrying_the_weight_below() {
    // k = 3.7e5 N/m on 0.1 kg nodes: symplectic Euler would need h < √(m/k) = 0.52 ms.
    let (count, k) = (20usize, 3.7e5f32);
    let mut w = world(1.0 / 60.0, 1, Vec3::new(0.0, -9.81, 0.0));
    let (nodes, net) = hanging_rope(count, k, 1.0);
    let limit = net.critical_step(&nodes);
    let e = w.spawn((nodes, net, ImplicitEuler::default())).id();
    for _ in 0..300 {
        w.step_physics();
    }
    assert!(w.get::<Quarantined>(e).is_none());
    let n = w.get::<Nodes>(e).unwrap();
    let segment = 1.0 / (count - 1) as f32;
    let mut worst = 0.0f32;
    for i in 0..count - 1 {
        let l = (n.positions()[i + 1] - n.positions()[i]).length();
        // Spring i carries the nodes below it: (count − 1 − i) · 0.1 kg.
        let tension = (count - 1 - i) as f32 * 0.1 * 9.81;
        let expected = segment + tension / k;
        worst = worst.max(((l - segment) / (expected - segment) - 1.0).abs());
    }
    let speed = n.max_speed();
    let report = w.get::<ImplicitState>(e).unwrap().last_solve();
    println!(
        "stretch against the weight below, worst {:.2}% off; at rest {speed:.1e} m/s; explicit limit {:.2e} s vs h = {:.2e} s; last step {} Newton, {} CG",
        100.0 * worst,
        limit,
        1.0 / 60.0,
        report.newton_iterations,
        report.cg_iterations
    );
    assert!(worst < 0.02, "{worst}");
    assert!(speed < 1e-3);
    assert!(limit < 1.0 / 600.0, "explicit would need > 10 substeps");
}

#[test]
fn a_stiff_cloth_pinned_at_two_corners_is_stable_implicit_where_explicit_needs_many_substeps() {
    let cloth = || {
        ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 32, 32, 0.03)
            .stiffness(5e3, 1e3, 1e2)
            .build()
            .unwrap()
    };
    let (nodes, net) = cloth();
    let limit = net.critical_step(&nodes);
    let needed = ((1.0 / 60.0) / (0.9 * limit)).ceil() as u32;
    let mut w = world(1.0 / 60.0, 1, Vec3::new(0.0, -9.81, 0.0));
    let e = w.spawn((nodes, net, ImplicitEuler::default())).id();
    let mut peak = 0.0f32;
    let (mut newton, mut cg) = (0u32, 0u32);
    for _ in 0..600 {
        w.step_physics();
        let r = w.get::<ImplicitState>(e).unwrap().last_solve();
        (newton, cg) = (newton + r.newton_iterations, cg + r.cg_iterations);
        let n = w.get::<Nodes>(e).unwrap();
        peak = peak.max(n.max_speed());
    }
    assert!(w.get::<Quarantined>(e).is_none());
    let n = w.get::<Nodes>(e).unwrap();
    let lowest = n.bounds().map_or(f32::INFINITY, |b| b.0.y);
    let speed = n.max_speed();
    println!(
        "32×32 cloth, explicit limit {limit:.2e} s ({needed} substeps at 60 Hz); implicit ×1: 10 s bounded, peak {peak:.2} m/s, lowest node at {lowest:.3} m, now {speed:.2} m/s; {:.1} Newton, {:.1} CG per step",
        f64::from(newton) / 600.0,
        f64::from(cg) / 600.0
    );
    assert!(needed > 10, "{needed}");
    // A 0.93 m cloth hanging from two corners: nothing can fall more than its diagonal.
    assert!(lowest > 2.0 - 1.4, "{lowest}");
    assert!(peak < 10.0, "{peak}");
    // Still swinging slowly on its two pins (backward Euler barely damps so low a mode), and
    // slower than it fell.
    assert!(speed < peak, "{speed}");
}

#[test]
fn a_free_cloth_keeps_its_momentum_under_the_implicit_step() {
    let mut w = world(1.0 / 60.0, 1, Vec3::ZERO);
    let (mut nodes, net) = ClothBuilder::new(Vec3::ZERO, 12, 12, 0.05)
        .stiffness(1e4, 1e3, 1e2)
        .pin_corners(false)
        .build()
        .unwrap();
    for i in 0..nodes.len() {
        let p = nodes.positions()[i];
        // A drift plus a twist and a crumple.
        let v = Vec3::new(0.3, 0.1 * p.z, -0.2) + Vec3::new(0.0, (7.0 * p.x).sin(), 0.0);
        nodes.set_velocity(i, v).unwrap();
    }
    let momentum = |n: &Nodes| -> Vec3 {
        (0..n.len())
            .map(|i| n.mass(i).unwrap() * Vec3::from(n.velocities()[i]))
            .sum()
    };
    let p0 = momentum(&nodes);
    let e = w.spawn((nodes, net, ImplicitEuler::default())).id();
    for _ in 0..120 {
        w.step_physics();
    }
    let p1 = momentum(w.get::<Nodes>(e).unwrap());
    println!("P {p0} -> {p1}");
    assert!(
        (p1 - p0).length() < 1e-4 * p0.length().max(1.0),
        "{p0} -> {p1}"
    );
}
