//! Boxes and balls falling onto a ramp and the ground. Writes `out/pile.gif`, a side view
//! (x–y) of 5 s at 60 Hz, one frame every 4 steps.
//!
//! ```text
//! cargo run --release --example pile
//! ```

mod common;

use std::path::Path;

use bevy_ecs::prelude::*;
use common::{Canvas, Gif};
use hooke::prelude::*;
use hooke::{Contacts, Rotation, scenes};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = scenes::world_with(
        1.0 / 60.0,
        4,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )?;
    let (boxes, balls) = scenes::pile_scene(&mut world, 60, 30)?;
    let (width, height) = (480, 320);
    let mut canvas = Canvas::new(width, height, [-9.0, -0.5, 7.0, 10.2], [250, 250, 250]);
    let mut gif = Gif::new(width, height);
    let ramp_q = glam::Quat::from_rotation_z(20f32.to_radians());
    let edges = [
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
    let corners = |x: Vec3, q: glam::Quat, h: Vec3| -> Vec<(f32, f32)> {
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
    };
    for step in 0..=300 {
        if step > 0 {
            world.step_physics();
        }
        if step % 4 != 0 {
            continue;
        }
        canvas.clear([250, 250, 250]);
        canvas.line((-9.0, 0.0), (7.0, 0.0), 3, [102, 102, 102]);
        let ramp = corners(Vec3::new(-3.0, 1.5, 0.0), ramp_q, Vec3::new(4.0, 0.2, 2.0));
        for (a, b) in edges {
            canvas.line(ramp[a], ramp[b], 2, [102, 102, 102]);
        }
        for &e in &boxes {
            let x = world.get::<Position>(e).unwrap().get();
            let q = world.get::<Rotation>(e).unwrap().0;
            let c = corners(x, q, Vec3::new(0.35, 0.25, 0.3));
            for (a, b) in edges {
                canvas.line(c[a], c[b], 1, [0, 51, 204]);
            }
        }
        for &e in &balls {
            let x = world.get::<Position>(e).unwrap().get();
            canvas.dot(x.x, x.y, 9, [204, 51, 0]);
        }
        gif.frame(&canvas, 7);
        if step % 60 == 0 {
            let asleep = world
                .query_filtered::<(), With<hooke::Sleeping>>()
                .iter(&world)
                .count();
            let d = world.resource::<PhysicsDiagnostics>();
            println!(
                "t = {:.0} s: {} touching pairs, {} asleep, kinetic {:.1} J, step {:?}",
                step as f32 / 60.0,
                world.resource::<Contacts>().touching_count(),
                asleep,
                d.kinetic_energy,
                d.step_time
            );
        }
    }
    let path = Path::new("out/pile.gif");
    gif.save(path)?;
    println!(
        "wrote {} (side view: boxes blue, balls red, ramp and ground grey)",
        path.display()
    );
    Ok(())
}
