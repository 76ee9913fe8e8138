//! Issue 37: a stable Neo-Hookean body started at 1 % of its volume stayed crushed (its
//! energy had a local minimum at F = 0 without the −½ μ′ log(I_C + 1) term), and a
//! co-rotated one stepped explicitly (the defaults) rang through inversion for ever (mean
//! volume −0.01 of its rest volume, 191 of 384 elements inverted after 3 s); a stable
//! Neo-Hookean one started mirrored went non-finite. Crushed, flattened or mirrored through
//! its centre, a jelly now comes back to its volume under both models, at the defaults (a
//! body with inverted elements is solved by BDF2) and under implicit Euler.

use crate::common;

use glam::Vec3;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};

/// A 0.5 m jelly (E = 1e6, ν = 0.3) whose nodes start at `scale` times their distance from
/// its centre (negative: mirrored through it), in free fall: the volume ratio over its last
/// second (mean, lowest) and the inverted elements at the end, or None if quarantined.
fn release(model: StrainModel, scale: Vec3, implicit: bool) -> Option<(f32, f32, usize)> {
    let mut w = common::default_world();
    let mesh = TetMesh::cuboid(Vec3::splat(0.5), [4, 4, 4], CellSplit::Six).unwrap();
    let material = Material::new(1e6, 0.3, 1000.0).unwrap();
    let centre = Vec3::new(0.0, 10.0, 0.0);
    let (mut nodes, body) = SoftBody::build(&mesh, centre, material, model).unwrap();
    for i in 0..nodes.len() {
        let x = Vec3::from(nodes.positions()[i]);
        nodes
            .set_position(i, centre + scale * (x - centre))
            .unwrap();
    }
    let e = if implicit {
        w.spawn((nodes, body, ImplicitEuler::default())).id()
    } else {
        w.spawn((nodes, body)).id()
    };
    let (mut sum, mut lowest, mut count) = (0.0, f32::INFINITY, 0);
    for step in 0..180 {
        w.step_physics();
        w.get::<Quarantined>(e).is_none().then_some(())?;
        if step >= 120 {
            let ratio = w.get::<SoftBody>(e).unwrap().stats().volume_ratio;
            sum += ratio;
            lowest = lowest.min(ratio);
            count += 1;
        }
    }
    let inverted = w.get::<SoftBody>(e).unwrap().stats().inverted;
    Some((sum / count as f32, lowest, inverted))
}

#[test]
fn a_crushed_or_mirrored_jelly_comes_back_to_its_volume() {
    let crushed = Vec3::splat(0.2154);
    let flat = Vec3::new(1.0, 0.02, 1.0);
    let mirrored = Vec3::new(1.0, -1.0, 1.0);
    for model in [StrainModel::Corotated, StrainModel::StableNeoHookean] {
        for (name, scale) in [
            ("1 % volume", crushed),
            ("2 % height", flat),
            ("mirrored", mirrored),
        ] {
            for implicit in [false, true] {
                let outcome = release(model, scale, implicit);
                println!("{model:?} {name}, implicit {implicit}: {outcome:?}");
                let (mean, lowest, inverted) =
                    outcome.unwrap_or_else(|| panic!("{model:?} {name}: quarantined"));
                assert!(
                    (mean - 1.0).abs() < 0.01,
                    "{model:?} {name} {implicit}: {mean}"
                );
                assert!(lowest > 0.99, "{model:?} {name} {implicit}: {lowest}");
                assert_eq!(inverted, 0, "{model:?} {name} {implicit}");
            }
        }
    }
}
