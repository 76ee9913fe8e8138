//! The README demo: a swinging rope, a hair strand, tracers in a vortex and thrown
//! particles, stepped headless for 5 s. Prints one summary line per simulated second and
//! writes `out/showcase.png` (trajectories and rope snapshots, with axes in metres and a
//! legend).
//!
//! ```text
//! cargo run --release --example showcase
//! ```

mod common;

use bevy_ecs::prelude::*;
use common::{legend, ramp, register_fonts};
use hooke::prelude::*;
use hooke::tools::scenes;
use plotters::prelude::*;

fn xy(world: &World, e: Entity) -> (f32, f32) {
    let p = world.get::<Position>(e).map_or(Vec3::NAN, Position::get);
    (p.x, p.y)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 8 substeps: the rope's springs (4000 N/m on 0.1 kg) need h < √(m/k) ≈ 5 ms.
    let mut world = scenes::world_with(
        1.0 / 60.0,
        8,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )?;
    let scene = scenes::showcase(&mut world)?;

    let mut particle_paths: Vec<Vec<(f32, f32)>> = vec![Vec::new(); scene.particles.len()];
    let mut tracer_paths: Vec<Vec<(f32, f32)>> = vec![Vec::new(); scene.tracers.len()];
    // (time fraction, rope, hair) every half second.
    let mut snapshots = Vec::new();
    let seconds = 5;
    println!(
        "{:>5} {:>10} {:>10} {:>10} {:>10} {:>10}  counts",
        "t (s)", "kinetic J", "gravity J", "spring J", "total J", "|P| kg·m/s"
    );
    for step in 0..=seconds * 60 {
        if step > 0 {
            world.step_physics();
        }
        for (path, &e) in particle_paths.iter_mut().zip(&scene.particles) {
            path.push(xy(&world, e));
        }
        for (path, &e) in tracer_paths.iter_mut().zip(&scene.tracers) {
            path.push(xy(&world, e));
        }
        if step % 30 == 0 {
            let t = step as f32 / (seconds * 60) as f32;
            let rope: Vec<_> = scene.rope.nodes.iter().map(|&e| xy(&world, e)).collect();
            let hair: Vec<_> = scene.hair.nodes.iter().map(|&e| xy(&world, e)).collect();
            snapshots.push((t, rope, hair));
        }
        if step > 0 && step % 60 == 0 {
            let d = world.resource::<PhysicsDiagnostics>();
            let c = d.counts;
            println!(
                "{:>5} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>10.4}  {} particles, {} springs, {} tracers, {} quarantined",
                step / 60,
                d.kinetic_energy,
                d.gravitational_energy,
                d.spring_energy,
                d.total_energy(),
                d.linear_momentum.length(),
                c.particles,
                c.springs,
                c.tracers,
                c.quarantined
            );
        }
    }

    register_fonts()?;
    let path = "out/showcase.png";
    std::fs::create_dir_all("out")?;
    let root = BitMapBackend::new(path, (1100, 760)).into_drawing_area();
    root.fill(&RGBColor(252, 252, 250))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "hooke showcase: 5 s at 60 Hz (rope and hair snapshots every 0.5 s, blue → orange)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-5.0f32..6.0, -3.0f32..4.0)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE)
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            [(-5.0, 0.0), (6.0, 0.0)],
            RGBColor(160, 160, 160),
        ))?
        .label("y = 0")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], RGBColor(160, 160, 160)));
    let tracer = RGBColor(120, 170, 120);
    for (i, p) in tracer_paths.iter().enumerate() {
        let s = chart.draw_series(LineSeries::new(p.iter().copied(), tracer))?;
        if i == 0 {
            s.label("tracers carried by the vortex field")
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], tracer));
        }
    }
    for (t, rope, hair) in &snapshots {
        let c = ramp(*t);
        chart.draw_series(LineSeries::new(rope.iter().copied(), c.stroke_width(2)))?;
        chart.draw_series(LineSeries::new(hair.iter().copied(), c.stroke_width(1)))?;
    }
    // Legend entries for the snapshots: the first and last colours.
    chart
        .draw_series(std::iter::empty::<Circle<(f32, f32), i32>>())?
        .label("rope (thick) and hair (thin) at t = 0 s")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], ramp(0.0).stroke_width(2)));
    chart
        .draw_series(std::iter::empty::<Circle<(f32, f32), i32>>())?
        .label("… at t = 5 s")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], ramp(1.0).stroke_width(2)));
    let red = RGBColor(200, 60, 60);
    // Each path up to where it leaves the view (plotters would pin it to the border).
    let inside = |&(x, y): &(f32, f32)| (-5.0..=6.0).contains(&x) && (-3.0..=4.0).contains(&y);
    for (i, p) in particle_paths.iter().enumerate() {
        let shown = p.iter().copied().take_while(inside);
        let s = chart.draw_series(LineSeries::new(shown, red.stroke_width(2)))?;
        if i == 0 {
            s.label("thrown particles' paths (no ground: they fall through y = 0)")
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], red.stroke_width(2)));
        }
    }
    chart
        .draw_series(std::iter::once(Circle::new(
            xy(&world, scene.rope.nodes[0]),
            5,
            BLACK.filled(),
        )))?
        .label("rope anchor (pinned)")
        .legend(|(x, y)| Circle::new((x + 9, y), 4, BLACK.filled()));
    legend(&mut chart)?;
    root.present()?;
    let d = world.resource::<PhysicsDiagnostics>();
    println!("wrote {path}; last step {:?}", d.step_time);
    Ok(())
}
