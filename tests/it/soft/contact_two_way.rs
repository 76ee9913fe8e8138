//! Soft bodies against dynamic rigid bodies, two-way: the body feels the nodes. Closed forms:
//! a soft cube resting on a weightless floating platform drags it down at a = m g / (m + M);
//! a soft ball thrown at a free box in zero gravity keeps the pair's momentum.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::collision::Collider;
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::particles::GravityScale;
use hooke::prelude::*;
use hooke::rigid::RigidBody;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

fn world(g: Vec3, substeps: u32) -> World {
    let mut w = scenes::world_with(1.0 / 60.0, substeps, Integrator::SymplecticEuler, g).unwrap();
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    w
}

fn soft_mass(n: &Nodes) -> f32 {
    (0..n.len()).map(|i| n.mass(i).unwrap()).sum()
}

/// A 0.3 m soft cube sitting on a 1 m × 0.1 m × 1 m platform that gravity does not pull.
fn platform_scene(implicit: bool) -> (World, Entity, Entity, f32, f32) {
    let (young, substeps) = if implicit { (1e6, 1) } else { (1e5, 8) };
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), substeps);
    let platform_kg = 5.0;
    let platform = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.05, 0.5).unwrap(),
            Mass::new(platform_kg).unwrap(),
            hooke::rigid::Inertia::diagonal(0.42, 0.83, 0.42).unwrap(),
            Position::from(Vec3::ZERO),
            GravityScale(0.0),
        ))
        .id();
    let mesh = TetMesh::cuboid(Vec3::splat(0.3), [3, 3, 3], CellSplit::Six).unwrap();
    let material = Material::new(young, 0.3, 200.0).unwrap();
    // Its bottom 1 mm above the platform's contact layer (5 mm).
    let (nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.0, 0.05 + 0.006 + 0.15, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    let m = soft_mass(&nodes);
    let mut e = w.spawn((nodes, body));
    if implicit {
        e.insert(ImplicitEuler::default());
    }
    let soft = e.id();
    (w, platform, soft, m, platform_kg)
}

#[test]
fn a_soft_cube_on_a_floating_platform_drags_it_down_at_m_g_over_the_total_mass() {
    for implicit in [true, false] {
        let (mut w, platform, soft, m, big_m) = platform_scene(implicit);
        // Let the landing settle, then measure the platform's acceleration over 0.75 s.
        for _ in 0..15 {
            w.step_physics();
        }
        let v0 = w.get::<LinearVelocity>(platform).unwrap().0.y;
        for _ in 0..45 {
            w.step_physics();
        }
        let v1 = w.get::<LinearVelocity>(platform).unwrap().0.y;
        assert!(w.get::<Quarantined>(soft).is_none());
        let expected = -0.75 * m * 9.81 / (m + big_m);
        let measured = v1 - v0;
        // The cube rides on the platform: their speeds agree.
        let n = w.get::<Nodes>(soft).unwrap();
        let cube_v = n.velocities().iter().map(|v| v.y).sum::<f32>() / n.len() as f32;
        let top = w.get::<Position>(platform).unwrap().0.y + 0.05;
        let lowest = n.bounds().map_or(f32::INFINITY, |b| b.0.y);
        println!(
            "implicit {implicit}: platform Δv over 0.75 s {measured:.4} m/s (closed form {expected:.4}); cube {cube_v:.3} m/s, platform {v1:.3} m/s; cube bottom {:.1} mm above the platform",
            1e3 * (lowest - top)
        );
        assert!(
            (measured / expected - 1.0).abs() < 0.05,
            "{measured} vs {expected}"
        );
        // The platform's velocity leads by one substep's a h: it takes the impulses after it
        // moved, and moves by them in the next substep.
        let lead = expected.abs() / 0.75 / 60.0;
        assert!(
            (cube_v - v1).abs() < lead + 0.02,
            "rides along: {cube_v} vs {v1}"
        );
        assert!(lowest - top > 0.0 && lowest - top < 0.01, "resting on it");
        // Pressed evenly, the light platform barely tips in this second; it does tip over
        // longer runs (see the module docs of `soft::contact`).
        let tilt = w
            .get::<hooke::rigid::Rotation>(platform)
            .unwrap()
            .0
            .angle_between(glam::Quat::IDENTITY);
        assert!(tilt.to_degrees() < 2.0, "tilted {}°", tilt.to_degrees());
    }
}

#[test]
fn a_soft_ball_thrown_at_a_free_box_keeps_the_momentum_of_the_pair() {
    for implicit in [true, false] {
        let mut w = world(Vec3::ZERO, if implicit { 1 } else { 8 });
        let big_m = 4.0;
        let b = w
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
                Mass::new(big_m).unwrap(),
                hooke::rigid::Inertia::diagonal(0.107, 0.107, 0.107).unwrap(),
                Position::from(Vec3::new(1.0, 0.05, 0.0)),
            ))
            .id();
        let mesh = TetMesh::ball(0.15, 4).unwrap();
        let material = Material::new(if implicit { 1e6 } else { 1e5 }, 0.3, 300.0).unwrap();
        let (mut nodes, body) =
            SoftBody::build(&mesh, Vec3::ZERO, material, StrainModel::Corotated).unwrap();
        for i in 0..nodes.len() {
            nodes.set_velocity(i, Vec3::new(2.0, 0.0, 0.0)).unwrap();
        }
        let m = soft_mass(&nodes);
        let mut e = w.spawn((nodes, body));
        if implicit {
            e.insert(ImplicitEuler::default());
        }
        let soft = e.id();
        let momentum = |w: &World| {
            let n = w.get::<Nodes>(soft).unwrap();
            let p: Vec3 = (0..n.len())
                .map(|i| n.mass(i).unwrap() * Vec3::from(n.velocities()[i]))
                .sum();
            p + big_m * Vec3::from(w.get::<LinearVelocity>(b).unwrap().0)
        };
        let p0 = momentum(&w);
        for _ in 0..60 {
            w.step_physics();
        }
        let p1 = momentum(&w);
        let box_v = w.get::<LinearVelocity>(b).unwrap().0;
        assert!(w.get::<Quarantined>(soft).is_none());
        println!(
            "implicit {implicit}: P {p0} -> {p1}; box {box_v} m/s (ball {m:.2} kg, box {big_m} kg)"
        );
        assert!(box_v.x > 0.2, "the box was hit: {box_v}");
        assert!((p1 - p0).length() < 2e-3 * p0.length(), "P: {p0} -> {p1}");
        // No more than an elastic hit could give it: 2 m v / (m + M).
        assert!(box_v.x <= 2.0 * m * 2.0 / (m + big_m) + 1e-3, "{box_v}");
    }
}

