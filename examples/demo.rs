//! The whole of hooke in one scene, at the defaults (`PhysicsPlugins` and nothing else but
//! an implicit jelly): a stack of crates hit by a tumbling box, a rope, a cloth hanging from
//! two corners, a jelly cube and tracers in a vortex. Steps 1.5 s headless and writes
//! `out/demo.png`: a 3D perspective view, faces shaded by a light from above, equal scales
//! on the three axes (metres).
//!
//! ```text
//! cargo run --release --example demo
//! ```

mod common;

use bevy_ecs::prelude::*;
use common::{legend, register_fonts};
use hooke::cloth::Cloth;
use hooke::particles::{Nodes, Tracer};
use hooke::prelude::*;
use hooke::soft::{CellSplit, TetMesh};
use hooke::tools::scenes;
use plotters::prelude::*;

/// A shaded face: its corners, its base colour, and whether both sides are seen (cloth).
struct Face {
    corners: Vec<Vec3>,
    color: RGBColor,
    two_sided: bool,
}

const LIGHT: Vec3 = Vec3::new(0.35, 1.0, 0.45);
/// Larger is farther from the camera, as plotters projects (its depth of backend pixels).
const FAR: f32 = 1.0;
const YAW: f64 = 0.65;
const PITCH: f64 = 0.45;

fn shade(face: &Face) -> RGBColor {
    let c = &face.corners;
    let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
    let l = LIGHT.normalize();
    let lit = if face.two_sided {
        n.dot(l).abs()
    } else {
        n.dot(l).max(0.0)
    };
    let k = 0.45 + 0.55 * lit;
    let RGBColor(r, g, b) = face.color;
    RGBColor(
        (f32::from(r) * k) as u8,
        (f32::from(g) * k) as u8,
        (f32::from(b) * k) as u8,
    )
}

fn box_faces(world: &World, e: Entity, half: Vec3, color: RGBColor, out: &mut Vec<Face>) {
    let x = world.get::<Position>(e).unwrap().get();
    let q = world.get::<Rotation>(e).map_or(Quat::IDENTITY, |r| r.0);
    let corner = |s: [f32; 3]| x + q * (half * Vec3::from(s));
    // Each face counter-clockwise seen from outside, so its normal points out.
    let quads = [
        [[1., -1., -1.], [1., 1., -1.], [1., 1., 1.], [1., -1., 1.]],
        [
            [-1., -1., -1.],
            [-1., -1., 1.],
            [-1., 1., 1.],
            [-1., 1., -1.],
        ],
        [[-1., 1., -1.], [-1., 1., 1.], [1., 1., 1.], [1., 1., -1.]],
        [
            [-1., -1., -1.],
            [1., -1., -1.],
            [1., -1., 1.],
            [-1., -1., 1.],
        ],
        [[-1., -1., 1.], [1., -1., 1.], [1., 1., 1.], [-1., 1., 1.]],
        [
            [-1., -1., -1.],
            [-1., 1., -1.],
            [1., 1., -1.],
            [1., -1., -1.],
        ],
    ];
    for quad in quads {
        out.push(Face {
            corners: quad.iter().map(|&s| corner(s)).collect(),
            color,
            two_sided: false,
        });
    }
}

