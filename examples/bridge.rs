//! A crate pushed across a plank bridge on hinges at the defaults, as an animated GIF.
//!
//! ```text
//! cargo run --release --example bridge -- [--seconds 16] [--out out/bridge.gif]
//! ```
//!
//! Above, the bridge seen from the side (x, y, equal scales): 20 planks hinged end to end and
//! to two abutments, spawned in their equilibrium (the discrete catenary, drawn dashed), and
//! the crate walked across at 1 m/s by a force a player could push with. Below, the widest
//! any hinge's anchors stand apart (`JointDiagnostics::largest_gap`) and how far the bridge
//! sags under the crate, against time. The scene is
//! `hooke::tools::joint_scenes::ChainBridge`, the one `tests/it/joints/bridge.rs` runs.

mod common;
use common::{axes, legend, register_fonts};

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};
use hooke::prelude::*;
use hooke::tools::joint_scenes::{ChainBridge, ChainBridgeParts};
use plotters::prelude::*;

type Options = common::Clip;

fn options() -> Result<Options, String> {
    common::clip_options(16.0, "out/bridge.gif")
}

/// The corners of box `e` (half extents `half`) seen from the side: (x, y) in m.
fn outline(w: &World, e: Entity, half: Vec3) -> Option<Vec<(f32, f32)>> {
    let x = Vec3::from(w.get::<Position>(e)?.0);
    let q = w.get::<Rotation>(e)?.0;
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    Some(
        corners
            .iter()
            .map(|&(sx, sy)| {
                let p = x + q * Vec3::new(sx * half.x, sy * half.y, 0.0);
                (p.x, p.y)
            })
            .collect(),
    )
}

/// What one frame shows besides the scene: the time (s) and the histories (s, mm) and (s, m).
struct Frame<'a> {
    t: f32,
    gaps: &'a [(f32, f32)],
    sags: &'a [(f32, f32)],
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let o = options()?;
    register_fonts()?;
    let bridge = ChainBridge::default();
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let parts = bridge.spawn(&mut w)?;
    std::fs::create_dir_all(o.out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&o.out, (1000, 700), 200)?.into_drawing_area();
    let steps = (o.seconds * 60.0).round() as usize;
    let far = 0.5 * bridge.span + 0.5;
    let (mut gaps, mut sags) = (Vec::new(), Vec::new());
    let (mut widest, mut deepest) = (0.0_f32, 0.0_f32);
    let mut arrived = None;
    for step in 0..=steps {
        let t = step as f32 / 60.0;
        if step > 0 {
            let x = w
                .get::<Position>(parts.crate_box)
                .map_or(Vec3A::ZERO, |p| p.0);
            if x.x > far && arrived.is_none() {
                arrived = Some(t);
            }
            let speed = if arrived.is_none() { 1.0 } else { 0.0 };
            ChainBridge::push(&mut w, parts.crate_box, speed);
            w.step_physics();
        }
        let gap = w.resource::<JointDiagnostics>().largest_gap;
        let sag = -parts
            .planks
            .iter()
            .filter_map(|&p| w.get::<Position>(p).map(|x| x.0.y))
            .fold(0.0_f32, f32::min);
        widest = widest.max(gap);
        deepest = deepest.max(sag);
        gaps.push((t, 1e3 * gap));
        sags.push((t, sag));
        if step % 12 != 0 && step != steps {
            continue;
        }
        let frame = Frame {
            t,
            gaps: &gaps,
            sags: &sags,
        };
        draw(&root, &w, &bridge, &parts, &o, &frame)?;
        root.present()?;
        if step == steps {
            let png = o.out.with_extension("png");
            let still = BitMapBackend::new(&png, (1000, 700)).into_drawing_area();
            draw(&still, &w, &bridge, &parts, &o, &frame)?;
            still.present()?;
        }
    }
    let quarantined = parts
        .planks
        .iter()
        .chain([&parts.crate_box])
        .filter(|&&e| w.get::<Quarantined>(e).is_some())
        .count();
    println!(
        "wrote {} ({} frames); crate across at {}, widest hinge gap {:.2} mm, deepest sag {:.3} m \
         (lowest hinge at rest {:.3} m), {quarantined} bodies quarantined",
        o.out.display(),
        steps / 12 + 1,
        arrived.map_or("never".to_string(), |t| format!("{t:.1} s")),
        1e3 * widest,
        deepest,
        bridge.sag(),
    );
    Ok(())
}

