//! A soft cube and a soft beam dropped on the ground, wobbling, as an animated GIF.
//!
//! ```text
//! cargo run --release --example jelly -- [--model corotated|green|cauchy|neohookean]
//!     [--integrator implicit|symplectic] [--seconds 3] [--out out/jelly.gif]
//! ```
//!
//! Side view (x, y); each frame draws the bodies' surface edges, with the step's elastic
//! energy and the integrator's cost in the title. Implicit runs at 60 Hz with one substep;
//! symplectic Euler needs 40 substeps for these materials (fewer diverge: the quarantine
//! catches it and the frame says so).

mod common;
use common::{legend, register_fonts};

use std::path::PathBuf;
use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;
use plotters::prelude::*;

struct Options {
    model: StrainModel,
    implicit: bool,
    seconds: f32,
    out: PathBuf,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        model: StrainModel::Corotated,
        implicit: true,
        seconds: 3.0,
        out: PathBuf::from("out/jelly.gif"),
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--model" => {
                o.model = match value.as_str() {
                    "corotated" => StrainModel::Corotated,
                    "green" => StrainModel::Green,
                    "cauchy" => StrainModel::Cauchy,
                    "neohookean" => StrainModel::StableNeoHookean,
                    other => return Err(format!("unknown model {other}")),
                }
            }
            "--integrator" => {
                o.implicit = match value.as_str() {
                    "implicit" => true,
                    "symplectic" => false,
                    other => return Err(format!("unknown integrator {other}")),
                }
            }
            "--seconds" => o.seconds = value.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--out" => o.out = PathBuf::from(value),
            other => return Err(format!("unknown flag {other}")),
        }
    }
    Ok(o)
}

/// A soft body of `mesh` at `at`, turned by `turn`, with its surface for drawing.
fn spawn(
    w: &mut World,
    mesh: &TetMesh,
    at: Vec3,
    turn: Quat,
    material: Material,
    o: &Options,
) -> Result<(Entity, Vec<[u32; 3]>), hooke::Error> {
    let (mut nodes, body) = SoftBody::build(mesh, Vec3::ZERO, material, o.model)?;
    for i in 0..nodes.len() {
        let p = turn * Vec3::from(nodes.positions()[i]) + at;
        nodes.set_position(i, p)?;
    }
    let mut e = w.spawn((nodes, body));
    if o.implicit {
        e.insert(ImplicitEuler::default());
    }
    Ok((e.id(), mesh.surface()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let o = options()?;
    register_fonts()?;
    let substeps = if o.implicit { 1 } else { 40 };
    let mut w = scenes::world_with(
        1.0 / 60.0,
        substeps,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )?;
    scenes::ground(&mut w)?;
    let cube_mesh = TetMesh::cuboid(Vec3::splat(0.4), [4, 4, 4], CellSplit::Six)?;
    let beam_mesh = TetMesh::cuboid(Vec3::new(1.2, 0.12, 0.12), [12, 2, 2], CellSplit::Six)?;
    let jelly = Material::new(2e5, 0.35, 1000.0)?;
    let rubber = Material::new(1e6, 0.3, 1100.0)?;
    let (cube, cube_surface) = spawn(
        &mut w,
        &cube_mesh,
        Vec3::new(-0.7, 0.8, 0.0),
        Quat::from_rotation_z(0.5),
        jelly,
        &o,
    )?;
    let (beam, beam_surface) = spawn(
        &mut w,
        &beam_mesh,
        Vec3::new(0.85, 0.6, 0.0),
        Quat::from_rotation_z(-0.3),
        rubber,
        &o,
    )?;
    std::fs::create_dir_all(o.out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&o.out, (720, 420), 50)?.into_drawing_area();
    let steps = (o.seconds * 60.0).round() as usize;
    let mut solve_ms = 0.0f64;
    let label = match o.model {
        StrainModel::Corotated => "co-rotated",
        StrainModel::Green => "Green (St. Venant–Kirchhoff)",
        StrainModel::Cauchy => "Cauchy (linear)",
        StrainModel::StableNeoHookean => "stable Neo-Hookean",
    };
    let scheme = if o.implicit {
        "backward Euler, 1 substep"
    } else {
        "symplectic Euler, 40 substeps"
    };
    for step in 0..=steps {
        if step > 0 {
            let t0 = Instant::now();
            w.step_physics();
            solve_ms += t0.elapsed().as_secs_f64() * 1e3;
        }
        if step % 3 != 0 {
            continue;
        }
        let energy: f64 = [cube, beam]
            .iter()
            .map(|&e| {
                w.get::<SoftBody>(e)
                    .map_or(0.0, |b| b.stats().elastic_energy)
            })
            .sum();
        let lost = [cube, beam]
            .iter()
            .any(|&e| w.get::<Quarantined>(e).is_some());
        root.fill(&WHITE)?;
        let title = format!(
            "hooke soft bodies: {label}, {scheme}; t = {:.2} s, elastic energy {energy:.1} J{}",
            step as f32 / 60.0,
            if lost {
                " — QUARANTINED (diverged)"
            } else {
                ""
            }
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 17))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d(-1.5f32..1.5f32, -0.05f32..1.2f32)?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("height y (m)")
            .label_style(("sans-serif", 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        chart
            .draw_series(LineSeries::new(
                [(-1.5f32, 0.0f32), (1.5, 0.0)],
                BLACK.stroke_width(2),
            ))?
            .label("ground (static collider)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(2)));
        for (e, surface, color, name) in [
            (
                cube,
                &cube_surface,
                RGBColor(200, 60, 40),
                "jelly cube, E = 2e5 Pa",
            ),
            (
                beam,
                &beam_surface,
                RGBColor(40, 90, 200),
                "rubber beam, E = 1e6 Pa",
            ),
        ] {
            let n = w.get::<Nodes>(e).ok_or("body gone")?;
            let p = |i: u32| {
                let v = n.positions()[i as usize];
                (v.x, v.y)
            };
            let edges = surface.iter().flat_map(|t| {
                [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
                    .map(|(a, b)| PathElement::new([p(a), p(b)], color.stroke_width(1)))
            });
            chart.draw_series(edges)?.label(name).legend(move |(x, y)| {
                PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2))
            });
        }
        legend(&mut chart)?;
        root.present()?;
    }
    println!(
        "wrote {} ({} frames); {label}, {scheme}: {:.2} ms per 60 Hz step",
        o.out.display(),
        steps / 3 + 1,
        solve_ms / steps.max(1) as f64
    );
    Ok(())
}
