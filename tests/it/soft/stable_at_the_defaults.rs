//! Soft bodies at the defaults (`PhysicsPlugins` and nothing else): each knows its explicit
//! limit, and one past it is solved by BDF2 and told once, instead of being quarantined in
//! its first steps (a 1 m beam at E = 1e5 or 1e8 was, at the default 4 substeps).

use crate::common;

use glam::Vec3;
use hooke::integrator::{ImplicitEuler, ImplicitScheme};
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, SoftStability, StrainModel, TetMesh};

/// A bar of `length` hanging from pins at y = 0 (ν = 0, so its stretch is one-dimensional):
/// its elongation under its own weight is ρ g L² / (2E).
fn hanging_bar(young: f32) -> (f32, f32, Option<ImplicitScheme>, bool) {
    let length = 1.0;
    let mut w = common::default_world();
    let mesh = TetMesh::cuboid(Vec3::new(0.1, length, 0.1), [2, 20, 2], CellSplit::Six).unwrap();
    // Mass damping α = 5/s settles it in a few seconds (the scheme itself hardly damps).
    let material = Material::new(young, 0.0, 1000.0)
        .unwrap()
        .with_damping(5.0, 0.0)
        .unwrap();
    let (mut nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.0, -0.5 * length, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let mut bottom = Vec::new();
    for i in 0..nodes.len() {
        let y = nodes.positions()[i].y;
        if y.abs() < 1e-5 {
            nodes.pin(i).unwrap();
        }
        if (y + length).abs() < 1e-5 {
            bottom.push(i);
        }
    }
    let e = w.spawn((nodes, body)).id();
    let h_crit = w.get::<SoftBody>(e).unwrap().critical_step();
    for _ in 0..480 {
        w.step_physics();
    }
    let quarantined = w.get::<Quarantined>(e).is_some();
    let n = w.get::<Nodes>(e).unwrap();
    let y = bottom.iter().map(|&i| n.positions()[i].y).sum::<f32>() / bottom.len() as f32;
    let scheme = w.get::<ImplicitEuler>(e).map(|s| s.scheme);
    assert_eq!(w.get::<SoftStability>(e).unwrap().critical_step, h_crit);
    (-y - length, h_crit, scheme, quarantined)
}

#[test]
fn a_hanging_bar_of_any_stiffness_stretches_by_the_closed_form_at_the_defaults() {
    for young in [1e4f32, 1e5, 1e6, 1e8] {
        let closed = 1000.0 * 9.81 * 1.0 / (2.0 * young);
        let (stretch, h_crit, scheme, quarantined) = hanging_bar(young);
        println!(
            "E = {young:.0e} Pa: limit {h_crit:.2e} s ({}), stretch {stretch:.4e} m vs ρgL²/2E = {closed:.4e} ({:+.2}%)",
            scheme.map_or("explicit".to_string(), |s| s.name().to_string()),
            100.0 * (stretch / closed - 1.0)
        );
        assert!(!quarantined, "E = {young}");
        // Past the default substep (1/240 s) it is rescued by BDF2; within it, explicit.
        let past = 1.0 / 240.0 > h_crit;
        assert_eq!(scheme, past.then_some(ImplicitScheme::Bdf2), "E = {young}");
        assert!(
            (stretch / closed - 1.0).abs() < 0.02,
            "E = {young}: {stretch} vs {closed}"
        );
    }
}

#[test]
fn the_limit_is_safe_an_explicit_body_just_inside_it_stays_bounded() {
    // The limit of the E = 1e5 bar, and that bar run explicitly at 0.95 of it, undamped.
    let mesh = TetMesh::cuboid(Vec3::new(0.1, 1.0, 0.1), [2, 20, 2], CellSplit::Six).unwrap();
    let material = Material::new(1e5, 0.3, 1000.0).unwrap();
    let (nodes, body) =
        SoftBody::build(&mesh, Vec3::ZERO, material, StrainModel::Corotated).unwrap();
    let h = body.critical_step();
    let substeps = ((1.0 / 60.0) / (0.95 * h)).ceil() as u32;
    let mut w = common::default_world();
    w.insert_resource(hooke::integrator::StabilityPolicy::Warn);
    w.insert_resource(hooke::core::time::PhysicsTime::new(1.0 / 60.0, substeps).unwrap());
    let e = w.spawn((nodes, body)).id();
    for _ in 0..120 {
        w.step_physics();
    }
    assert!(w.get::<ImplicitEuler>(e).is_none());
    assert!(w.get::<Quarantined>(e).is_none());
    assert_eq!(w.resource::<PhysicsDiagnostics>().stability_warnings, 0);
    println!("E = 1e5, ν = 0.3: limit {h:.3e} s; explicit at {substeps} substeps, 2 s bounded");
}
