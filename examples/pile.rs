//! Boxes and balls falling onto a ramp and the ground. Writes `out/pile.gif`, a side view
//! (x–y) of 5 s at 60 Hz, one frame every 4 steps, and its last frame as `out/pile.png`.
//!
//! ```text
//! cargo run --release --example pile
//! ```

mod common;

use bevy_ecs::prelude::*;
use common::{legend, register_fonts};
use hooke::collision::Contacts;
use hooke::prelude::*;
use hooke::rigid::Rotation;
use hooke::tools::scenes;
use plotters::coord::Shift;
use plotters::prelude::*;

const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (1, 3),
    (3, 2),
    (2, 0),
    (4, 5),
    (5, 7),
    (7, 6),
    (6, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// A box's eight corners, projected on the x–y plane.
fn corners(x: Vec3, q: glam::Quat, h: Vec3) -> Vec<(f32, f32)> {
    (0..8)
        .map(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            );
            let p = x + q * c;
            (p.x, p.y)
        })
        .collect()
}

/// One side view of the scene at simulated time `t` (s).
fn frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    world: &World,
    boxes: &[Entity],
    balls: &[Entity],
    t: f32,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&RGBColor(250, 250, 250))?;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("60 boxes and 30 balls onto a ramp, side view, t = {t:.2} s"),
            ("sans-serif", 15),
        )
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(36)
        .build_cartesian_2d(-9.0f32..7.0, -0.5f32..10.2)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(("sans-serif", 11))
        .disable_mesh()
        .draw()?;
    let grey = RGBColor(102, 102, 102);
    let ramp_q = glam::Quat::from_rotation_z(20f32.to_radians());
    let ramp = corners(Vec3::new(-3.0, 1.5, 0.0), ramp_q, Vec3::new(4.0, 0.2, 2.0));
    chart
        .draw_series(
            std::iter::once(PathElement::new(
                [(-9.0, 0.0), (7.0, 0.0)],
                grey.stroke_width(3),
            ))
            .chain(EDGES.map(|(a, b)| PathElement::new([ramp[a], ramp[b]], grey.stroke_width(2)))),
        )?
        .label("ground and ramp (static)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], grey.stroke_width(2)));
    let blue = RGBColor(0, 51, 204);
    let box_edges: Vec<_> = boxes
        .iter()
        .flat_map(|&e| {
            let x = world.get::<Position>(e).map_or(Vec3::NAN, Position::get);
            let q = world
                .get::<Rotation>(e)
                .map_or(glam::Quat::IDENTITY, |r| r.0);
            let c = corners(x, q, Vec3::new(0.35, 0.25, 0.3));
            EDGES.map(|(a, b)| PathElement::new([c[a], c[b]], blue))
        })
        .collect();
    chart
        .draw_series(box_edges)?
        .label("boxes 0.7 × 0.5 × 0.6 m")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], blue));
    let red = RGBColor(204, 51, 0);
    chart
        .draw_series(balls.iter().map(|&e| {
            let x = world.get::<Position>(e).map_or(Vec3::NAN, Position::get);
            // 0.3 m at the chart's scale of about 32 px/m.
            Circle::new((x.x, x.y), 10, red.filled())
        }))?
        .label("balls, 0.3 m radius")
        .legend(move |(x, y)| Circle::new((x + 8, y), 5, red.filled()));
    legend(&mut chart)?;
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = scenes::world_with(
        1.0 / 60.0,
        4,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )?;
    let (boxes, balls) = scenes::pile_scene(&mut world, 60, 30)?;
    register_fonts()?;
    let (path, still) = ("out/pile.gif", "out/pile.png");
    std::fs::create_dir_all("out")?;
    let size = (560, 400);
    // One frame every 4 steps (1/15 s), shown for 70 ms: about real time.
    let gif = BitMapBackend::gif(path, size, 70)?.into_drawing_area();
    for step in 0..=300 {
        if step > 0 {
            world.step_physics();
        }
        if step % 4 != 0 {
            continue;
        }
        let t = step as f32 / 60.0;
        frame(&gif, &world, &boxes, &balls, t)?;
        if step % 60 == 0 {
            let asleep = world
                .query_filtered::<(), With<hooke::core::rest::Sleeping>>()
                .iter(&world)
                .count();
            let d = world.resource::<PhysicsDiagnostics>();
            println!(
                "t = {t:.0} s: {} touching pairs, {} asleep, kinetic {:.1} J, step {:?}",
                world.resource::<Contacts>().touching_count(),
                asleep,
                d.kinetic_energy,
                d.step_time
            );
        }
    }
    frame(
        &BitMapBackend::new(still, size).into_drawing_area(),
        &world,
        &boxes,
        &balls,
        5.0,
    )?;
    println!(
        "wrote {path} and its last frame {still} (side view: boxes blue, balls red, ramp and ground grey)"
    );
    Ok(())
}