fn mesh_faces(nodes: &Nodes, tris: &[[u32; 3]], color: RGBColor, two_sided: bool) -> Vec<Face> {
    let x = nodes.positions();
    tris.iter()
        .map(|t| Face {
            corners: t.iter().map(|&i| Vec3::from(x[i as usize])).collect(),
            color,
            two_sided,
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::ground(&mut world)?;
    // A stack of four crates, and a box thrown at it, tumbling.
    let crate_half = Vec3::splat(0.25);
    let mut boxes = Vec::new();
    for k in 0..4 {
        let at = Vec3::new(-1.6, 0.25 + 0.5 * k as f32, -0.6);
        boxes.push((scenes::dynamic_box(&mut world, crate_half, at)?, crate_half));
    }
    let thrown_half = Vec3::new(0.2, 0.15, 0.1);
    let thrown = scenes::dynamic_box(&mut world, thrown_half, Vec3::new(-3.6, 1.4, -0.6))?;
    world.get_mut::<LinearVelocity>(thrown).unwrap().0 = Vec3::new(5.0, 1.5, 0.0).into();
    world.get_mut::<AngularVelocity>(thrown).unwrap().0 = Vec3::new(3.0, 6.0, 2.0).into();
    boxes.push((thrown, thrown_half));
    // A rope pinned at its start; a cloth pinned at two corners; a jelly; tracers.
    let rope = ChainBuilder::rope(Vec3::new(0.4, 2.8, -2.2), Vec3::new(2.0, 2.8, -2.2), 17)
        .spawn(&mut world)?;
    let cloth = ClothBuilder::new(Vec3::new(-0.4, 2.2, -0.9), 15, 15, 0.1).spawn(&mut world)?;
    let jelly = scenes::jelly(&mut world, Vec3::new(1.6, 0.9, 1.2), true)?;
    let jelly_surface = TetMesh::cuboid(Vec3::splat(0.4), [3, 3, 3], CellSplit::Six)?.surface();
    let centre = Vec3::new(-1.2, 3.0, 2.2);
    world.spawn(VelocityField::vortex(centre, Vec3::Y, 1.5)?);
    let tracers: Vec<Entity> = (0..36)
        .map(|i| {
            let (r, a) = (0.3 + 0.02 * i as f32, i as f32 * 0.9);
            let x = centre + Vec3::new(r * a.cos(), 0.02 * i as f32 - 0.3, r * a.sin());
            Ok(world.spawn((Position::try_new(x)?, Tracer)).id())
        })
        .collect::<Result<_, hooke::Error>>()?;
    let mut tracer_paths: Vec<Vec<Vec3>> = vec![Vec::new(); tracers.len()];
    let steps = 90;
    for _ in 0..steps {
        world.step_physics();
        for (path, &e) in tracer_paths.iter_mut().zip(&tracers) {
            path.push(world.get::<Position>(e).unwrap().get());
        }
    }
    let quarantined = world.query::<&Quarantined>().iter(&world).count();
    println!("1.5 s at 60 Hz, 4 substeps: {quarantined} bodies quarantined");

    // Faces, far to near (the painter's order).
    let mut faces = Vec::new();
    for &(e, half) in &boxes {
        let color = if e == thrown {
            RGBColor(220, 90, 40)
        } else {
            RGBColor(200, 160, 90)
        };
        box_faces(&world, e, half, color, &mut faces);
    }
    let c = world.get::<Cloth>(cloth).unwrap();
    let n = world.get::<Nodes>(cloth).unwrap();
    faces.extend(mesh_faces(n, c.triangles(), RGBColor(70, 120, 220), true));
    let n = world.get::<Nodes>(jelly).unwrap();
    faces.extend(mesh_faces(n, &jelly_surface, RGBColor(80, 190, 90), false));
    std::fs::create_dir_all("out")?;
    register_fonts()?;
    let root = BitMapBackend::new("out/demo.png", (1100, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        "hooke at the defaults, t = 1.5 s: crates, a tumbling box, rope, cloth, jelly, tracers",
        ("sans-serif", 20),
    )?;
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .caption(
            "x, y (up) and z in metres, equal scales",
            ("sans-serif", 14),
        )
        .build_cartesian_3d(-3.2f32..3.2, 0.0f32..6.4, -3.2f32..3.2)?;
    chart.with_projection(|mut p| {
        p.yaw = YAW;
        p.pitch = PITCH;
        p.scale = 0.95;
        p.into_matrix()
    });
    // The painter's order: far faces first; closed bodies' faces turned away are dropped.
    let spec = chart.as_coord_spec();
    let depth = |p: Vec3| FAR * spec.projected_depth(&p.x, &p.y, &p.z) as f32;
    let mean = |f: &Face| f.corners.iter().map(|&p| depth(p)).sum::<f32>() / f.corners.len() as f32;
    faces.retain(|f| {
        let c = &f.corners;
        let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
        f.two_sided || depth(c[0] + 0.3 * n) <= depth(c[0])
    });
    faces.sort_by(|a, b| mean(b).total_cmp(&mean(a)));
    chart
        .configure_axes()
        .label_style(("sans-serif", 11))
        .light_grid_style(RGBColor(235, 235, 235))
        .max_light_lines(3)
        .draw()?;
    // The ground at y = 0.
    chart.draw_series(std::iter::once(Polygon::new(
        vec![
            (-3.2, 0.0, -3.2),
            (3.2, 0.0, -3.2),
            (3.2, 0.0, 3.2),
            (-3.2, 0.0, 3.2),
        ],
        RGBColor(225, 225, 215).filled(),
    )))?;
    for f in &faces {
        let pts: Vec<(f32, f32, f32)> = f.corners.iter().map(|p| (p.x, p.y, p.z)).collect();
        chart.draw_series(std::iter::once(Polygon::new(
            pts.clone(),
            shade(f).filled(),
        )))?;
        if !f.two_sided {
            // Edges of solid bodies, so that touching crates read as separate boxes.
            let mut ring = pts;
            ring.push(ring[0]);
            chart.draw_series(std::iter::once(PathElement::new(
                ring,
                RGBColor(60, 50, 40),
            )))?;
        }
    }
    let rope_points: Vec<(f32, f32, f32)> = rope
        .nodes
        .iter()
        .map(|&e| {
            let p = world.get::<Position>(e).unwrap().get();
            (p.x, p.y, p.z)
        })
        .collect();
    chart
        .draw_series(LineSeries::new(rope_points, BLACK.stroke_width(3)))?
        .label("rope (pinned at its first node)")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], BLACK.stroke_width(3)));
    for (i, path) in tracer_paths.iter().enumerate() {
        let series = chart.draw_series(LineSeries::new(
            path.iter().map(|p| (p.x, p.y, p.z)),
            RGBColor(150, 70, 180).stroke_width(1),
        ))?;
        if i == 0 {
            series
                .label("tracers in a vortex (paths)")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 18, y)], RGBColor(150, 70, 180)));
        }
    }
    for (label, color) in [
        ("crates (stack)", RGBColor(200, 160, 90)),
        ("thrown box", RGBColor(220, 90, 40)),
        ("cloth, pinned at two corners", RGBColor(70, 120, 220)),
        ("jelly (co-rotated FEM, implicit)", RGBColor(80, 190, 90)),
    ] {
        chart
            .draw_series(std::iter::empty::<Circle<(f32, f32, f32), i32>>())?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], color.filled()));
    }
    legend(&mut chart)?;
    root.present()?;
    println!("wrote out/demo.png");
    Ok(())
}
