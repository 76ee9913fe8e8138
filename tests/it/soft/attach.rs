//! Soft-body nodes attached to rigid bodies, two-way (`NodeAttachments`), against closed
//! forms: a bar holding a box stretches by F L / (E A) plus its own weight's ρ g L² / (2E),
//! momentum passes exactly between the two, and a kinematic body carries its nodes.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::rigid::AngularMomentum;
use hooke::rigid::Inertia;
use hooke::rigid::RigidBody;
use hooke::soft::{CellSplit, Material, NodeAttachments, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

fn world(g: Vec3) -> World {
    let mut w = scenes::world_with(1.0 / 60.0, 1, Integrator::SymplecticEuler, g).unwrap();
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    w
}

/// A 1 m bar along y (0.1 m square, ν = 0), from y = 0 to 1, its top pinned.
fn bar(young: f32, density: f32) -> (Nodes, SoftBody, Vec<usize>) {
    let mesh = TetMesh::cuboid(Vec3::new(0.1, 1.0, 0.1), [2, 10, 2], CellSplit::Six).unwrap();
    let material = Material::new(young, 0.0, density).unwrap();
    let (mut nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.0, 0.5, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let bottom = nodes.select(|p| p.y < 1e-4);
    assert_eq!(
        nodes.pin_where(|p| p.y > 1.0 - 1e-4),
        9,
        "the top face's 3 × 3 nodes"
    );
    (nodes, body, bottom)
}

fn rigid_box(w: &mut World, at: Vec3, kg: f32) -> Entity {
    let i = kg * 0.01 / 6.0; // a 0.1 m cube
    w.spawn((
        RigidBody::Dynamic,
        Mass::new(kg).unwrap(),
        Inertia::diagonal(i, i, i).unwrap(),
        Position::from(at),
    ))
    .id()
}

#[test]
fn a_bar_holding_a_box_stretches_by_the_closed_form_and_holds_its_weight() {
    let (young, density, kg) = (1e6f32, 100.0f32, 10.0f32);
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let (nodes, body, bottom) = bar(young, density);
    let b = rigid_box(&mut w, Vec3::new(0.0, -0.05, 0.0), kg);
    let soft = w
        .spawn((
            nodes,
            body,
            ImplicitEuler::default(),
            NodeAttachments::new(b, bottom.iter().copied()).unwrap(),
        ))
        .id();
    let mut lowest = 0.0f32;
    for _ in 0..600 {
        w.step_physics();
        lowest = lowest.min(w.get::<Position>(b).unwrap().0.y);
    }
    assert!(w.get::<Quarantined>(soft).is_none());
    let (area, g) = (0.01f32, 9.81f32);
    let expected = kg * g / (young * area) + density * g / (2.0 * young);
    let drop = -0.05 - w.get::<Position>(b).unwrap().0.y;
    let speed = w.get::<LinearVelocity>(b).unwrap().0.length();
    let force = w.get::<NodeAttachments>(soft).unwrap().force_on(b).unwrap();
    println!(
        "box drop {:.3} mm (closed form {:.3} mm), lowest {:.3} mm, speed {speed:.1e} m/s, force on the box {force}",
        1e3 * drop,
        1e3 * expected,
        -1e3 * (lowest + 0.05)
    );
    let n = w.get::<Nodes>(soft).unwrap();
    let ends = bottom.iter().map(|&i| n.positions()[i].y).sum::<f32>() / bottom.len() as f32;
    println!("bar end at {:.3} mm", 1e3 * ends);
    assert!((drop / expected - 1.0).abs() < 0.02, "{drop} vs {expected}");
    assert!(speed < 1e-3, "at rest: {speed}");
    // The bar holds the box up with its weight.
    assert!((force.y / (kg * g) - 1.0).abs() < 1e-2, "{force}");
    assert!(force.x.abs() < 1e-2 && force.z.abs() < 1e-2);
    // Bounded on the way: a static load's dynamic overshoot is at most twice the stretch.
    assert!(-(lowest + 0.05) < 2.2 * expected);
}

/// The same with explicit integration at enough substeps: the lumped-mass response couples
/// the same way, more softly.
#[test]
fn an_explicit_bar_holds_the_box_too() {
    let (young, density, kg) = (1e5f32, 100.0f32, 1.0f32);
    let mut w = scenes::world_with(
        1.0 / 60.0,
        20,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let (nodes, body, bottom) = bar(young, density);
    // Undamped otherwise: the box's own damping settles the oscillation.
    let b = rigid_box(&mut w, Vec3::new(0.0, -0.05, 0.0), kg);
    w.entity_mut(b).insert(hooke::particles::LinearDamping(2.0));
    let soft = w
        .spawn((
            nodes,
            body,
            NodeAttachments::new(b, bottom.iter().copied()).unwrap(),
        ))
        .id();
    for _ in 0..600 {
        w.step_physics();
    }
    assert!(w.get::<Quarantined>(soft).is_none());
    let expected = kg * 9.81 / (young * 0.01) + density * 9.81 / (2.0 * young);
    let drop = -0.05 - w.get::<Position>(b).unwrap().0.y;
    println!(
        "explicit: box drop {:.3} mm (closed form {:.3} mm)",
        1e3 * drop,
        1e3 * expected
    );
    assert!((drop / expected - 1.0).abs() < 0.05, "{drop} vs {expected}");
}

fn momenta(w: &mut World, soft: Entity, b: Entity) -> (Vec3, Vec3) {
    let n = w.get::<Nodes>(soft).unwrap();
    let (mut p, mut l) = (Vec3::ZERO, Vec3::ZERO);
    for i in 0..n.len() {
        let m = n.mass(i).unwrap();
        let (x, v) = (Vec3::from(n.positions()[i]), Vec3::from(n.velocities()[i]));
        p += m * v;
        l += m * x.cross(v);
    }
    let m = w.get::<Mass>(b).unwrap().value();
    let x = Vec3::from(w.get::<Position>(b).unwrap().0);
    let v = Vec3::from(w.get::<LinearVelocity>(b).unwrap().0);
    p += m * v;
    l += m * x.cross(v) + Vec3::from(w.get::<AngularMomentum>(b).unwrap().0);
    (p, l)
}

/// A free soft cube and the box holding one of its faces, thrown spinning in zero gravity:
/// their total linear momentum stays put. The angular momentum's drift is first order in
/// the substep (the impulses act after the positions moved), so it shrinks fourfold with
/// four substeps.
#[test]
fn momentum_passes_exactly_between_a_free_soft_body_and_its_rigid_body() {
    let run = |implicit: bool, substeps: u32| {
        let mut w = scenes::world_with(
            1.0 / 60.0,
            substeps,
            Integrator::SymplecticEuler,
            Vec3::ZERO,
        )
        .unwrap();
        w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
        let mesh = TetMesh::cuboid(Vec3::splat(0.2), [2, 2, 2], CellSplit::Five).unwrap();
        let material = Material::new(if implicit { 1e6 } else { 2e3 }, 0.3, 500.0).unwrap();
        let (nodes, body) =
            SoftBody::build(&mesh, Vec3::ZERO, material, StrainModel::Corotated).unwrap();
        let face: Vec<usize> = (0..nodes.len())
            .filter(|&i| nodes.positions()[i].x > 0.1 - 1e-4)
            .collect();
        let b = rigid_box(&mut w, Vec3::new(0.15, 0.0, 0.0), 2.0);
        w.entity_mut(b).insert((
            LinearVelocity::from(Vec3::new(0.5, 1.0, -0.3)),
            hooke::rigid::AngularVelocity::from(Vec3::new(0.0, 0.0, 2.0)),
        ));
        let mut e = w.spawn((nodes, body, NodeAttachments::new(b, face).unwrap()));
        if implicit {
            e.insert(ImplicitEuler::default());
        }
        let soft = e.id();
        // The first step sets L from ω; measure from then on.
        w.step_physics();
        let (p0, l0) = momenta(&mut w, soft, b);
        for _ in 0..120 {
            w.step_physics();
        }
        let (p1, l1) = momenta(&mut w, soft, b);
        assert!(w.get::<Quarantined>(soft).is_none());
        // It moved as one: the box and the soft body's centre travelled together.
        let n = w.get::<Nodes>(soft).unwrap();
        let centre = n.positions().iter().map(|p| Vec3::from(*p)).sum::<Vec3>() / n.len() as f32;
        let gap = Vec3::from(w.get::<Position>(b).unwrap().0) - centre;
        assert!(gap.length() < 0.3, "held together: {gap}");
        let dp = (p1 - p0).length() / p0.length();
        let dl = (l1 - l0).length() / l0.length();
        println!("implicit {implicit}, {substeps} substeps: |ΔP|/|P| {dp:.1e}, |ΔL|/|L| {dl:.1e}");
        assert!(dp < 2e-5, "P: {p0} -> {p1}");
        dl
    };
    // Backward Euler itself does not keep L either (m(v₁ − v₀) = h f(x₁) leaves
    // L₁ − L₀ = h Σ m v₁ × v₀: its numerical damping of the spin and wobble).
    assert!(run(true, 1) < 0.1);
    let (coarse, fine) = (run(false, 1), run(false, 4));
    assert!(coarse < 0.04, "{coarse}");
    assert!(fine < coarse / 3.0, "first order: {coarse} -> {fine}");
}

#[test]
fn a_kinematic_body_carries_its_nodes_and_a_despawned_one_lets_go() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let (nodes, body, _) = bar(1e6, 100.0);
    let mut nodes = nodes;
    // Unpin the top; hang the bar from a kinematic hand instead.
    let top: Vec<usize> = (0..nodes.len())
        .filter(|&i| nodes.positions()[i].y > 1.0 - 1e-4)
        .collect();
    let offsets: Vec<Vec3> = top
        .iter()
        .map(|&i| Vec3::from(nodes.positions()[i]) - Vec3::new(0.0, 1.05, 0.0))
        .collect();
    for &i in &top {
        nodes.set_mass(i, 0.05).unwrap();
    }
    let hand = w
        .spawn((
            RigidBody::Kinematic,
            Position::from(Vec3::new(0.0, 1.05, 0.0)),
            LinearVelocity::from(Vec3::new(1.0, 0.0, 0.0)),
            hooke::rigid::Rotation(Quat::IDENTITY),
        ))
        .id();
    let soft = w
        .spawn((
            nodes,
            body,
            ImplicitEuler::default(),
            NodeAttachments::new(hand, top.iter().copied()).unwrap(),
        ))
        .id();
    for _ in 0..60 {
        w.step_physics();
    }
    let hand_x = w.get::<Position>(hand).unwrap().0;
    let n = w.get::<Nodes>(soft).unwrap();
    for (&i, offset) in top.iter().zip(&offsets) {
        // Carried 1 m along x with the hand, each at its place on it.
        let p = Vec3::from(n.positions()[i]);
        let gap = p - (Vec3::from(hand_x) + *offset);
        assert!(gap.length() < 1e-3, "node {i}: {gap}");
    }
    assert!((hand_x.x - 1.0).abs() < 1e-4);
    w.entity_mut(hand).despawn();
    let before = w.get::<Nodes>(soft).unwrap().positions()[top[0]].y;
    for _ in 0..30 {
        w.step_physics();
    }
    let after = w.get::<Nodes>(soft).unwrap().positions()[top[0]].y;
    assert!(
        after < before - 0.5,
        "falls once let go: {before} -> {after}"
    );
    assert!(w.get::<Quarantined>(soft).is_none());
}

#[test]
fn bad_attachments_are_typed_errors() {
    let mut w = world(Vec3::ZERO);
    let b = w.spawn_empty().id();
    assert!(matches!(
        NodeAttachments::new(b, []),
        Err(hooke::Error::TooFew { .. })
    ));
    assert!(matches!(
        NodeAttachments::new(b, 0..129),
        Err(hooke::Error::OutOfRange { .. })
    ));
    let mut a = NodeAttachments::new(b, [3, 1, 3]).unwrap();
    assert_eq!(a.bodies().count(), 1);
    assert_eq!(a.force_on(b), None, "not run yet");
    a.detach(b);
    assert_eq!(a.bodies().count(), 0);
}
