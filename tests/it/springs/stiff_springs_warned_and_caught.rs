//! Issue 13's hard cases at the defaults (60 Hz, 4 substeps, symplectic Euler): a rope stiff
//! enough to stretch < 0.1 % under its weight used to reach 1e23 m in two steps, finite and
//! never quarantined, and nothing told the user why. Now the stability limit is known and told
//! (`StabilityWarning`), and what diverges is caught in the step it happens
//! (`DivergenceGuard`). These tests keep the springs explicit (`StabilityPolicy::Warn`) to
//! watch the guard; at the default policy the same rope is solved implicitly
//! (`springs::implicit_entities`).

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::quarantine::BodyQuarantined;
use hooke::core::quarantine::DivergenceGuard;
use hooke::core::quarantine::QuarantineReason;
use hooke::core::quarantine::Quarantined;
use hooke::core::time::PhysicsTime;
use hooke::integrator::StabilityWarning;
use hooke::prelude::*;
use hooke::springs::SpringStability;
use hooke::tools::scenes;

/// The defaults, but springs past their limit stay explicit.
fn default_world() -> World {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.insert_resource(hooke::integrator::StabilityPolicy::Warn);
    w
}

fn warnings(w: &World) -> Vec<StabilityWarning> {
    let m = w.resource::<Messages<StabilityWarning>>();
    m.get_cursor().read(m).cloned().collect()
}

/// 20 nodes of 0.1 kg over 1 m, k such that the top segment stretches 0.1 % under the
/// rope's weight: k = 20 · 0.1 · 9.81 / (0.0526 · 1e-3) ≈ 3.7e5 N/m.
fn stiff_rope() -> hooke::springs::ChainBuilder {
    let weight = 20.0 * 0.1 * 9.81;
    let segment = 1.0 / 19.0;
    hooke::springs::ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), 20)
        .stiffness(weight / (segment * 1e-3))
}

#[test]
fn a_stiff_rope_is_told_its_limit_and_caught_when_it_diverges() {
    let mut w = default_world();
    let rope = stiff_rope().spawn(&mut w).unwrap();
    w.step_physics();
    let told = warnings(&w);
    assert_eq!(told.len(), 1, "{told:?}");
    let warning = &told[0];
    println!("{}", warning.advice());
    // A uniform chain's highest frequency is 2√(k/m): h_crit = √(m/k) (the bound is exact).
    let k = 20.0 * 0.1 * 9.81 / (1e-3 / 19.0);
    let closed = (0.1f32 / k).sqrt();
    assert!(
        (warning.critical_step / closed - 1.0).abs() < 0.01,
        "{} vs {closed}",
        warning.critical_step
    );
    assert!((warning.substep - 1.0 / 240.0).abs() < 1e-7);
    assert!(warning.substeps_needed > 4);
    assert!(rope.springs.contains(&warning.entity));
    let d = w.resource::<PhysicsDiagnostics>();
    assert_eq!(d.stability_warnings, 1);
    assert!((d.spring_critical_step - closed).abs() < 0.01 * closed);

    // It diverges, and is caught in the step it does: nothing flies off.
    let mut caught_at = None;
    for step in 1..=5 {
        w.step_physics();
        let farthest = rope
            .nodes
            .iter()
            .filter(|&&n| w.get::<Quarantined>(n).is_none())
            .map(|&n| w.get::<Position>(n).unwrap().0.length())
            .fold(0.0f32, f32::max);
        assert!(farthest < 100.0, "step {step}: a live node at {farthest} m");
        if caught_at.is_none()
            && rope
                .nodes
                .iter()
                .any(|&n| w.get::<Quarantined>(n).is_some())
        {
            caught_at = Some(step);
        }
    }
    let caught_at = caught_at.expect("the divergence is caught");
    let reasons: Vec<QuarantineReason> = rope
        .nodes
        .iter()
        .filter_map(|&n| w.get::<Quarantined>(n).map(|q| q.reason.clone()))
        .collect();
    println!(
        "caught at step {caught_at}: {:?}",
        &reasons[..reasons.len().min(3)]
    );
    assert!(caught_at <= 3);
    assert!(reasons.iter().all(|r| matches!(
        r,
        QuarantineReason::Diverged { .. } | QuarantineReason::SpringFailed { .. }
    )));
    assert!(w.resource::<PhysicsDiagnostics>().quarantined_total > 0);
    // The pin at the top is not blamed.
    assert!(w.get::<Quarantined>(rope.nodes[0]).is_none());
    // Told once.
    assert_eq!(w.resource::<PhysicsDiagnostics>().stability_warnings, 1);
}

