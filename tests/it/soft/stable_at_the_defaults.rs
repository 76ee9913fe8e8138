//! Soft bodies at the defaults (`PhysicsPlugins` and nothing else): each knows its explicit
//! limit, and one past it is stepped on its own a few times per substep or, stiffer, solved
//! by BDF2, and told once, instead of being quarantined in its first steps (a 1 m beam at
//! E = 1e5 or 1e8 was, at the default 4 substeps).

use crate::common;

use glam::Vec3;
use hooke::integrator::{ImplicitEuler, ImplicitScheme, LocalSubsteps, Rescue};
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, SoftStability, StrainModel, TetMesh};

/// A bar of `length` hanging from pins at y = 0 (ν = 0, so its stretch is one-dimensional):
/// its elongation under its own weight is ρ g L² / (2E).
fn hanging_bar(young: f32) -> (f32, f32, Option<Rescue>, bool) {
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
    let scheme = match (w.get::<LocalSubsteps>(e), w.get::<ImplicitEuler>(e)) {
        (Some(l), _) => Some(Rescue::LocalSubsteps(l.count())),
        (None, Some(s)) => Some(Rescue::Implicit(s.scheme)),
        (None, None) => None,
    };
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
            scheme.map_or("explicit".to_string(), |s| format!("{s:?}")),
            100.0 * (stretch / closed - 1.0)
        );
        assert!(!quarantined, "E = {young}");
        // Within the default substep (1/240 s), explicit; past it, stepped on its own while
        // 12 local substeps suffice, solved by BDF2 beyond.
        let needed = hooke::integrator::stability::substeps_needed(1.0 / 240.0, h_crit);
        let expected = if 1.0 / 240.0 <= h_crit {
            None
        } else if needed <= hooke::soft::stability::LOCAL_SUBSTEPS_CHEAPER_UP_TO {
            Some(Rescue::LocalSubsteps(needed.max(2)))
        } else {
            Some(Rescue::Implicit(ImplicitScheme::Bdf2))
        };
        assert_eq!(scheme, expected, "E = {young}");
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

/// A 1 m cantilever, 0.1 m square (E = 1e8 Pa, ν = 0.3, ρ = 1000 kg/m³, 20×2×2 cells),
/// released straight under gravity: it swings about its sag in its first bending mode. Its
/// frequency and sag as `substeps` at 60 Hz give them (None: the defaults, where the policy
/// rescues it by BDF2; Some(n): explicit at n substeps).
fn cantilever(substeps: Option<u32>) -> (f64, f64, Option<ImplicitScheme>) {
    cantilever_nu(substeps, [20, 2, 2], 0.3)
}

