//! The FEM cantilever: strain model × mesh against beam theory, each a static solve.

use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::soft::{Material, StrainModel};
use hooke::tools::accuracy::{Measurement, Setting, SweepReport, world_for};

use crate::problems::Problem;

/// Tip deflection (m) of a 1 m × 0.1 m × 0.1 m cantilever (E = 1e8 Pa, ν = 0) under a 10 N tip
/// load, from one backward-Euler step of 100 s (M/h² vanishes beside K: a static solve), and
/// the solve's time (s).
fn deflection(cells: [usize; 3], model: StrainModel) -> hooke::Result<(f64, f64)> {
    let mut w = world_for(Setting::new(Integrator::SymplecticEuler, 1), 100.0)?;
    w.insert_resource(Gravity::new(Vec3::ZERO)?);
    let settings = ImplicitEuler {
        tolerance: 1e-6,
        max_newton: 20,
        max_cg: 5000,
        ..ImplicitEuler::default()
    };
    let beam = hooke::tools::scenes::Cantilever::spawn(&mut w, cells, model, settings)?;
    let t0 = Instant::now();
    w.step_physics();
    let spent = t0.elapsed().as_secs_f64();
    if w.get::<Quarantined>(beam.body).is_some() {
        return Ok((f64::NAN, spent));
    }
    Ok((beam.deflection(&w).map_or(f64::NAN, f64::from), spent))
}

pub fn cantilever(quick: bool) -> hooke::Result<Problem> {
    // F L³ / (3 E I) with I = a⁴/12.
    let closed = 10.0 * 1.0 / (3.0 * 1e8 * 0.1f64.powi(4) / 12.0);
    let meshes: &[[usize; 3]] = if quick {
        &[[10, 1, 1], [20, 2, 2]]
    } else {
        &[[10, 1, 1], [20, 2, 2], [40, 4, 4]]
    };
    let models = [
        StrainModel::Green,
        StrainModel::Cauchy,
        StrainModel::Corotated,
        StrainModel::StableNeoHookean,
    ];
    let (mut measurements, mut names) = (Vec::new(), Vec::new());
    for model in models {
        for &cells in meshes {
            let mut times = Vec::new();
            let mut tip = 0.0;
            for _ in 0..if quick { 1 } else { 3 } {
                let (d, t) = deflection(cells, model)?;
                tip = d;
                times.push(t);
            }
            times.sort_by(f64::total_cmp);
            let error = (tip - closed).abs();
            measurements.push(Measurement {
                setting: Setting::new(Integrator::ImplicitEuler, 1),
                error: if error.is_finite() {
                    error
                } else {
                    f64::INFINITY
                },
                seconds_per_step: times[times.len() / 2],
                quarantined: false,
            });
            names.push((
                format!("{model:?}"),
                format!("{}×{}×{}", cells[0], cells[1], cells[2]),
            ));
        }
    }
    let mut p = Problem::new(
        "FEM cantilever, static tip load (E = 1e8)",
        "|tip deflection − F L³/(3EI)| per 4.000 mm; time of the static solve",
        "closed form (Euler–Bernoulli); linear tets lock, so error falls with the mesh",
        closed,
        SweepReport {
            measurements,
            reference_seconds_per_step: None,
        },
    );
    p.names = Some(names);
    Ok(p)
}

/// A soft beam (co-rotated, E = 1e5 Pa, ν = 0.3, 1 m × 0.2 m × 0.2 m, 5 × 1 × 1 cells) pinned
/// at one end and released level under gravity: its free end's path over 1.5 s against the
/// same beam at RK4 ×64.
pub fn swinging_beam(quick: bool) -> hooke::Result<Problem> {
    /// The free end's node indices.
    #[derive(Component)]
    struct Beam(Vec<usize>);
    let build = |w: &mut World| -> hooke::Result<()> {
        w.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0))?);
        w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
        let material = Material::new(1e5, 0.3, 1000.0)?;
        let (nodes, body) = hooke::tools::scenes::pinned_beam(
            1.0,
            0.2,
            [5, 1, 1],
            material,
            StrainModel::Corotated,
        )?;
        let tip = (0..nodes.len())
            .filter(|&i| (nodes.positions()[i].x - 1.0).abs() < 1e-5)
            .collect();
        w.spawn((nodes, body, Beam(tip)));
        Ok(())
    };
    let tip = |w: &mut World| -> Vec<f32> {
        let mut q = w.query::<(&Nodes, &Beam)>();
        q.iter(w)
            .flat_map(|(n, beam)| {
                beam.0
                    .iter()
                    .flat_map(|&i| n.positions()[i].to_array())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let report = hooke::tools::accuracy::sweep(
        build,
        tip,
        &crate::problems::settings(),
        hooke::tools::accuracy::Reference::Converged(Setting::new(Integrator::Rk4, 64)),
        hooke::tools::accuracy::Sweep::seconds(1.5).with_timing_runs(if quick { 1 } else { 7 }),
    )?;
    Ok(Problem::new(
        "FEM beam swinging (co-rotated, E = 1e5)",
        "max error of the free end's nodes over 1.5 s, per 1 m length",
        "the same beam at RK4 ×64 (converged)",
        1.0,
        report,
    ))
}
