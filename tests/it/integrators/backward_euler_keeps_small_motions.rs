//! A 1 mm axial vibration of a soft bar 8 m from the origin, solved by backward Euler at 1 to
//! 32 substeps. Its displacement per substep is a few ulps of an f32 position there, so a
//! velocity differenced from f32 positions, (x₁ − x₀)/h, resolves only ulp(x)/h and the
//! nodes stick near their turning points: the frequency read half at 32 substeps. The solve
//! carries the displacement in f64 and keeps what rounding drops, so the frequency holds.

use glam::Vec3;
use hooke::integrator::{ImplicitEuler, ImplicitScheme};
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

const LENGTH: f32 = 1.0;
const START: f32 = 8.0;
const CELLS: usize = 10;
const AMPLITUDE: f32 = 1e-3;

/// E = 1e4 Pa, ρ = 1000 kg/m³, ν = 0: c = √(E/ρ) = 3.16 m/s; a fixed–free bar's first axial
/// mode ω = (π/2) c / L = 4.97 rad/s, and the lumped chain of 10 cells
/// (4 c / Δx) sin(π / 40) … (2c/Δx) sin(π/(4n)), 0.2% below.
fn closed_form() -> f64 {
    let c = (1e4f64 / 1000.0).sqrt();
    let dx = f64::from(LENGTH) / CELLS as f64;
    2.0 * c / dx * (std::f64::consts::PI / (4.0 * CELLS as f64)).sin()
}

/// The tip's upward zero crossings' mean spacing gives ω (rad/s); also the last amplitude.
fn vibrate(substeps: u32, scheme: ImplicitScheme) -> (f64, f32) {
    let mut w = scenes::world_with(
        1.0 / 60.0,
        substeps,
        Integrator::SymplecticEuler,
        Vec3::ZERO,
    )
    .unwrap();
    let mesh = TetMesh::cuboid(Vec3::new(LENGTH, 0.1, 0.1), [CELLS, 1, 1], CellSplit::Six).unwrap();
    let material = Material::new(1e4, 0.0, 1000.0).unwrap();
    let (mut nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(START + 0.5 * LENGTH, 0.0, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let omega = closed_form() as f32;
    let mut tip = Vec::new();
    for i in 0..nodes.len() {
        let x = nodes.positions()[i].x;
        if (x - START).abs() < 1e-4 {
            nodes.pin(i).unwrap();
        } else {
            // The first mode's shape, sin(π s / 2L), moving at its peak speed.
            let s = (x - START) / LENGTH;
            let v = omega * AMPLITUDE * (std::f32::consts::FRAC_PI_2 * s).sin();
            nodes.set_velocity(i, Vec3::new(v, 0.0, 0.0)).unwrap();
        }
        if (x - START - LENGTH).abs() < 1e-4 {
            tip.push(i);
        }
    }
    let rest = START + LENGTH;
    let settings = ImplicitEuler {
        scheme,
        ..ImplicitEuler::default()
    };
    let e = w.spawn((nodes, body, settings)).id();
    let (mut crossings, mut last, mut t) = (Vec::new(), 0.0f32, 0.0f64);
    let mut peak = 0.0f32;
    for step in 0..300 {
        w.step_physics();
        t += 1.0 / 60.0;
        let n = w.get::<Nodes>(e).unwrap();
        let u = tip.iter().map(|&i| n.positions()[i].x - rest).sum::<f32>() / tip.len() as f32;
        if last < 0.0 && u >= 0.0 {
            crossings.push(t - 1.0 / 60.0 * f64::from(u / (u - last)));
        }
        if step >= 240 {
            peak = peak.max(u.abs());
        }
        last = u;
    }
    assert!(w.get::<Quarantined>(e).is_none());
    assert!(crossings.len() >= 3, "{substeps}: {crossings:?}");
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    (std::f64::consts::TAU / period, peak)
}

#[test]
fn a_small_vibration_keeps_its_frequency_at_every_substep_count() {
    let exact = closed_form();
    for scheme in [ImplicitScheme::BackwardEuler, ImplicitScheme::Bdf2] {
        for substeps in [1, 4, 16, 32] {
            let (omega, amplitude) = vibrate(substeps, scheme);
            println!(
                "{:>14} ×{substeps:<2}: ω {omega:.4} rad/s ({:+.2}% of {exact:.4}), amplitude in the 5th second {:.3} mm",
                scheme.name(),
                100.0 * (omega / exact - 1.0),
                amplitude * 1e3
            );
            assert!(
                (omega / exact - 1.0).abs() < 0.01,
                "{scheme:?} ×{substeps}: {omega}"
            );
            // Backward Euler damps by 1/(1 + ω²h²) in energy per substep: at least 40% of
            // the amplitude is left after 5 s at one substep; BDF2 keeps nearly all of it.
            let kept = if scheme == ImplicitScheme::Bdf2 {
                0.95
            } else {
                0.35
            };
            assert!(
                amplitude > kept * AMPLITUDE,
                "{scheme:?} ×{substeps}: {amplitude}"
            );
        }
    }
}
