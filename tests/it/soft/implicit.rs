//! Backward Euler for soft bodies: stability where explicit integration diverges, and the
//! cantilever's static deflection against beam theory, with its convergence under refinement.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

fn world(g: Vec3, dt: f32, substeps: u32) -> World {
    let mut w = scenes::world_with(dt, substeps, Integrator::SymplecticEuler, g).unwrap();
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    // These tests watch explicit integration itself: past its limit a body stays explicit
    // (the default policy would solve it by BDF2; see `soft::stable_at_the_defaults`).
    w.insert_resource(hooke::integrator::StabilityPolicy::Warn);
    w
}

/// A beam along x from 0 to `length`, its nodes at x = 0 pinned.
fn beam(
    length: f32,
    side: f32,
    cells: [usize; 3],
    material: Material,
    model: StrainModel,
) -> (Nodes, SoftBody) {
    scenes::pinned_beam(length, side, cells, material, model).unwrap()
}

fn max_speed(n: &Nodes) -> f32 {
    n.velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max)
}

#[test]
fn a_stiff_hanging_beam_is_stable_implicit_at_60_hz_and_diverges_explicit() {
    // E = 1e7 Pa, ρ = 1000 kg/m³: waves at 100 m/s cross a 5 cm element in 0.5 ms, so the
    // explicit step limit is about 0.3 ms, far below 1/60 s.
    let material = Material::new(1e7, 0.3, 1000.0).unwrap();
    for model in [StrainModel::Corotated, StrainModel::StableNeoHookean] {
        let mut w = world(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, 1);
        let (nodes, body) = beam(0.6, 0.1, [12, 2, 2], material, model);
        let e = w.spawn((nodes, body, ImplicitEuler::default())).id();
        let mut worst = 0.0f32;
        for _ in 0..600 {
            w.step_physics();
            worst = worst.max(max_speed(w.get::<Nodes>(e).unwrap()));
        }
        let n = w.get::<Nodes>(e).unwrap();
        assert!(w.get::<Quarantined>(e).is_none(), "{model:?}");
        assert!(n.is_finite());
        let stats = w.get::<SoftBody>(e).unwrap().stats();
        // Bounded, and at rest after 10 s (backward Euler damps).
        assert!(worst < 2.0, "{model:?} peak speed {worst} m/s");
        assert!(
            max_speed(n) < 1e-2,
            "{model:?} still moving at {}",
            max_speed(n)
        );
        assert_eq!(stats.inverted, 0);
        assert!(
            (stats.volume_ratio - 1.0).abs() < 0.01,
            "{}",
            stats.volume_ratio
        );
        println!(
            "{model:?}: peak speed {worst:.3} m/s, last substep {} Newton / {} CG iterations, residual {:.1e}",
            stats.implicit.newton_iterations, stats.implicit.cg_iterations, stats.implicit.residual
        );
    }
    // The same beam under symplectic Euler at the default 4 substeps: caught, not flying.
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, 4);
    let (nodes, body) = beam(0.6, 0.1, [12, 2, 2], material, StrainModel::Corotated);
    let e = w.spawn((nodes, body)).id();
    let mut caught = None;
    for step in 0..600 {
        w.step_physics();
        if w.get::<Quarantined>(e).is_some() {
            caught = Some(step);
            break;
        }
    }
    println!("explicit symplectic Euler, 4 substeps: quarantined at step {caught:?}");
    assert!(
        caught.is_some(),
        "explicit integration diverges and is quarantined"
    );
}

/// The static tip deflection (m) of a 1 m cantilever, 0.1 m square, E = 1e8, under 10 N.
fn cantilever(cells: [usize; 3]) -> f32 {
    // One backward-Euler step of 100 s is a static solve: M/h² vanishes beside K.
    let mut w = world(Vec3::ZERO, 100.0, 1);
    let settings = ImplicitEuler {
        tolerance: 1e-6,
        // Nearly linear: three Newton steps reach the f32 floor of the positions (see the
        // test below).
        max_newton: 3,
        max_cg: 5000,
        ..ImplicitEuler::default()
    };
    let beam = scenes::Cantilever::spawn(&mut w, cells, StrainModel::Corotated, settings).unwrap();
    w.step_physics();
    let r = w.get::<SoftBody>(beam.body).unwrap().stats().implicit;
    println!(
        "  static solve: {} Newton, {} CG iterations, gradient {:.1e} of the load's",
        r.newton_iterations, r.cg_iterations, r.residual
    );
    beam.deflection(&w).unwrap()
}

