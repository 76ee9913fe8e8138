//! The character controller at its defaults on the course of
//! `hooke::tools::character_scenes`, drawn from the side as a PNG.
//!
//! ```text
//! cargo run --release --example character -- [--seconds 10] [--out docs/character.png]
//! ```
//!
//! Two capsules walk +x at 1.5 m/s. On lane 1 one climbs six 18 cm stairs (step height
//! 25 cm), crosses the landing, walks down a 30° ramp snapped to it and pushes a 10 kg crate
//! along (at most 500 N). On lane 2 the other walks into a 60° ramp (maximum slope 45°) and
//! stays at its foot. The outlines are drawn every 0.5 s.

mod common;
use common::{axes, legend, register_fonts};

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::character::CharacterState;
use hooke::prelude::*;
use hooke::tools::character_scenes::{CharacterCourse, LANE_2};
use plotters::prelude::*;

/// The side silhouette (x, y) of a box rotated about z.
fn silhouette(half: Vec3, at: Vec3, q: Quat) -> Vec<(f32, f32)> {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(sx, sy)| {
            let p = at + q * Vec3::new(sx * half.x, sy * half.y, 0.0);
            (p.x, p.y)
        })
        .collect()
}

/// A capsule outline (x, y) about `centre`.
fn capsule(centre: Vec3, half: f32, r: f32) -> Vec<(f32, f32)> {
    let mut out = Vec::new();
    for i in 0..=16 {
        let a = std::f32::consts::PI * i as f32 / 16.0;
        out.push((centre.x + r * a.cos(), centre.y + half + r * a.sin()));
    }
    for i in 0..=16 {
        let a = std::f32::consts::PI * (1.0 + i as f32 / 16.0);
        out.push((centre.x + r * a.cos(), centre.y - half + r * a.sin()));
    }
    out.push(out[0]);
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let clip = common::clip_options(10.0, "docs/character.png")?;
    let (seconds, out) = (clip.seconds, clip.out);
    register_fonts()?;
    let course = CharacterCourse::default();
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(30.0, 0.5, 10.0)?,
        Position::from(Vec3::new(10.0, -0.5, 0.0)),
    ));
    let parts = course.spawn(&mut w)?;
    let dt = w.resource::<PhysicsTime>().dt();
    let steps = (seconds / dt).round() as usize;
    let mut paths = [Vec::new(), Vec::new()];
    let mut poses = [Vec::new(), Vec::new()];
    let mut crates = Vec::new();
    let (mut stepped, mut strongest) = (0, 0.0f32);
    for step in 0..=steps {
        if step > 0 {
            for who in parts.characters {
                w.get_mut::<CharacterInput>(who).unwrap().velocity = Vec3::new(1.5, 0.0, 0.0);
            }
            w.step_physics();
            let s = w.get::<CharacterState>(parts.characters[0]).unwrap();
            stepped += s.stepped as usize;
            let push: Vec3 = s.hits.iter().map(|h| h.impulse).sum();
            strongest = strongest.max(push.length() / dt);
        }
        for (lane, who) in parts.characters.iter().enumerate() {
            let x = w.get::<Position>(*who).unwrap().get();
            paths[lane].push((x.x, x.y));
            if step % ((0.5 / dt).round() as usize) == 0 {
                poses[lane].push(x);
                if lane == 0 {
                    let c = w.get::<Position>(parts.crate_).unwrap().get();
                    let q = w.get::<Rotation>(parts.crate_).unwrap().0;
                    crates.push((c, q));
                }
            }
        }
    }
    let ends: Vec<Vec3> = parts
        .characters
        .iter()
        .map(|e| w.get::<Position>(*e).unwrap().get())
        .collect();
    println!(
        "lane 1: end {:.3} (landing {:.2} m up at the top), stepped {stepped} times, pushed with at most {strongest:.0} N; crate at {:.3}",
        ends[0],
        course.landing_height(),
        w.get::<Position>(parts.crate_).unwrap().get()
    );
    println!(
        "lane 2: end {:.3}, the 60° ramp starts at x = {}",
        ends[1],
        course.wall_start()
    );

    let (x_range, y_range) = (-0.8f32..15.2f32, -0.4f32..3.0f32);
    // Equal scales: the plot area's pixels per metre are the same along x and y.
    let width = 1400u32;
    let (label_y, label_x, margin, caption) = (44u32, 36u32, 8u32, 24u32);
    let per_metre = (width - label_y - 2 * margin) as f32 / (x_range.end - x_range.start);
    let panel_h =
        (per_metre * (y_range.end - y_range.start)) as u32 + label_x + 2 * margin + caption;
    std::fs::create_dir_all(out.parent().unwrap_or(std::path::Path::new(".")))?;
    let root = BitMapBackend::new(&out, (width, 2 * panel_h + 34)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!("Character controller at the defaults: two capsules walking +x at 1.5 m/s for {seconds} s"),
        ("sans-serif", 20),
    )?;
    let panels = root.split_evenly((2, 1));
    let blocks = course.blocks();
    let (half, r) = course.capsule;
    for (lane, area) in panels.iter().enumerate() {
        let title = if lane == 0 {
            "lane 1 (z = 0): 18 cm stairs, landing, 30° ramp down, 10 kg crate"
        } else {
            "lane 2 (z = −3 m): a 60° ramp, steeper than the 45° maximum"
        };
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 15))
            .margin(margin)
            .x_label_area_size(label_x)
            .y_label_area_size(label_y)
            .build_cartesian_2d(x_range.clone(), y_range.clone())?;
        axes(&mut chart, "x (m)", "y (m)")?;
        chart.draw_series(std::iter::once(Rectangle::new(
            [(x_range.start, y_range.start), (x_range.end, 0.0)],
            RGBColor(200, 200, 200).filled(),
        )))?;
        let lane_z = if lane == 0 { 0.0 } else { LANE_2 };
        for b in blocks
            .iter()
            .filter(|b| (b.position.z - lane_z).abs() < 0.5)
        {
            chart.draw_series(std::iter::once(Polygon::new(
                silhouette(b.half, b.position, b.rotation),
                RGBColor(160, 160, 170).filled(),
            )))?;
        }
        if lane == 0 {
            for (i, (c, q)) in crates.iter().enumerate() {
                let shade = common::ramp(i as f32 / crates.len().max(1) as f32);
                let mut corners = silhouette(Vec3::splat(0.5), *c, *q);
                corners.push(corners[0]);
                let series =
                    chart.draw_series(std::iter::once(PathElement::new(corners, shade)))?;
                if i == 0 {
                    series
                        .label("crate every 0.5 s")
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], shade));
                }
            }
        }
        for (i, p) in poses[lane].iter().enumerate() {
            let shade = common::ramp(i as f32 / poses[lane].len().max(1) as f32);
            let series = chart.draw_series(std::iter::once(PathElement::new(
                capsule(*p, half, r),
                shade.stroke_width(1),
            )))?;
            if i == 0 {
                series
                    .label("capsule every 0.5 s (blue → orange)")
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], shade));
            }
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                paths[lane].clone(),
                BLACK.stroke_width(2),
            )))?
            .label("centre path")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(2)));
        legend(&mut chart)?;
    }
    root.present()?;
    println!("wrote {}", out.display());
    Ok(())
}