/// A stiff jelly (E = 1e7, 27 kg) dropped on a 10 kg crate that stands on the ground: it
/// lands and rests on it within 1.25 s, the crate pressed onto the ground by the jelly's
/// weight, not through it, and the crate reads at rest. (It creeps sideways on so light a
/// crate, printed here; see the module docs of `soft::contact`.)
#[test]
fn a_jelly_dropped_on_a_crate_on_the_ground_comes_to_rest_on_it() {
    // Implicit only: explicitly integrated (E = 2e5, 16 substeps) the same drop peaks at
    // 4.6 m/s at landing, above the 2.4 m/s of the fall (see the module docs of
    // `soft::contact`).
    for implicit in [true] {
        let mut w = world(Vec3::new(0.0, -9.81, 0.0), if implicit { 1 } else { 16 });
        scenes::ground(&mut w).unwrap();
        let crate_ = w
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.4, 0.2, 0.4).unwrap(),
                Mass::new(10.0).unwrap(),
                hooke::rigid::Inertia::diagonal(0.67, 1.07, 0.67).unwrap(),
                Position::from(Vec3::new(0.0, 0.2, 0.0)),
            ))
            .id();
        let mesh = TetMesh::cuboid(Vec3::splat(0.3), [3, 3, 3], CellSplit::Six).unwrap();
        let young = if implicit { 1e7 } else { 2e5 };
        let material = Material::new(young, 0.3, 1000.0).unwrap();
        let (nodes, body) = SoftBody::build(
            &mesh,
            Vec3::new(0.0, 0.4 + 0.3 + 0.15, 0.0),
            material,
            StrainModel::Corotated,
        )
        .unwrap();
        let mut e = w.spawn((nodes, body));
        if implicit {
            e.insert(ImplicitEuler::default());
        }
        let soft = e.id();
        let mut peak = 0.0f32;
        for _ in 0..75 {
            w.step_physics();
            let n = w.get::<Nodes>(soft).unwrap();

            peak = peak.max(n.max_speed());
        }
        assert!(w.get::<Quarantined>(soft).is_none());
        let crate_y = w.get::<Position>(crate_).unwrap().0.y;
        let crate_v = w.get::<LinearVelocity>(crate_).unwrap().0.length();
        let n = w.get::<Nodes>(soft).unwrap();
        let lowest = n.bounds().map_or(f32::INFINITY, |b| b.0.y);
        let speed = n.max_speed();
        let creep = n.positions().iter().map(|p| p.x).sum::<f32>() / n.len() as f32;
        println!(
            "implicit {implicit}: crate at {crate_y:.4} m (v {crate_v:.1e}), jelly bottom {:.1} mm above the crate, peak {peak:.2} m/s, now {speed:.1e} m/s, crept {:.1} mm sideways",
            1e3 * (lowest - (crate_y + 0.2)),
            1e3 * creep
        );
        // It fell 0.3 m: at most √(2 g h) = 2.4 m/s.
        assert!(peak < 2.6, "{peak}");
        assert!(
            (crate_y - 0.2).abs() < 0.01,
            "the crate stays on the ground: {crate_y}"
        );
        assert!(crate_v < 0.05, "{crate_v}");
        assert!(speed < 0.25, "the jelly rests: {speed}");
        assert!(
            (lowest - (crate_y + 0.2)).abs() < 0.01,
            "on the crate: {lowest}"
        );
    }
}

#[test]
fn a_soft_body_stepped_on_its_own_is_solved_by_bdf2_once_it_presses_on_a_dynamic_body() {
    // At 8 substeps the E = 1e5 cube is past its (safe) limit: the policy steps it 3 times
    // per substep on its own while it falls, and solves it by BDF2 once it lands on the
    // platform, whose impulses it takes once per substep (with local steps in between the
    // cube would sink 0.7 mm into it).
    let (mut w, _, soft, _, _) = platform_scene(false);
    w.step_physics();
    assert_eq!(
        w.get::<hooke::integrator::LocalSubsteps>(soft)
            .map(|l| l.count()),
        Some(3)
    );
    for _ in 0..15 {
        w.step_physics();
    }
    assert!(w.get::<hooke::integrator::LocalSubsteps>(soft).is_none());
    assert_eq!(
        w.get::<ImplicitEuler>(soft).map(|s| s.scheme),
        Some(hooke::integrator::ImplicitScheme::Bdf2)
    );
}