/// The same cantilever meshed with `cells` and Poisson ratio `nu`.
fn cantilever_nu(
    substeps: Option<u32>,
    cells: [usize; 3],
    nu: f32,
) -> (f64, f64, Option<ImplicitScheme>) {
    let mut w = common::default_world();
    if let Some(n) = substeps {
        w.insert_resource(hooke::integrator::StabilityPolicy::Warn);
        w.insert_resource(hooke::core::time::PhysicsTime::new(1.0 / 60.0, n).unwrap());
    }
    let mesh = TetMesh::cuboid(Vec3::new(1.0, 0.1, 0.1), cells, CellSplit::Six).unwrap();
    let material = Material::new(1e8, nu, 1000.0).unwrap();
    let (mut nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.5, 0.0, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let mut tip = Vec::new();
    for k in 0..nodes.len() {
        let x = nodes.positions()[k].x;
        if x.abs() < 1e-5 {
            nodes.pin(k).unwrap();
        }
        if (x - 1.0).abs() < 1e-5 {
            tip.push(k);
        }
    }
    let e = w.spawn((nodes, body)).id();
    let mut ys = Vec::new();
    for _ in 0..120 {
        w.step_physics();
        let n = w.get::<Nodes>(e).unwrap();
        ys.push(f64::from(tip.iter().map(|&k| n.positions()[k].y).sum::<f32>()) / tip.len() as f64);
    }
    assert!(w.get::<Quarantined>(e).is_none(), "{substeps:?}");
    // Upward crossings of the mean, the mean taken over whole periods (refined once).
    let mut mean = ys.iter().sum::<f64>() / ys.len() as f64;
    let mut crossings = Vec::new();
    for _ in 0..2 {
        crossings.clear();
        for k in 1..ys.len() {
            let (a, b) = (ys[k - 1] - mean, ys[k] - mean);
            if a < 0.0 && b >= 0.0 {
                crossings.push((k as f64 - b / (b - a)) / 60.0);
            }
        }
        let (first, last) = (
            (crossings[0] * 60.0).ceil() as usize,
            (crossings[crossings.len() - 1] * 60.0).floor() as usize,
        );
        mean = ys[first..=last].iter().sum::<f64>() / (last - first + 1) as f64;
    }
    let count = crossings.len() - 1;
    let omega = std::f64::consts::TAU * count as f64 / (crossings[count] - crossings[0]);
    (omega, -mean, w.get::<ImplicitEuler>(e).map(|s| s.scheme))
}

#[test]
fn a_cantilever_keeps_its_first_mode_at_the_defaults() {
    // Euler–Bernoulli: ω₁ = 1.8751² √(EI / (ρ A L⁴)) = 32.1 rad/s. A 20×2×2 mesh of linear
    // tetrahedra locks (it is stiffer than the beam), so the rescue is measured against the
    // same mesh integrated explicitly at the substeps its limit asks for; the mesh's own
    // error against beam theory is printed (see `soft::implicit` for its convergence).
    let omega_eb = 1.8751f64.powi(2) * (1e8f64 * 1e-4 / 12.0 / (1000.0 * 0.01)).sqrt();
    let (omega, sag, scheme) = cantilever(None);
    let (reference, sag_ref, _) = cantilever(Some(300));
    println!(
        "cantilever: defaults ({scheme:?}) ω {omega:.3} rad/s, sag {:.3} mm; explicit ×300 ω {reference:.3}, sag {:.3} mm ({:+.2}%); beam theory ω₁ {omega_eb:.2} (the mesh {:+.1}%)",
        sag * 1e3,
        sag_ref * 1e3,
        100.0 * (omega / reference - 1.0),
        100.0 * (reference / omega_eb - 1.0)
    );
    assert_eq!(scheme, Some(ImplicitScheme::Bdf2));
    assert!(
        (omega / reference - 1.0).abs() < 0.02,
        "{omega} vs {reference}"
    );
    assert!((sag / sag_ref - 1.0).abs() < 0.02, "{sag} vs {sag_ref}");
}

#[test]
fn a_fine_cantilever_at_the_defaults_swings_within_5_percent_of_beam_theory() {
    // The same beam at 60×6×6 cells (12,960 tetrahedra) and ν = 0 (no Poisson locking): the
    // mesh converges on beam theory at first order (20×2×2 at ν = 0.3 is +28 %, 40×4×4 at
    // ν = 0 is +4.9 %, this +3.3 %), and the rescue (BDF2: it would need over a hundred
    // local substeps) keeps what the mesh has.
    let omega_eb = 1.8751f64.powi(2) * (1e8f64 * 1e-4 / 12.0 / (1000.0 * 0.01)).sqrt();
    let (omega, sag, scheme) = cantilever_nu(None, [60, 6, 6], 0.0);
    println!(
        "fine cantilever at the defaults ({scheme:?}): ω {omega:.3} rad/s vs Euler–Bernoulli {omega_eb:.2} ({:+.1}%), sag {:.2} mm",
        100.0 * (omega / omega_eb - 1.0),
        sag * 1e3
    );
    assert_eq!(scheme, Some(ImplicitScheme::Bdf2));
    assert!(
        (omega / omega_eb - 1.0).abs() < 0.05,
        "{omega} vs {omega_eb}"
    );
}