#[test]
fn the_substeps_the_warning_names_keep_the_same_rope_stable() {
    let mut w = default_world();
    stiff_rope().spawn(&mut w).unwrap();
    w.step_physics();
    let needed = warnings(&w)[0].substeps_needed;
    let mut w = scenes::world_with(
        1.0 / 60.0,
        needed,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let rope = stiff_rope().spawn(&mut w).unwrap();
    for _ in 0..120 {
        w.step_physics();
    }
    println!("{needed} substeps: 2 s without a warning or a quarantine");
    assert!(warnings(&w).is_empty());
    for &n in &rope.nodes {
        assert!(w.get::<Quarantined>(n).is_none());
        assert!(w.get::<Position>(n).unwrap().0.length() < 3.0);
    }
}

/// Two free 1 kg masses on a k = 100 N/m spring: ω = √(2k/m), h_crit = 2/ω = 0.1414 s.
/// Just below the limit symplectic Euler stays bounded; just above it diverges and the
/// guard catches it.
#[test]
fn the_critical_step_of_a_two_mass_spring_is_the_closed_form_and_is_the_edge() {
    let mut nodes = Nodes::new();
    nodes.push(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap();
    nodes
        .push(Vec3::new(1.1, 0.0, 0.0), Vec3::ZERO, 1.0)
        .unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 1, 1.0, 100.0, 0.0).unwrap();
    let closed = 2.0 / (2.0f32 * 100.0).sqrt();
    let h = net.critical_step(&nodes);
    assert!((h / closed - 1.0).abs() < 1e-5, "{h} vs {closed}");
    for (factor, stable) in [(0.95f32, true), (1.05, false)] {
        let mut w = scenes::world_with(factor * closed, 1, Integrator::SymplecticEuler, Vec3::ZERO)
            .unwrap();
        w.insert_resource(hooke::integrator::StabilityPolicy::Warn);
        let e = w.spawn((nodes.clone(), net.clone())).id();
        let mut peak = 0.0f32;
        for _ in 0..2000 {
            w.step_physics();
            if w.get::<Quarantined>(e).is_some() {
                break;
            }
            let n = w.get::<Nodes>(e).unwrap();
            peak = peak.max((n.positions()[1] - n.positions()[0]).length());
        }
        let caught = w.get::<Quarantined>(e).map(|q| q.reason.clone());
        println!("h = {factor} h_crit: peak length {peak:.3} m, {caught:?}");
        if stable {
            // Bounded by symplectic Euler's conserved modified energy: the stretch's peak is
            // the initial 0.1 m over √(1 − (ωh/2)²) = √(1 − 0.95²).
            let bound = 1.0 + 0.1 / (1.0 - factor * factor).sqrt();
            assert!(caught.is_none() && peak < bound + 0.01, "{peak} vs {bound}");
            assert!(warnings(&w).is_empty());
        } else {
            assert!(
                matches!(
                    caught,
                    Some(QuarantineReason::Diverged { node: Some(_), .. })
                ),
                "{caught:?}"
            );
            assert_eq!(warnings(&w).len(), 0, "messages of older steps are gone");
            assert_eq!(w.resource::<PhysicsDiagnostics>().stability_warnings, 1);
        }
    }
}

#[test]
fn a_stiff_cloth_is_told_and_its_runaway_node_named() {
    let mut w = default_world();
    let cloth = hooke::cloth::ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 16, 16, 0.05)
        .stiffness(2e5, 2e4, 2e3)
        .spawn(&mut w)
        .unwrap();
    w.step_physics();
    let told = warnings(&w);
    assert_eq!(told.len(), 1);
    assert_eq!(told[0].entity, cloth);
    let limit = w.get::<SpringStability>(cloth).unwrap().critical_step;
    assert_eq!(limit, told[0].critical_step);
    println!("{}", told[0].advice());
    let mut caught = None;
    for _ in 0..5 {
        w.step_physics();
        if let Some(q) = w.get::<Quarantined>(cloth) {
            caught = Some(q.reason.clone());
            break;
        }
        let n = w.get::<Nodes>(cloth).unwrap();
        assert!(n.positions().iter().all(|p| p.length() < 100.0));
    }
    println!("{caught:?}");
    assert!(matches!(
        caught,
        Some(QuarantineReason::Diverged { node: Some(_), speed }) if speed > 1e4
    ));
    let m = w.resource::<Messages<BodyQuarantined>>();
    assert!(m.get_cursor().read(m).any(|q| q.entity == cloth));
}

/// A pinned hook and a 1 kg ball 150 m below it on a 1 m spring (k = 10 N/m): strain 149.
fn torn_spring(w: &mut World) -> (Entity, Entity, Entity) {
    let hook = w
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    w.entity_mut(hook).insert(Mass::PINNED);
    let ball = w
        .spawn(ParticleBundle::new(Vec3::new(0.0, -150.0, 0.0), Vec3::ZERO, 1.0).unwrap())
        .id();
    let spring = hooke::springs::Spring::new(hook, ball, 1.0, 10.0, 0.0)
        .unwrap()
        .spawn(w)
        .unwrap();
    (hook, ball, spring)
}

#[test]
fn a_spring_torn_past_the_strain_limit_names_itself_and_spares_its_pin() {
    let mut w = default_world();
    // Strain 149 > the default limit of 100.
    let (hook, ball, spring) = torn_spring(&mut w);
    w.step_physics();
    match w.get::<Quarantined>(ball).map(|q| q.reason.clone()) {
        Some(QuarantineReason::SpringFailed { spring: s, strain }) => {
            assert_eq!(s, spring);
            assert!((strain - 149.0).abs() < 0.5, "{strain}");
        }
        other => panic!("{other:?}"),
    }
    assert!(
        w.get::<Quarantined>(hook).is_none(),
        "the pin did not diverge"
    );
    // A looser guard lets the same spring pull.
    let mut w = default_world();
    w.insert_resource(DivergenceGuard {
        max_spring_strain: 1e3,
        ..DivergenceGuard::default()
    });
    let (_, ball, _) = torn_spring(&mut w);
    w.step_physics();
    assert!(w.get::<Quarantined>(ball).is_none());
    assert!(
        PhysicsTime::default().substeps() == 4,
        "the defaults these tests assume"
    );
}
