//! Collision hooks at the defaults on the scene of `hooke::tools::hook_scenes`: a one-way
//! platform and a conveyor belt, written as game code (`PlatformHooks`), drawn as a PNG.
//!
//! ```text
//! cargo run --release --example collision_hooks -- [--seconds 4] [--out docs/collision_hooks.png]
//! ```
//!
//! Left: a ball launched up at 8 m/s from under a one-way platform rises through it on the
//! free-flight parabola, then lands on it and stays. Right: a 5 kg crate dropped at rest on
//! a belt whose surface runs at 2 m/s is accelerated by friction at μ g and then carried at
//! the belt's speed. Each curve is drawn against its closed form.

mod common;
use common::{axes, legend, register_fonts};

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::hook_scenes::{HooksCourse, PlatformHooks};
use plotters::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let clip = common::clip_options(4.0, "docs/collision_hooks.png")?;
    let (seconds, out) = (clip.seconds, clip.out);
    register_fonts()?;
    let course = HooksCourse::default();
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.add_physics(CollisionHooksPlugin::<PlatformHooks>::default());
    let parts = course.spawn(&mut w)?;
    let dt = w.resource::<PhysicsTime>().dt();
    let g = 9.81f32;
    let mu = w.get::<Friction>(parts.crate_).map_or(0.5, |f| f.0);
    let steps = (seconds / dt).round() as usize;
    let (mut heights, mut speeds) = (vec![(0.0, course.ball_radius)], vec![(0.0, 0.0)]);
    for step in 1..=steps {
        w.step_physics();
        let t = step as f32 * dt;
        heights.push((
            t,
            w.get::<Position>(parts.ball)
                .map_or(f32::NAN, |p| p.get().y),
        ));
        speeds.push((
            t,
            w.get::<LinearVelocity>(parts.crate_)
                .map_or(f32::NAN, |v| v.get().x),
        ));
    }
    let apex = heights.iter().map(|h| h.1).fold(f32::MIN, f32::max);
    let rest = heights.last().map_or(f32::NAN, |h| h.1);
    // Before it reaches the belt's end (x = 7 m) and drops off onto the floor.
    let (carried_at, carried) = speeds
        .iter()
        .take_while(|v| v.0 <= 1.5)
        .last()
        .copied()
        .unwrap_or((0.0, f32::NAN));
    println!(
        "ball: apex {apex:.3} m (free flight {:.3}), at {seconds} s its centre is at {rest:.3} m (resting on the platform: top + r = {:.3})",
        course.free_apex(g),
        course.platform_top + course.ball_radius
    );
    println!(
        "crate: {carried:.4} m/s at {carried_at:.2} s (belt {} m/s), μ = {mu}",
        course.belt_speed
    );

    std::fs::create_dir_all(out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::new(&out, (1400, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        "Collision hooks at the defaults: a one-way platform and a conveyor belt (PlatformHooks)",
        ("sans-serif", 20),
    )?;
    let panels = root.split_evenly((1, 2));

    let mut chart = ChartBuilder::on(&panels[0])
        .caption(
            format!(
                "ball launched up at {} m/s from under the platform",
                course.launch
            ),
            ("sans-serif", 15),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(0f32..seconds, 0f32..(apex + 0.5))?;
    axes(&mut chart, "time (s)", "height of the ball's centre (m)")?;
    let slab = hooke::tools::hook_scenes::SLAB;
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [
                (0.0, course.platform_top - 2.0 * slab),
                (seconds, course.platform_top),
            ],
            RGBColor(170, 170, 180).filled(),
        )))?
        .label("one-way platform (up is its walkable side)")
        .legend(|(x, y)| {
            Rectangle::new(
                [(x, y - 4), (x + 16, y + 4)],
                RGBColor(170, 170, 180).filled(),
            )
        });
    let free: Vec<(f32, f32)> = heights
        .iter()
        .map(|&(t, _)| (t, course.ball_radius + course.launch * t - 0.5 * g * t * t))
        .filter(|&(_, y)| y > 0.0)
        .collect();
    chart
        .draw_series(LineSeries::new(heights.clone(), BLUE.stroke_width(3)))?
        .label("hooke, with the hooks")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE.stroke_width(3)));
    chart
        .draw_series(LineSeries::new(free, BLACK.stroke_width(1)))?
        .label("free flight r + v t − g t²/2")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(1)));
    legend(&mut chart)?;

    let mut chart = ChartBuilder::on(&panels[1])
        .caption(
            format!(
                "{} kg crate on a belt running at {} m/s (μ = {mu})",
                course.crate_kg, course.belt_speed
            ),
            ("sans-serif", 15),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(0f32..seconds.min(2.0), 0f32..(course.belt_speed * 1.2))?;
    // (The crate reaches the belt's end at about 3 s and drops off.)
    axes(&mut chart, "time (s)", "crate's speed along the belt (m/s)")?;
    let shown = seconds.min(2.0);
    let speeds: Vec<(f32, f32)> = speeds.into_iter().filter(|v| v.0 <= shown).collect();
    let closed: Vec<(f32, f32)> = speeds
        .iter()
        .map(|&(t, _)| (t, (mu * g * t).min(course.belt_speed)))
        .collect();
    chart
        .draw_series(LineSeries::new(speeds, RED.stroke_width(3)))?
        .label("hooke, with the hooks")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(3)));
    chart
        .draw_series(LineSeries::new(closed, BLACK.stroke_width(1)))?
        .label("closed form min(μ g t, belt speed)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(1)));
    legend(&mut chart)?;
    root.present()?;
    println!("wrote {}", out.display());
    Ok(())
}
