//! The intermediate-axis theorem (the "Dzhanibekov effect"): a body with I = diag(1, 2, 3)
//! spun about its middle axis with a tiny wobble flips over and over, while |L| stays exact
//! and the energy stays put. Writes `out/tumbling.png`: body-frame ω components (top) and
//! energy and |L| relative to their start (bottom).
//!
//! ```text
//! cargo run --release --example tumbling
//! ```

mod common;

use common::{legend, register_fonts};
use hooke::prelude::*;
use hooke::rigid::AngularMomentum;
use hooke::rigid::AngularVelocity;
use hooke::rigid::Inertia;
use hooke::rigid::MassProperties;
use hooke::rigid::RigidBodyBundle;
use hooke::rigid::Rotation;
use hooke::tools::scenes;
use plotters::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = scenes::world_with(1.0 / 60.0, 1, Integrator::SymplecticEuler, Vec3::ZERO)?;
    let props = MassProperties::new(1.0, Vec3::ZERO, Inertia::diagonal(1.0, 2.0, 3.0)?)?;
    let body = world
        .spawn(RigidBodyBundle::dynamic(props)?.with_angular_velocity(Vec3::new(0.01, 2.0, 0.01))?)
        .id();
    let seconds = 20.0;
    let steps = (seconds * 60.0) as usize;
    let mut samples = Vec::with_capacity(steps);
    for _ in 0..steps {
        world.step_physics();
        let q = world.get::<Rotation>(body).unwrap().0;
        let w = world.get::<AngularVelocity>(body).unwrap().0;
        let l = world.get::<AngularMomentum>(body).unwrap().0;
        samples.push((q.inverse() * Vec3::from(w), 0.5 * w.dot(l), l.length()));
    }
    let (t0, l0) = (samples[0].1, samples[0].2);

    register_fonts()?;
    let path = "out/tumbling.png";
    std::fs::create_dir_all("out")?;
    let root = BitMapBackend::new(path, (1000, 720)).into_drawing_area();
    root.fill(&WHITE)?;
    let (title, body) = root.split_vertically(40);
    title.draw(&Text::new(
        "Intermediate-axis flips: I = diag(1, 2, 3) spun at ω = (0.01, 2, 0.01) rad/s, symplectic Euler, 60 Hz",
        (16, 10),
        ("sans-serif", 17),
    ))?;
    let (upper, lower) = body.split_vertically(380);
    let t = |i: usize| i as f32 / 60.0;
    let mut top = ChartBuilder::on(&upper)
        .caption("angular velocity in the body frame", ("sans-serif", 15))
        .margin(10)
        .x_label_area_size(32)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0f32..seconds, -2.5f32..2.5)?;
    top.configure_mesh()
        .x_desc("t (s)")
        .y_desc("ω (rad/s)")
        .label_style(("sans-serif", 12))
        .draw()?;
    let colors = [
        RGBColor(200, 60, 60),
        RGBColor(40, 120, 200),
        RGBColor(60, 160, 80),
    ];
    for (axis, (color, name)) in colors.into_iter().zip(["ω_x", "ω_y", "ω_z"]).enumerate() {
        top.draw_series(LineSeries::new(
            samples.iter().enumerate().map(|(i, s)| (t(i), s.0[axis])),
            color.stroke_width(2),
        ))?
        .label(name)
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2)));
    }
    legend(&mut top)?;
    let dev = |r: f32| 100.0 * (r - 1.0);
    let mut bottom = ChartBuilder::on(&lower)
        .caption(
            "what is conserved: kinetic energy and |L| against their start",
            ("sans-serif", 15),
        )
        .margin(10)
        .x_label_area_size(32)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0f32..seconds, -1.0f32..1.0)?;
    bottom
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc("change (%)")
        .label_style(("sans-serif", 12))
        .draw()?;
    let orange = RGBColor(230, 140, 20);
    bottom
        .draw_series(LineSeries::new(
            samples
                .iter()
                .enumerate()
                .map(|(i, s)| (t(i), dev(s.1 / t0))),
            orange.stroke_width(2),
        ))?
        .label("kinetic energy")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], orange.stroke_width(2)));
    bottom
        .draw_series(LineSeries::new(
            samples
                .iter()
                .enumerate()
                .map(|(i, s)| (t(i), dev(s.2 / l0))),
            BLACK,
        ))?
        .label("|L| (exact by construction)")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK));
    legend(&mut bottom)?;
    root.present()?;

    let flips = samples
        .windows(2)
        .filter(|w| w[0].0.y.signum() != w[1].0.y.signum())
        .count();
    let max_dev = samples
        .iter()
        .map(|s| (s.1 / t0 - 1.0).abs())
        .fold(0.0, f32::max);
    println!("spin about the intermediate axis: ω_y changed sign {flips} times in {seconds} s");
    println!(
        "max energy deviation {:.3} %, max |L| deviation {:.1e}",
        100.0 * max_dev,
        samples
            .iter()
            .map(|s| (s.2 / l0 - 1.0).abs())
            .fold(0.0, f32::max)
    );
    println!("wrote {path} (top: body-frame ω; bottom: energy and |L| change in %)");
    Ok(())
}
