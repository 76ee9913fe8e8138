//! Regression: the first rope defaults (0.1 kg nodes, k = 2000 N/m) were unstable for
//! symplectic Euler at the default 60 Hz step (ω_max h ≈ 4.7 > 2) and blew up. Defaults must
//! be stable at the default step; the cloth, with 2 substeps as documented.

use hooke::prelude::*;
use hooke::tools::scenes;

#[test]
fn rope_and_hair_defaults_are_stable_at_60_hz_one_substep() {
    let mut world = scenes::world_with(
        1.0 / 60.0,
        1,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let rope = ChainBuilder::rope(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), 20)
        .spawn(&mut world)
        .unwrap();
    let hair = ChainBuilder::hair(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.5, -0.2, 1.0), 12)
        .spawn(&mut world)
        .unwrap();
    for _ in 0..600 {
        world.step_physics();
    }
    // Static stretch of the rope under its own weight: Σ_i i m g / k over 19 free nodes.
    let stretch = (1..20).map(|i| i as f32 * 0.1 * 9.81 / 150.0).sum::<f32>();
    for &n in rope.nodes.iter().chain(&hair.nodes) {
        assert!(world.get::<Quarantined>(n).is_none());
        let p = world.get::<Position>(n).unwrap().get();
        assert!(p.length() < 1.5 * (2.0 + stretch), "{p}");
        // Energy bound: no node can be faster than a fall through the rope's whole reach.
        let v = world.get::<LinearVelocity>(n).unwrap().get();
        let v_max = (2.0 * 9.81 * 1.5 * (2.0 + stretch)).sqrt();
        assert!(v.length() < v_max, "{v} faster than {v_max} m/s");
    }
}

#[test]
fn cloth_defaults_are_stable_at_60_hz_two_substeps() {
    let mut world = scenes::world_with(
        1.0 / 60.0,
        2,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let cloth = ClothBuilder::new(Vec3::ZERO, 20, 20, 0.05)
        .spawn(&mut world)
        .unwrap();
    for _ in 0..600 {
        world.step_physics();
    }
    let nodes = world.get::<Nodes>(cloth).unwrap();
    assert!(world.get::<Quarantined>(cloth).is_none());
    assert!(nodes.is_finite());
    // Soft by design (k = 8 N/m): it drapes far, but it must not run away.
    assert!(nodes.positions().iter().all(|p| p.length() < 20.0));
    assert!(nodes.velocities().iter().all(|v| v.length() < 10.0));
}
