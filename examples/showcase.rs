//! The README demo: a swinging rope, a hair strand, tracers in a vortex and thrown
//! particles, stepped headless for 5 s. Prints one summary line per simulated second and
//! writes `out/showcase.png` (trajectories and rope snapshots).
//!
//! ```text
//! cargo run --release --example showcase
//! ```

mod common;

use std::path::Path;

use bevy_ecs::prelude::*;
use common::{Canvas, ramp};
use hooke::prelude::*;
use hooke::scenes;

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

    let mut canvas = Canvas::new(1100, 700, [-5.0, -3.0, 6.0, 4.0], [250, 250, 248]);
    let mut particle_paths: Vec<Vec<(f32, f32)>> = vec![Vec::new(); scene.particles.len()];
    let mut tracer_paths: Vec<Vec<(f32, f32)>> = vec![Vec::new(); scene.tracers.len()];
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
            // A snapshot of the rope and the hair every half second, blue to orange.
            let t = step as f32 / (seconds * 60) as f32;
            let rope: Vec<_> = scene.rope.nodes.iter().map(|&e| xy(&world, e)).collect();
            let hair: Vec<_> = scene.hair.nodes.iter().map(|&e| xy(&world, e)).collect();
            canvas.polyline(&rope, 2, ramp(t));
            canvas.polyline(&hair, 1, ramp(t));
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
    for path in &tracer_paths {
        canvas.polyline(path, 1, [120, 170, 120]);
    }
    for path in &particle_paths {
        canvas.polyline(path, 2, [200, 60, 60]);
    }
    for &e in &scene.particles {
        let (x, y) = xy(&world, e);
        canvas.dot(x, y, 4, [150, 20, 20]);
    }
    // Ground line at y = 0 and the rope's anchor.
    canvas.line((-5.0, 0.0), (6.0, 0.0), 1, [180, 180, 180]);
    let (ax, ay) = xy(&world, scene.rope.nodes[0]);
    canvas.dot(ax, ay, 5, [0, 0, 0]);
    let path = Path::new("out/showcase.png");
    canvas.save_png(path)?;
    let d = world.resource::<PhysicsDiagnostics>();
    println!(
        "wrote {} (rope and hair snapshots blue→orange every 0.5 s, particle paths red, tracers green); last step {:?}",
        path.display(),
        d.step_time
    );
    Ok(())
}
