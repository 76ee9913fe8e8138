//! A ball thrown at a hinged door at the defaults, as an animated GIF.
//!
//! ```text
//! cargo run --release --example door -- [--restitution 0] [--seconds 1.5] [--out out/door.gif]
//! ```
//!
//! Left, the door and the ball seen from above (x, z, equal scales): a 50 kg door hinged at
//! its edge with stops at 0° and 100°, a 14.5 kg ball thrown at 6 m/s striking it 0.8 m from
//! the hinge. Right, the door's angle against time beside the closed form: the blow's
//! angular momentum about the hinge, m v r, shared between the ball and the door, turns the
//! door at J r / I until it stops dead at 100°. The scene is
//! `hooke::tools::joint_scenes::HingedDoor`, the one `tests/it/joints/door.rs` runs.

mod common;
use common::{axes, legend, register_fonts};

use std::path::PathBuf;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{HingedDoor, HingedDoorParts};
use plotters::prelude::*;

struct Options {
    restitution: f32,
    seconds: f32,
    out: PathBuf,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        restitution: 0.0,
        seconds: 1.5,
        out: PathBuf::from("out/door.gif"),
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--restitution" => {
                o.restitution = value.parse().map_err(|e| format!("--restitution: {e}"))?;
            }
            "--seconds" => o.seconds = value.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--out" => o.out = PathBuf::from(value),
            other => return Err(format!("unknown flag {other}")),
        }
    }
    Ok(o)
}

/// The door's turn about its hinge (rad).
fn door_angle(w: &World, door: Entity) -> f32 {
    w.get::<Rotation>(door)
        .map_or(0.0, |q| 2.0 * q.0.y.atan2(q.0.w))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let o = options()?;
    register_fonts()?;
    let scene = HingedDoor {
        restitution: o.restitution,
        ..HingedDoor::default()
    };
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let parts = scene.spawn(&mut w)?;
    std::fs::create_dir_all(o.out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::gif(&o.out, (1000, 500), 60)?.into_drawing_area();
    let steps = (o.seconds * 60.0).round() as usize;
    let mut angles = Vec::new();
    let hit = Some(scene.strike_time());
    for step in 0..=steps {
        let t = step as f32 / 60.0;
        if step > 0 {
            w.step_physics();
        }
        let angle = door_angle(&w, parts.door);
        angles.push((t, angle.to_degrees()));
        if step % 2 != 0 && step != steps {
            continue;
        }
        draw(&root, &w, &scene, &parts, &o, (t, &angles, hit))?;
        root.present()?;
        if step == steps {
            let png = o.out.with_extension("png");
            let still = BitMapBackend::new(&png, (1000, 500)).into_drawing_area();
            draw(&still, &w, &scene, &parts, &o, (t, &angles, hit))?;
            still.present()?;
        }
    }
    let (spin, _) = scene.after_hit();
    println!(
        "wrote {} ({} frames); door at {:.2}° after {:.1} s, closed-form spin {spin:.4} rad/s",
        o.out.display(),
        steps / 2 + 1,
        door_angle(&w, parts.door).to_degrees(),
        o.seconds
    );
    Ok(())
}

/// Draws the top view and the angle plot on `root` (1000 × 500 px); `frame` is the time
/// (s), the angle's history (s, degrees) and when the door first moved (s).
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    w: &World,
    scene: &HingedDoor,
    parts: &HingedDoorParts,
    o: &Options,
    frame: (f32, &[(f32, f32)], Option<f32>),
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let (t, angles, hit) = frame;
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(480);
    // Equal scales: about 416 × 414 px of plot, x in −0.4..1.4 m and z in −1.2..0.6 m.
    let mut top = ChartBuilder::on(&left)
        .caption(format!("Seen from above, t = {t:.2} s"), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(44)
        .build_cartesian_2d(-0.4f32..1.4f32, -1.2f32..0.6f32)?;
    axes(&mut top, "x (m)", "z (m)")?;
    let open = HingedDoor::OPEN;
    let stop = (open.cos(), -open.sin());
    top.draw_series(LineSeries::new(
        [(0.0f32, 0.0f32), stop],
        RGBColor(200, 40, 40).stroke_width(1),
    ))?
    .label("open stop, 100°")
    .legend(|(x, y)| {
        PathElement::new([(x, y), (x + 18, y)], RGBColor(200, 40, 40).stroke_width(1))
    });
    let wood = RGBColor(170, 110, 50);
    let angle = door_angle(w, parts.door);
    let edge = (
        2.0 * HingedDoor::DOOR.x * angle.cos(),
        -2.0 * HingedDoor::DOOR.x * angle.sin(),
    );
    // 0.05 m thick at about 230 px/m.
    top.draw_series([PathElement::new(
        [(0.0f32, 0.0f32), edge],
        wood.stroke_width(12),
    )])?
    .label(format!(
        "door, {:.0} kg, hinged at (0, 0)",
        HingedDoor::door_mass()
    ))
    .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], wood.stroke_width(8)));
    let blue = RGBColor(40, 80, 200);
    // Drawn while it is in view (it rolls off along −z on the floor).
    let ball = w
        .get::<Position>(parts.ball)
        .map(|p| Vec3::from(p.0))
        .filter(|p| p.z > -1.1 && p.x < 1.3);
    let radius = (HingedDoor::BALL * 230.0).round() as i32;
    top.draw_series(ball.map(|p| Circle::new((p.x, p.z), radius, blue.filled())))?
        .label(format!(
            "ball, {:.1} kg, thrown at {} m/s (gone on along -z)",
            HingedDoor::ball_mass(),
            scene.speed
        ))
        .legend(move |(x, y)| Circle::new((x + 9, y), 5, blue.filled()));
    legend(&mut top)?;
    let (spin, _) = scene.after_hit();
    let mut plot = ChartBuilder::on(&right)
        .caption(
            format!(
                "door angle: blow's closed form {spin:.3} rad/s (e = {})",
                scene.restitution
            ),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(50)
        .build_cartesian_2d(0f32..o.seconds, -5f32..110f32)?;
    axes(&mut plot, "time t (s)", "door angle (degrees)")?;
    if let Some(t0) = hit {
        let reach = t0 + open / spin;
        let closed = [
            (0.0, 0.0),
            (t0, 0.0),
            (
                reach.min(o.seconds),
                (spin * (reach.min(o.seconds) - t0)).to_degrees(),
            ),
            (
                o.seconds,
                if reach < o.seconds {
                    100.0
                } else {
                    (spin * (o.seconds - t0)).to_degrees()
                },
            ),
        ];
        plot.draw_series(LineSeries::new(
            closed,
            RGBColor(120, 120, 120).stroke_width(4),
        ))?
        .label("closed form: J r / I, then the stop")
        .legend(|(x, y)| {
            PathElement::new(
                [(x, y), (x + 18, y)],
                RGBColor(120, 120, 120).stroke_width(4),
            )
        });
    }
    plot.draw_series(LineSeries::new(
        angles.iter().copied(),
        wood.stroke_width(2),
    ))?
    .label("hooke at the defaults")
    .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], wood.stroke_width(2)));
    legend(&mut plot)?;
    Ok(())
}