#[test]
fn the_cantilever_converges_to_beam_theory_under_refinement() {
    // F L³ / (3 E I) with I = a⁴/12: 10 / (3 · 1e8 · 8.333e-6) = 4.000 mm.
    let exact = 10.0 / (3.0 * 1e8 * (0.1f32.powi(4) / 12.0));
    let mut last = 0.0;
    let mut found: Vec<f32> = Vec::new();
    for cells in [[15, 3, 3], [30, 6, 6], [60, 12, 12]] {
        let d = cantilever(cells);
        println!(
            "cantilever {:?} cells ({} tets): tip {:.4} mm, {:.1}% of F L³/3EI = {:.4} mm",
            cells,
            6 * cells[0] * cells[1] * cells[2],
            d * 1e3,
            100.0 * d / exact,
            exact * 1e3
        );
        assert!(d > last, "refinement softens the locked linear tets");
        last = d;
        found.push(d);
    }
    // The error falls by about 4 per halving (second order in the cell size): Richardson's
    // extrapolation of the two finest meshes.
    let extrapolated = found[2] + (found[2] - found[1]) / 3.0;
    println!(
        "Richardson (h²): {:.4} mm, {:+.1}% (Timoshenko's shear term adds +0.6%)",
        extrapolated * 1e3,
        100.0 * (extrapolated / exact - 1.0)
    );
    assert!(
        (last / exact - 1.0).abs() < 0.05,
        "finest mesh: {last} vs {exact}"
    );
    assert!((extrapolated / exact - 1.0).abs() < 0.03, "{extrapolated}");
}

#[test]
fn newton_converges_on_a_large_soft_deformation() {
    // A soft, heavy beam pinned at one end sags by a large fraction of its length in one
    // step: the nonlinear case, where Newton must iterate (and f32 rounding is far below
    // the forces).
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), 1.0 / 30.0, 1);
    let material = Material::new(2e4, 0.3, 1000.0).unwrap();
    for model in [
        StrainModel::Corotated,
        StrainModel::StableNeoHookean,
        StrainModel::Green,
    ] {
        let (nodes, body) = beam(0.5, 0.1, [10, 2, 2], material, model);
        let e = w.spawn((nodes, body, ImplicitEuler::default())).id();
        let mut worst = 0.0f32;
        let mut iterations = 0;
        for _ in 0..30 {
            w.step_physics();
            let r = w.get::<SoftBody>(e).unwrap().stats().implicit;
            worst = worst.max(r.residual);
            iterations = iterations.max(r.newton_iterations);
        }
        println!(
            "{model:?}: worst final gradient {worst:.1e} of the first, at most {iterations} Newton iterations"
        );
        assert!(worst <= 5e-3, "{model:?}: {worst}");
        assert!(iterations <= 4, "{model:?}: {iterations} Newton iterations");
        assert!(w.get::<Quarantined>(e).is_none());
        w.entity_mut(e).despawn();
    }
}

/// A 0.5 m jelly cube (E = 1e7, 384 tets) dropped from 0.25 m onto the ground.
fn jelly(substeps: u32, implicit: bool) -> (World, Entity) {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, substeps);
    scenes::ground(&mut w).unwrap();
    let mesh = TetMesh::cuboid(Vec3::splat(0.5), [4, 4, 4], CellSplit::Six).unwrap();
    let material = Material::new(1e7, 0.3, 1000.0).unwrap();
    let (nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.0, 0.5, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let e = if implicit {
        w.spawn((nodes, body, ImplicitEuler::default())).id()
    } else {
        w.spawn((nodes, body)).id()
    };
    (w, e)
}

