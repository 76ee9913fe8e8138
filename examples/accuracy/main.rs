//! What accuracy costs in time: every integrator × substeps (and, for the FEM cantilever,
//! every strain model × mesh) on problems with known answers, each setting's error against
//! the closed form (or a converged reference, said so) beside its time per step, in one run.
//!
//! ```sh
//! cargo run --release --example accuracy            # a few minutes
//! cargo run --release --example accuracy -- --quick # under a minute
//! ```
//!
//! Writes `out/accuracy.png`, `out/accuracy.svg` and `out/accuracy.md`, and prints the table.

#[path = "../common/mod.rs"]
mod common;
use common::register_fonts;

mod chart;
mod fem;
mod joints;
mod problems;

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::accuracy::{Reference, Setting, Sweep, order, sweep};
use plotters::prelude::*;
use problems::Problem;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let quick = std::env::args().any(|a| a == "--quick");
    let start = Instant::now();
    type Build = fn(bool) -> hooke::Result<Problem>;
    let all: [(&str, Build); 17] = [
        ("oscillator", problems::oscillator),
        ("damped", problems::damped_oscillator),
        ("pendulum", problems::pendulum),
        ("kepler", problems::kepler),
        ("kepler-energy", problems::kepler_energy),
        ("torque-free", problems::torque_free),
        ("orientation", problems::orientation_updates),
        ("chain", problems::stiff_chain),
        ("catenary", problems::catenary),
        ("bounce", problems::bouncing_ball),
        ("incline", problems::incline),
        ("fem", fem::cantilever),
        ("beam", fem::swinging_beam),
        ("cloth", problems::cloth),
        ("soft-bar", problems::soft_bar),
        ("hinged-rod", joints::hinged_rod),
        ("chain-gap", joints::chain_gap),
    ];
    let mut done = Vec::new();
    for (i, (name, build)) in all.iter().enumerate() {
        let t = Instant::now();
        done.push(build(quick)?);
        eprintln!(
            "[{}/{}] {name}: {:.1} s",
            i + 1,
            all.len(),
            t.elapsed().as_secs_f32()
        );
    }
    let md = table(&done) + &orders()?;
    println!("{md}");
    std::fs::create_dir_all("out")?;
    std::fs::write("out/accuracy.md", &md)?;
    register_fonts()?;
    let size = (1920, 1950);
    chart::draw(
        &BitMapBackend::new(Path::new("out/accuracy.png"), size).into_drawing_area(),
        &done,
    )?;
    chart::draw(
        &SVGBackend::new(Path::new("out/accuracy.svg"), size).into_drawing_area(),
        &done,
    )?;
    eprintln!(
        "wrote out/accuracy.png, out/accuracy.svg and out/accuracy.md in {:.0} s",
        start.elapsed().as_secs_f32()
    );
    Ok(())
}

fn percent(x: f64) -> String {
    if !x.is_finite() {
        "diverged".into()
    } else if x < 1e-4 {
        format!("{:.1e} %", 100.0 * x)
    } else {
        format!("{:.3} %", 100.0 * x)
    }
}

/// Per problem: the cheapest setting within 1 %, 0.1 % and 0.01 %, and the default's error.
fn table(problems: &[Problem]) -> String {
    let mut s = String::new();
    s.push_str("| problem | error measured | reference | cheapest within 1 % | within 0.1 % | within 0.01 % | default (symplectic ×4, automatic rescue past the limit) |\n");
    s.push_str("|---|---|---|---|---|---|---|\n");
    for p in problems {
        let pick = |tol: f64| match p.cheapest_within(tol) {
            Some(i) => {
                let m = &p.report.measurements[i];
                let (series, label) = p.naming(i);
                format!(
                    "{series} {label}: {} in {:.1} µs",
                    percent(p.relative(m)),
                    m.seconds_per_step * 1e6
                )
            }
            None => "none swept".into(),
        };
        let default = if p.names.is_some() {
            p.default.map(|i| &p.report.measurements[i])
        } else {
            p.report.get(Setting::DEFAULT)
        };
        let default = default.map_or("— (a static solve: no such setting)".into(), |m| {
            format!(
                "{} in {:.1} µs",
                percent(p.relative(m)),
                m.seconds_per_step * 1e6
            )
        });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            p.name,
            p.measure.replace('|', "\\|"),
            p.reference,
            pick(1e-2),
            pick(1e-3),
            pick(1e-4),
            default
        );
    }
    s.push_str("\nEvery setting, relative error and µs per step:\n\n");
    for p in problems {
        let _ = writeln!(s, "- **{}**:", p.name);
        let row: Vec<String> = (0..p.report.measurements.len())
            .map(|i| {
                let m = &p.report.measurements[i];
                let (series, label) = p.naming(i);
                format!(
                    "{series} {label} {} / {:.1} µs",
                    percent(p.relative(m)),
                    m.seconds_per_step * 1e6
                )
            })
            .collect();
        let _ = writeln!(s, "  {}", row.join("; "));
    }
    s
}

/// The orders of convergence on the unit oscillator, measured at a coarse step (0.1 s) and a
/// horizon (1.3 s) away from whole periods, from the finest pair of substep counts whose
/// errors are both between 1e-4 (above the f32 floor) and 0.1 (asymptotic).
fn orders() -> hooke::Result<String> {
    #[derive(Component)]
    struct Bob;
    let build = |w: &mut World| -> hooke::Result<()> {
        w.insert_resource(Gravity::new(Vec3::ZERO)?);
        let tau = std::f32::consts::TAU;
        let b = hooke::tools::scenes::oscillator(w, 1.0, tau * tau, 0.0, 1.0)?;
        w.entity_mut(b).insert(Bob);
        Ok(())
    };
    let x = |w: &mut World| {
        let mut q = w.query_filtered::<&Position, With<Bob>>();
        q.iter(w).map(|p| p.get().x).collect()
    };
    let substeps = [1, 2, 4, 8, 16, 32, 64];
    let report = sweep(
        build,
        x,
        &Setting::grid(&Integrator::ALL, &substeps),
        Reference::exact(|t| vec![(std::f64::consts::TAU * t).cos()]),
        Sweep::steps(0.1, 13).with_timing_runs(1),
    )?;
    let mut s = String::from(
        "\nMeasured orders (unit oscillator, dt = 0.1 s, 1.3 s: away from whole periods):\n\n| integrator | expected | measured | between |\n|---|---|---|---|\n",
    );
    for integrator in Integrator::ALL {
        let errors: Vec<(u32, f64)> = substeps
            .iter()
            .filter_map(|&n| Some((n, report.get(Setting::new(integrator, n))?.error)))
            .collect();
        let pair = errors
            .windows(2)
            .rev()
            .find(|w| w.iter().all(|&(_, e)| (1e-4..0.1).contains(&e)));
        let (measured, between) = pair.map_or(("—".into(), "no pair in range".into()), |w| {
            (
                format!("{:.2}", order(w[0], w[1])),
                format!(
                    "×{} and ×{} ({:.1e} → {:.1e})",
                    w[0].0, w[1].0, w[0].1, w[1].1
                ),
            )
        });
        let _ = writeln!(
            s,
            "| {} | {} | {measured} | {between} |",
            integrator.name(),
            integrator.order()
        );
    }
    Ok(s)
}
