//! The intermediate-axis theorem (the "Dzhanibekov effect"): a body with I = diag(1, 2, 3)
//! spun about its middle axis with a tiny wobble flips over and over, while |L| stays exact
//! and the energy stays put. Writes `out/tumbling.png`: body-frame ω components (top) and
//! energy and |L| relative to their start (bottom).
//!
//! ```text
//! cargo run --release --example tumbling
//! ```

mod common;

use std::path::Path;

use common::Canvas;
use hooke::prelude::*;
use hooke::{
    AngularMomentum, AngularVelocity, Inertia, MassProperties, RigidBodyBundle, Rotation, scenes,
};

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

    // Top panel: ω in the body frame, rad/s, over [−2.5, 2.5]; bottom: ratios around 1.
    let (width, height) = (1000, 600);
    let mut top = Canvas::new(width, height, [0.0, -2.5, seconds, 2.5], [252, 252, 250]);
    let colors = [[200, 60, 60], [40, 120, 200], [60, 160, 80]];
    for (axis, color) in colors.into_iter().enumerate() {
        let pts: Vec<_> = samples
            .iter()
            .enumerate()
            .map(|(i, s)| (i as f32 / 60.0, s.0[axis] * 0.6 + 0.9))
            .collect();
        top.polyline(&pts, 2, color);
    }
    // Energy and |L| ratios, scaled so ±1 % fills the lower band.
    let band = |r: f32| -1.6 + (r - 1.0) * 50.0;
    let e: Vec<_> = samples
        .iter()
        .enumerate()
        .map(|(i, s)| (i as f32 / 60.0, band(s.1 / t0)))
        .collect();
    let l: Vec<_> = samples
        .iter()
        .enumerate()
        .map(|(i, s)| (i as f32 / 60.0, band(s.2 / l0)))
        .collect();
    top.line((0.0, band(1.0)), (seconds, band(1.0)), 1, [200, 200, 200]);
    top.line((0.0, 0.9), (seconds, 0.9), 1, [200, 200, 200]);
    top.polyline(&e, 2, [230, 140, 20]);
    top.polyline(&l, 1, [0, 0, 0]);
    top.frame(0, 0, width as i64 - 1, height as i64 - 1, [120, 120, 120]);
    let path = Path::new("out/tumbling.png");
    top.save_png(path)?;

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
    println!(
        "wrote {} (top: body ω_x red, ω_y blue, ω_z green; bottom: energy orange and |L| black, ±1 % band)",
        path.display()
    );
    Ok(())
}