/// Draws the bridge and the plots on `root` (1100 × 560 px).
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    w: &World,
    bridge: &ChainBridge,
    parts: &ChainBridgeParts,
    o: &Options,
    frame: &Frame,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (left, right) = root.split_vertically(360);
    // Equal scales: about 936 × 284 px of plot for x in ±7.5 m.
    let half_x = 7.5_f32;
    let tall = 2.0 * half_x * 284.0 / 936.0;
    let mut side = ChartBuilder::on(&left)
        .caption(
            format!(
                "A crate pushed across a hinged bridge, t = {:.2} s",
                frame.t
            ),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(44)
        .build_cartesian_2d(-half_x..half_x, -1.3f32..(tall - 1.3))?;
    axes(&mut side, "x (m)", "height y (m)")?;
    let a = ChainBridge::ABUTMENT;
    for &e in &parts.abutments {
        if let Some(c) = outline(w, e, a) {
            side.draw_series([Polygon::new(c, RGBColor(150, 150, 150).filled())])?;
        }
    }
    side.draw_series(LineSeries::new(
        bridge.hinge_points().iter().map(|p| (p.x, p.y)),
        RGBColor(120, 120, 120).stroke_width(1),
    ))?
    .label("equilibrium at rest (discrete catenary)")
    .legend(|(x, y)| {
        PathElement::new(
            [(x, y), (x + 18, y)],
            RGBColor(120, 120, 120).stroke_width(1),
        )
    });
    let wood = RGBColor(170, 110, 50);
    let planks = parts
        .planks
        .iter()
        .filter_map(|&p| outline(w, p, ChainBridge::PLANK))
        .map(|c| Polygon::new(c, wood.filled()));
    side.draw_series(planks)?
        .label("planks, 21.6 kg each, hinged end to end")
        .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 18, y + 4)], wood.filled()));
    let blue = RGBColor(40, 80, 200);
    if let Some(c) = outline(w, parts.crate_box, ChainBridge::CRATE) {
        side.draw_series([Polygon::new(c, blue.filled())])?
            .label(format!(
                "crate, {:.1} kg, pushed at 1 m/s",
                ChainBridge::crate_mass()
            ))
            .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 18, y + 4)], blue.filled()));
    }
    // Above the middle of the bridge, clear of the crate at either end.
    side.configure_series_labels()
        .position(SeriesLabelPosition::UpperMiddle)
        .label_font(("sans-serif", 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    let (top, bottom) = right.split_horizontally(500);
    let mut gap = ChartBuilder::on(&top)
        .caption(
            "widest hinge gap (the goal: under 10 mm)",
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0f32..o.seconds, 0f32..1.0f32)?;
    axes(&mut gap, "time t (s)", "anchors apart (mm)")?;
    gap.draw_series(LineSeries::new(
        frame.gaps.iter().copied(),
        BLUE.stroke_width(2),
    ))?
    .label("widest of 21 hinges")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLUE.stroke_width(2)));
    legend(&mut gap)?;
    let mut sag = ChartBuilder::on(&bottom)
        .caption("sag: the lowest plank below the ends", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0f32..o.seconds, 0f32..1.0f32)?;
    axes(&mut sag, "time t (s)", "sag (m)")?;
    // The lowest plank centre of the equilibrium, below the end hinges.
    let rest = -bridge
        .hinge_points()
        .windows(2)
        .map(|p| 0.5 * (p[0].y + p[1].y))
        .fold(0.0_f32, f32::min);
    sag.draw_series(LineSeries::new(
        [(0.0f32, rest), (o.seconds, rest)],
        RGBColor(120, 120, 120).stroke_width(1),
    ))?
    .label("at rest (closed form)")
    .legend(|(x, y)| {
        PathElement::new(
            [(x, y), (x + 18, y)],
            RGBColor(120, 120, 120).stroke_width(1),
        )
    });
    sag.draw_series(LineSeries::new(
        frame.sags.iter().copied(),
        wood.stroke_width(2),
    ))?
    .label("measured")
    .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], wood.stroke_width(2)));
    legend(&mut sag)?;
    Ok(())
}