#[test]
fn a_stiff_jelly_cube_lands_and_rests_at_60_hz_with_one_implicit_substep() {
    let (mut w, e) = jelly(1, true);
    let mut peak = 0.0f32;
    for _ in 0..300 {
        w.step_physics();
        peak = peak.max(max_speed(w.get::<Nodes>(e).unwrap()));
    }
    assert!(w.get::<Quarantined>(e).is_none());
    let n = w.get::<Nodes>(e).unwrap();
    let lowest = n
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    let highest = n
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f32::NEG_INFINITY, f32::max);
    println!(
        "implicit x1: peak speed {peak:.2} m/s, rests with bottom at {lowest:.4} m, top at {highest:.4} m"
    );
    // It fell 0.25 m: at most √(2 g h) = 2.2 m/s, and nothing gained after.
    assert!(peak < 2.5, "bounded: {peak}");
    assert!((lowest - 0.005).abs() < 0.01, "on the ground: {lowest}");
    assert!((highest - 0.505).abs() < 0.02, "its height kept: {highest}");
    assert!(max_speed(n) < 0.05, "at rest: {}", max_speed(n));
    let stats = w.get::<SoftBody>(e).unwrap().stats();
    assert_eq!(stats.inverted, 0);

    // Explicit symplectic Euler: the substeps the same drop needs to stay finite.
    let mut needed = None;
    for substeps in [4, 8, 16, 32, 64] {
        let (mut w, e) = jelly(substeps, false);
        let mut peak = 0.0f32;
        for _ in 0..120 {
            w.step_physics();
            if w.get::<Quarantined>(e).is_some() {
                peak = f32::INFINITY;
                break;
            }
            peak = peak.max(max_speed(w.get::<Nodes>(e).unwrap()));
        }
        println!("symplectic Euler x{substeps}: peak node speed {peak:.2} m/s");
        if peak.is_finite() && needed.is_none() {
            needed = Some(substeps);
        }
    }
    println!("explicit needs {needed:?} substeps at 60 Hz to stay finite");
    // Diverged and quarantined at the default 4 substeps; finite from 32. (Its peak node
    // speed then exceeds the fall's 2.2 m/s: the contact projection kicks the stiff bottom
    // layer, which the implicit solve avoids by holding contact nodes in the solve.)
    assert_eq!(needed, Some(32));
}

#[test]
fn targeted_nodes_carry_the_body_and_let_go() {
    use hooke::soft::NodeTargets;
    for implicit in [true, false] {
        let substeps = if implicit { 1 } else { 16 };
        let mut w = world(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, substeps);
        let material = Material::new(2e4, 0.3, 500.0).unwrap();
        let mesh = TetMesh::cuboid(Vec3::new(0.4, 0.1, 0.1), [4, 1, 1], CellSplit::Six).unwrap();
        let (nodes, body) = SoftBody::build(
            &mesh,
            Vec3::new(0.2, 1.0, 0.0),
            material,
            StrainModel::Corotated,
        )
        .unwrap();
        let grip: Vec<usize> = (0..nodes.len())
            .filter(|&i| nodes.positions()[i].x.abs() < 1e-5)
            .collect();
        let start: Vec<Vec3> = grip
            .iter()
            .map(|&i| Vec3::from(nodes.positions()[i]))
            .collect();
        let targets = NodeTargets::new(grip.iter().copied().zip(start.iter().copied())).unwrap();
        let e = if implicit {
            w.spawn((nodes, body, targets, ImplicitEuler::default()))
                .id()
        } else {
            w.spawn((nodes, body, targets)).id()
        };
        // Carry the grip 1 m along x in 1 s.
        for step in 1..=60 {
            let shift = Vec3::X * (step as f32 / 60.0);
            let mut t = w.get_mut::<NodeTargets>(e).unwrap();
            for (&i, p) in grip.iter().zip(&start) {
                t.set(i, *p + shift).unwrap();
            }
            w.step_physics();
        }
        let n = w.get::<Nodes>(e).unwrap();
        for (&i, p) in grip.iter().zip(&start) {
            let x = Vec3::from(n.positions()[i]);
            assert!(
                (x - (*p + Vec3::X)).length() < 1e-4,
                "implicit {implicit}: grip at {x}"
            );
        }
        let far = n.positions().iter().map(|p| p.x).fold(f32::MIN, f32::max);
        assert!(
            far > 1.2,
            "implicit {implicit}: the body came along ({far})"
        );
        // Let go: the grip gets its mass back and everything falls.
        w.entity_mut(e).remove::<NodeTargets>();
        assert!(
            w.get::<Nodes>(e)
                .unwrap()
                .mass(grip[0])
                .unwrap()
                .is_finite()
        );
        let y0 = w.get::<Nodes>(e).unwrap().positions()[grip[0]].y;
        for _ in 0..30 {
            w.step_physics();
        }
        let y1 = w.get::<Nodes>(e).unwrap().positions()[grip[0]].y;
        assert!(
            y1 < y0 - 0.5,
            "implicit {implicit}: released grip falls ({y0} -> {y1})"
        );
        assert!(w.get::<Quarantined>(e).is_none());
    }
}
