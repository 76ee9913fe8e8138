//! Twenty ragdolls dropped into a pile at the defaults, as an animated GIF.
//!
//! ```text
//! cargo run --release --example ragdolls -- [--ragdolls 20] [--seconds 6] [--out out/ragdolls.gif]
//! ```
//!
//! Left, the pile seen from the front (x, y, equal scales): each ragdoll's capsules drawn
//! as thick segments, coloured by the order they were dropped in. Right, the widest any
//! joint's anchors stand apart (`JointDiagnostics::largest_gap`) against time, beside the
//! 1 cm the joints are meant to hold. The scene is `hooke::tools::joint_scenes::RagdollPile`,
//! the one the tests and `perf_report --only joints` run.

mod common;
use common::{axes, legend, ramp, register_fonts};

use std::path::PathBuf;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{Ragdoll, RagdollPile};
use plotters::prelude::*;

struct Options {
    ragdolls: usize,
    seconds: f32,
    out: PathBuf,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        ragdolls: 20,
        seconds: 6.0,
        out: PathBuf::from("out/ragdolls.gif"),
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--ragdolls" => o.ragdolls = value.parse().map_err(|e| format!("--ragdolls: {e}"))?,
            "--seconds" => o.seconds = value.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--out" => o.out = PathBuf::from(value),
            other => return Err(format!("unknown flag {other}")),
        }
    }
    Ok(o)
}

/// A point of the front view (x, y), in m.
type Point = (f32, f32);

/// The ends of part `e`'s capsule core (x, y) and its radius.
fn segment(w: &World, e: Entity, part: usize) -> Option<(Point, Point, f32)> {
    let x = Vec3::from(w.get::<Position>(e)?.0);
    let q = w.get::<Rotation>(e)?.0;
    let p = &Ragdoll::PARTS[part];
    let half = q * Vec3::new(0.0, p.half_height, 0.0);
    let (a, b) = (x - half, x + half);
    Some(((a.x, a.y), (b.x, b.y), p.radius))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let o = options()?;
    register_fonts()?;
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let (parts, _) = RagdollPile {
        ragdolls: o.ragdolls,
    }
    .spawn(&mut w)?;
    std::fs::create_dir_all(o.out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&o.out, (1000, 760), 100)?.into_drawing_area();
    let steps = (o.seconds * 60.0).round() as usize;
    let mut gaps: Vec<(f32, f32)> = Vec::new();
    let mut widest = 0.0_f32;
    for step in 0..=steps {
        if step > 0 {
            w.step_physics();
        }
        let t = step as f32 / 60.0;
        let d = *w.resource::<JointDiagnostics>();
        widest = widest.max(d.largest_gap);
        gaps.push((t, 1e3 * d.largest_gap));
        if step % 6 != 0 && step != steps {
            continue;
        }
        let frame = Frame {
            t,
            now: d.largest_gap,
            widest,
            gaps: &gaps,
        };
        draw(&root, &w, &parts, &o, &frame)?;
        root.present()?;
        if step == steps {
            let png = o.out.with_extension("png");
            let still = BitMapBackend::new(&png, (1000, 760)).into_drawing_area();
            draw(&still, &w, &parts, &o, &frame)?;
            still.present()?;
        }
    }
    let quarantined = parts
        .iter()
        .filter(|&&e| w.get::<Quarantined>(e).is_some())
        .count();
    println!(
        "wrote {} ({} frames); widest joint gap {:.2} mm, {quarantined} parts quarantined",
        o.out.display(),
        steps / 6 + 1,
        1e3 * widest
    );
    Ok(())
}

/// What one frame shows besides the pile: the time (s), the widest joint gap now and so far
/// (m), and the gap's history (s, mm).
struct Frame<'a> {
    t: f32,
    now: f32,
    widest: f32,
    gaps: &'a [(f32, f32)],
}

/// Draws the pile and the gap plot on `root` (1000 × 760 px).
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    w: &World,
    parts: &[Entity],
    o: &Options,
    frame: &Frame,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let Frame {
        t,
        now,
        widest,
        gaps,
    } = *frame;
    let (left, right) = root.split_horizontally(470);
    let top = 0.4 + 0.5 * o.ragdolls as f32 + 0.6;
    // Equal scales: the plot area is about PLOT_W × PLOT_H pixels; x spans what the height
    // gives it, and `scale` is pixels per metre (for the capsules' widths).
    const PLOT_W: f32 = 470.0 - 44.0 - 20.0;
    const PLOT_H: f32 = 760.0 - 36.0 - 20.0 - 30.0;
    let scale = PLOT_H / (top + 0.2);
    let half = 0.5 * PLOT_W / scale;
    let per_ragdoll = Ragdoll::PARTS.len();
    root.fill(&WHITE)?;
    let mut pile = ChartBuilder::on(&left)
        .caption(
            format!("{} ragdolls at the defaults, t = {t:.2} s", o.ragdolls),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(44)
        .build_cartesian_2d(-half..half, -0.2f32..top)?;
    axes(&mut pile, "x (m)", "height y (m)")?;
    pile.draw_series(LineSeries::new(
        [(-half, 0.0f32), (half, 0.0)],
        BLACK.stroke_width(2),
    ))?
    .label("ground (static box)")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(2)));
    for (k, chunk) in parts.chunks(per_ragdoll).enumerate() {
        let color = ramp(k as f32 / (o.ragdolls.max(2) - 1) as f32);
        let capsules = chunk.iter().enumerate().filter_map(|(i, &e)| {
            let (a, b, r) = segment(w, e, i)?;
            let width = (2.0 * r * scale).round().max(1.0) as u32;
            Some(PathElement::new([a, b], color.stroke_width(width)))
        });
        let series = pile.draw_series(capsules)?;
        if k == 0 || k + 1 == o.ragdolls {
            let name = if k == 0 {
                "first dropped (lowest)"
            } else {
                "last dropped (highest)"
            };
            series.label(name).legend(move |(x, y)| {
                PathElement::new([(x, y), (x + 18, y)], color.stroke_width(6))
            });
        }
    }
    legend(&mut pile)?;
    let mut gap = ChartBuilder::on(&right)
        .caption(
            format!(
                "widest joint gap: now {:.2} mm, most {:.2} mm",
                1e3 * now,
                1e3 * widest
            ),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(50)
        .build_cartesian_2d(0f32..o.seconds, 0f32..15f32)?;
    axes(&mut gap, "time t (s)", "anchors apart (mm)")?;
    gap.draw_series(LineSeries::new(
        [(0.0f32, 10.0f32), (o.seconds, 10.0)],
        RGBColor(200, 40, 40).stroke_width(1),
    ))?
    .label("the goal: under 1 cm")
    .legend(|(x, y)| {
        PathElement::new([(x, y), (x + 18, y)], RGBColor(200, 40, 40).stroke_width(1))
    });
    gap.draw_series(LineSeries::new(gaps.iter().copied(), BLUE.stroke_width(2)))?
        .label(format!(
            "widest of {} joints (JointDiagnostics)",
            o.ragdolls * Ragdoll::JOINTS.len()
        ))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLUE.stroke_width(2)));
    legend(&mut gap)?;
    Ok(())
}
