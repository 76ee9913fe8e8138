//! A flag in the wind and a cloth draped over a sphere, as an animated GIF.
//!
//! ```text
//! cargo run --release --example cloth -- [--seconds 4] [--out out/cloth.gif]
//! ```
//!
//! Both cloths are `Nodes` + `SpringNetwork` + `Cloth`, integrated by backward Euler
//! (`ImplicitEuler`) at 60 Hz with one substep. Left, seen from above: a 1 m flag on a pole
//! at the origin, in an 8 m/s wind along +z (a `VelocityField`), drag on its triangles.
//! Right, from the side: a 1.2 m cloth dropped on a static sphere, colliding through the node
//! contacts, coming to rest draped.

mod common;
use common::{legend, register_fonts};

use std::path::PathBuf;
use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::cloth::Cloth;
use hooke::cloth::ClothBuilder;
use hooke::cloth::ClothMaterial;
use hooke::integrator::ImplicitEuler;
use hooke::particles::VelocityField;
use hooke::prelude::*;
use hooke::tools::scenes;
use plotters::prelude::*;

fn options() -> Result<(f32, PathBuf), String> {
    let (mut seconds, mut out) = (4.0f32, PathBuf::from("out/cloth.gif"));
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--seconds" => seconds = value.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--out" => out = PathBuf::from(value),
            other => return Err(format!("unknown flag {other}")),
        }
    }
    Ok((seconds, out))
}

