//! A four-wheeled car driven by motors on its wheels' hinges, at the defaults, as an
//! animated GIF.
//!
//! ```text
//! cargo run --release --example vehicle -- [--seconds 5] [--out out/vehicle.gif]
//! ```
//!
//! Above, the car seen from the side (x, y, equal scales): a 300 kg chassis on four ball
//! wheels, each hinge's motor driving towards 5 m/s with at most 100 N·m; a spoke on each
//! wheel shows it turning. Below, the car's speed against time beside the closed form: the
//! motors' torque gives a = 4 τ / r / (M + 4 I / r²) until the target speed, then the car
//! holds it. The scene is `hooke::tools::joint_scenes::FourWheeler`, the one
//! `tests/it/joints/vehicle.rs` runs.

mod common;
use common::{axes, legend, register_fonts};

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{FourWheeler, FourWheelerParts};
use plotters::prelude::*;

type Options = common::Clip;

fn options() -> Result<Options, String> {
    common::clip_options(5.0, "out/vehicle.gif")
}

/// A body's place and turn.
fn pose(w: &World, e: Entity) -> Option<(Vec3, Quat)> {
    Some((Vec3::from(w.get::<Position>(e)?.0), w.get::<Rotation>(e)?.0))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let o = options()?;
    register_fonts()?;
    let car = FourWheeler::default();
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let parts = car.spawn(&mut w, 0.0)?;
    std::fs::create_dir_all(o.out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&o.out, (1000, 560), 100)?.into_drawing_area();
    let steps = (o.seconds * 60.0).round() as usize;
    let mut speeds = Vec::new();
    for step in 0..=steps {
        let t = step as f32 / 60.0;
        if step > 0 {
            w.step_physics();
        }
        let v = w
            .get::<LinearVelocity>(parts.chassis)
            .map_or(0.0, |v| v.0.x);
        speeds.push((t, v));
        if step % 6 != 0 && step != steps {
            continue;
        }
        draw(&root, &w, &car, &parts, &o, (t, &speeds))?;
        root.present()?;
        if step == steps {
            let png = o.out.with_extension("png");
            let still = BitMapBackend::new(&png, (1000, 560)).into_drawing_area();
            draw(&still, &w, &car, &parts, &o, (t, &speeds))?;
            still.present()?;
        }
    }
    let v = speeds.last().map_or(0.0, |s| s.1);
    println!(
        "wrote {} ({} frames); {v:.3} m/s after {:.1} s (target {} m/s), closed-form \
         acceleration {:.4} m/s²",
        o.out.display(),
        steps / 6 + 1,
        o.seconds,
        car.speed,
        car.acceleration()
    );
    Ok(())
}

/// Draws the side view and the speed plot on `root` (1000 × 560 px); `frame` is the time
/// (s) and the speed's history (s, m/s).
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    w: &World,
    car: &FourWheeler,
    parts: &FourWheelerParts,
    o: &Options,
    frame: (f32, &[(f32, f32)]),
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let (t, speeds) = frame;
    root.fill(&WHITE)?;
    let (upper, lower) = root.split_vertically(250);
    // Equal scales: about 936 × 174 px of plot for x in −2..24 m (36 px/m).
    let (x0, x1) = (-2.0_f32, 24.0_f32);
    let tall = (x1 - x0) * 174.0 / 936.0;
    let mut side = ChartBuilder::on(&upper)
        .caption(
            format!("A car on four wheel motors, t = {t:.2} s"),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(44)
        .build_cartesian_2d(x0..x1, -0.5f32..(tall - 0.5))?;
    axes(&mut side, "x (m)", "height y (m)")?;
    side.draw_series(LineSeries::new(
        [(x0, 0.0f32), (x1, 0.0)],
        BLACK.stroke_width(2),
    ))?
    .label("ground")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(2)));
    let blue = RGBColor(40, 80, 200);
    if let Some((x, q)) = pose(w, parts.chassis) {
        let c = FourWheeler::CHASSIS;
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(sx, sy)| {
            let p = x + q * Vec3::new(sx * c.x, sy * c.y, 0.0);
            (p.x, p.y)
        });
        side.draw_series([Polygon::new(corners.to_vec(), blue.filled())])?
            .label(format!("chassis, {:.0} kg", FourWheeler::chassis_mass()))
            .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 18, y + 4)], blue.filled()));
    }
    let grey = RGBColor(60, 60, 60);
    let radius = (FourWheeler::WHEEL * 36.0).round() as i32;
    // The near wheels (z > 0) over the far ones; a spoke on each to show the turn.
    for (k, &e) in parts.wheels.iter().enumerate() {
        let Some((x, q)) = pose(w, e) else { continue };
        let spoke = x + q * Vec3::new(FourWheeler::WHEEL, 0.0, 0.0);
        let series = side.draw_series([Circle::new((x.x, x.y), radius, grey.filled())])?;
        if k == 0 {
            series
                .label(format!(
                    "wheels, {:.1} kg, motors {} N·m at most",
                    FourWheeler::wheel_mass(),
                    car.torque
                ))
                .legend(move |(x, y)| Circle::new((x + 9, y), 5, grey.filled()));
        }
        side.draw_series(LineSeries::new(
            [(x.x, x.y), (spoke.x, spoke.y)],
            WHITE.stroke_width(2),
        ))?;
    }
    legend(&mut side)?;
    let a = car.acceleration();
    let mut plot = ChartBuilder::on(&lower)
        .caption("speed", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(50)
        .build_cartesian_2d(0f32..o.seconds, 0f32..6f32)?;
    axes(&mut plot, "time t (s)", "speed (m/s)")?;
    let reach = car.speed / a;
    let closed = [
        (0.0, 0.0),
        (reach.min(o.seconds), a * reach.min(o.seconds)),
        (
            o.seconds,
            if reach < o.seconds {
                car.speed
            } else {
                a * o.seconds
            },
        ),
    ];
    let gray = RGBColor(120, 120, 120);
    plot.draw_series(LineSeries::new(closed, gray.stroke_width(4)))?
        .label(format!(
            "closed form: {a:.3} m/s² (4 τ / r / (M + 4 I / r²)), then {} m/s",
            car.speed
        ))
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], gray.stroke_width(4)));
    plot.draw_series(LineSeries::new(
        speeds.iter().copied(),
        blue.stroke_width(2),
    ))?
    .label("hooke at the defaults")
    .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], blue.stroke_width(2)));
    plot.configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font(("sans-serif", 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