/// A flag of `nx` × `ny` nodes `s` apart in the x–y plane, its x = 0 edge pinned.
fn flag(w: &mut World) -> Result<Entity, hooke::Error> {
    let (nx, ny, s) = (20usize, 12usize, 0.05f32);
    let mut x = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            x.push(Vec3::new(i as f32 * s, 2.0 - j as f32 * s, 0.0));
        }
    }
    let id = |i: usize, j: usize| j * nx + i;
    let mut tris = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            tris.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            tris.push([id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)]);
        }
    }
    let (mut nodes, net, cloth) = Cloth::from_triangles(&x, &tris, ClothMaterial::default())?;
    for j in 0..ny {
        nodes.pin(id(0, j))?;
    }
    let cloth = cloth.with_drag(1.0)?;
    Ok(w.spawn((nodes, net, cloth, ImplicitEuler::default())).id())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (seconds, out) = options()?;
    register_fonts()?;
    let g = Vec3::new(0.0, -9.81, 0.0);
    let mut windy = scenes::world_with(1.0 / 60.0, 1, Integrator::SymplecticEuler, g)?;
    windy.spawn(VelocityField::uniform(Vec3::new(0.0, 0.0, 8.0))?);
    let flag = flag(&mut windy)?;

    let mut drape = scenes::world_with(1.0 / 60.0, 1, Integrator::SymplecticEuler, g)?;
    drape.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let radius = 0.5;
    drape.spawn((
        RigidBodyBundle::fixed(Vec3::new(0.0, radius, 0.0), Quat::IDENTITY)?,
        Collider::ball(radius)?,
    ));
    let (nodes, net, cloth) = ClothBuilder::new(Vec3::new(-0.6, 1.1, -0.6), 25, 25, 0.05)
        .pin_corners(false)
        .stiffness(400.0, 100.0, 2.0)
        .build_cloth()?;
    let sheet = drape
        .spawn((nodes, net, cloth, ImplicitEuler::default()))
        .id();

    std::fs::create_dir_all(out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&out, (960, 440), 50)?.into_drawing_area();
    let steps = (seconds * 60.0).round() as usize;
    let mut ms = [0.0f64; 2];
    for step in 0..=steps {
        if step > 0 {
            for (k, w) in [&mut windy, &mut drape].into_iter().enumerate() {
                let t0 = Instant::now();
                w.step_physics();
                ms[k] += t0.elapsed().as_secs_f64() * 1e3;
            }
        }
        if step % 3 != 0 {
            continue;
        }
        root.fill(&WHITE)?;
        let t = step as f32 / 60.0;
        let (left, right) = root.split_horizontally(480);
        let title = |name: &str| format!("hooke cloth: {name}, t = {t:.2} s");
        let blue = RGBColor(40, 90, 200);
        let red = RGBColor(200, 60, 40);

        // The flag from above: x along the flag, z downwind.
        let mut chart = panel(
            &left,
            title("flag in an 8 m/s wind (top view)"),
            (-0.2..1.2, -0.3..1.1),
            ("x (m)", "z, downwind (m)"),
        )?;
        draw_cloth(&mut chart, &windy, flag, blue, "flag edges", |p| (p.x, p.z))?;
        chart
            .draw_series([Circle::new((0.0f32, 0.0f32), 5, BLACK.filled())])?
            .label("pole (pinned edge)")
            .legend(|(x, y)| Circle::new((x + 9, y), 4, BLACK.filled()));
        chart
            .draw_series([PathElement::new(
                [(0.8f32, -0.2f32), (0.8, 0.05)],
                RGBColor(0, 150, 0).stroke_width(3),
            )])?
            .label("wind, 8 m/s along +z")
            .legend(|(x, y)| {
                PathElement::new([(x, y), (x + 18, y)], RGBColor(0, 150, 0).stroke_width(3))
            });
        legend(&mut chart)?;

        // The drape from the side.
        let mut chart = panel(
            &right,
            title("draped over a sphere (side view)"),
            (-0.9..0.9, -0.05..1.25),
            ("x (m)", "height y (m)"),
        )?;
        let circle = (0..=64).map(|k| {
            let a = k as f32 / 64.0 * std::f32::consts::TAU;
            (radius * a.cos(), radius + radius * a.sin())
        });
        chart
            .draw_series(LineSeries::new(circle, BLACK.stroke_width(2)))?
            .label("static sphere, r = 0.5 m")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(2)));
        draw_cloth(&mut chart, &drape, sheet, red, "cloth edges", |p| {
            (p.x, p.y)
        })?;
        legend(&mut chart)?;
        root.present()?;
    }
    let per = |k: usize| ms[k] / steps.max(1) as f64;
    println!(
        "wrote {} ({} frames); backward Euler, 1 substep: flag {:.2} ms, drape {:.2} ms per 60 Hz step",
        out.display(),
        steps / 3 + 1,
        per(0),
        per(1)
    );
    Ok(())
}

/// A titled panel with labelled axes over `range` (m).
fn panel<'a, 'b: 'a>(
    area: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    title: String,
    range: (std::ops::Range<f32>, std::ops::Range<f32>),
    axes: (&str, &str),
) -> Result<Chart<'a, 'b>, Box<dyn std::error::Error>> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(34)
        .y_label_area_size(44)
        .build_cartesian_2d(range.0, range.1)?;
    chart
        .configure_mesh()
        .x_desc(axes.0)
        .y_desc(axes.1)
        .label_style(("sans-serif", 12))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    Ok(chart)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf32, plotters::coord::types::RangedCoordf32>,
>;

fn draw_cloth<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    w: &World,
    e: Entity,
    color: RGBColor,
    name: &str,
    view: impl Fn(glam::Vec3A) -> (f32, f32),
) -> Result<(), Box<dyn std::error::Error>> {
    let (nodes, cloth) = (
        w.get::<Nodes>(e).ok_or("cloth gone")?,
        w.get::<Cloth>(e).ok_or("cloth gone")?,
    );
    let p = |i: u32| view(nodes.positions()[i as usize]);
    let edges = cloth.triangles().iter().flat_map(|t| {
        [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
            .map(|(a, b)| PathElement::new([p(a), p(b)], color.stroke_width(1)))
    });
    chart
        .draw_series(edges)?
        .label(name.to_string())
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2)));
    Ok(())
}
