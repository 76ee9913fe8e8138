//! Local substeps (`LocalSubsteps`), the default policy's rescue for a spring system that
//! needs a few more substeps than the world's: the system alone is stepped n times per
//! substep by the world's own scheme. Spring meshes and entity springs, against the same
//! system stepped by world substeps, closed forms, and the validation of the count.

use crate::common;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::integrator::{
    ImplicitEuler, ImplicitScheme, LocalSubsteps, Rescue, StabilityPolicy, StabilityWarning,
};
use hooke::prelude::*;

fn told(w: &World) -> Vec<StabilityWarning> {
    let m = w.resource::<Messages<StabilityWarning>>();
    m.get_cursor().read(m).cloned().collect()
}

/// A pendulum built as a mesh: a pinned node at the origin and a 1 kg node 1 m away level
/// with it, joined by a spring of stiffness `k`.
fn mesh_pendulum(w: &mut World, k: f32) -> Entity {
    let mut nodes = Nodes::new();
    nodes.push_pinned(Vec3::ZERO).unwrap();
    nodes.push(Vec3::X, Vec3::ZERO, 1.0).unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 1, 1.0, k, 0.0).unwrap();
    w.spawn((nodes, net)).id()
}

fn bob(w: &World, mesh: Entity) -> Vec3 {
    w.get::<Nodes>(mesh).unwrap().positions()[1].into()
}

#[test]
fn a_stiff_mesh_is_stepped_on_its_own_at_the_defaults_and_swings_at_the_closed_form_period() {
    // k = 1e6 N/m on 1 kg: 1000 rad/s, h_crit = 2 ms against the default 4.2 ms substep.
    let mut w = common::default_world();
    let mesh = mesh_pendulum(&mut w, 1e6);
    w.step_physics();
    let t = told(&w);
    assert_eq!(t.len(), 1, "{t:?}");
    assert_eq!(t[0].rescue, Some(Rescue::LocalSubsteps(3)));
    println!("{}", t[0].advice());
    assert_eq!(w.get::<LocalSubsteps>(mesh).map(|l| l.count()), Some(3));
    assert!(w.get::<ImplicitEuler>(mesh).is_none());
    // Released at 90°: T = 4 √(L/g) K(1/2) = 2.3678 s.
    let period = 2.3678f64;
    let (mut crossings, mut last, mut t) = (Vec::new(), 1.0f32, 1.0 / 60.0);
    let mut lowest = 0.0f32;
    for _ in 0..(10.0 * period * 60.0) as usize + 30 {
        w.step_physics();
        t += 1.0 / 60.0;
        let x = bob(&w, mesh);
        if last < 0.0 && x.x >= 0.0 {
            crossings.push(t - 1.0 / 60.0 * f64::from(x.x / (x.x - last)));
        }
        last = x.x;
        lowest = lowest.min(x.y);
    }
    let d = w.resource::<PhysicsDiagnostics>();
    assert_eq!(
        (d.rescued, d.rescued_by_substeps, d.quarantined_total),
        (1, 1, 0)
    );
    let n = crossings.len() - 1;
    let measured = (crossings[n] - crossings[0]) / n as f64;
    println!(
        "mesh pendulum at the defaults: period {measured:.4} s (closed {period:.4} s), lowest {lowest:.5} m"
    );
    assert!((measured / period - 1.0).abs() < 0.005, "{measured}");
    // It swings through the bottom on a rod stretched by 3 m g / k = 29 µm.
    assert!((lowest + 1.0).abs() < 1e-3, "{lowest}");
}

#[test]
fn a_mesh_that_would_need_many_local_substeps_is_solved_by_bdf2() {
    // 1e9 N/m: h_crit = 63 µs, 74 local substeps; past the policy's crossover.
    let mut w = common::default_world();
    let mesh = mesh_pendulum(&mut w, 1e9);
    w.step_physics();
    let t = told(&w);
    assert_eq!(t[0].rescue, Some(Rescue::Implicit(ImplicitScheme::Bdf2)));
    assert_eq!(
        w.get::<ImplicitEuler>(mesh).map(|s| s.scheme),
        Some(ImplicitScheme::Bdf2)
    );
    assert!(w.get::<LocalSubsteps>(mesh).is_none());
    let d = w.resource::<PhysicsDiagnostics>();
    assert_eq!((d.rescued, d.rescued_by_substeps), (1, 0));
}

#[test]
fn local_substeps_are_the_worlds_substeps_for_that_system_alone() {
    // One world substep with the mesh stepped 8 times locally against 8 world substeps:
    // the same scheme on the same forces (gravity held over a substep is constant anyway),
    // differing only in the rounding of h/8.
    let mut local = common::awake_world(1.0 / 60.0, 1, Vec3::new(0.0, -9.81, 0.0));
    local.insert_resource(StabilityPolicy::Warn);
    let a = mesh_pendulum(&mut local, 1e5);
    local
        .entity_mut(a)
        .insert(LocalSubsteps::try_new(8).unwrap());
    let mut world = common::awake_world(1.0 / 60.0, 8, Vec3::new(0.0, -9.81, 0.0));
    world.insert_resource(StabilityPolicy::Warn);
    let b = mesh_pendulum(&mut world, 1e5);
    let mut gap = 0.0f32;
    for _ in 0..120 {
        local.step_physics();
        world.step_physics();
        gap = gap.max((bob(&local, a) - bob(&world, b)).length());
    }
    println!("local ×8 against world ×8 over 2 s: largest gap {gap:.2e} m");
    assert_eq!(local.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    assert!(gap < 1e-4, "{gap}");
    // And it is not the world's single substep, which diverges on this spring.
    let mut coarse = common::awake_world(1.0 / 60.0, 1, Vec3::new(0.0, -9.81, 0.0));
    coarse.insert_resource(StabilityPolicy::Warn);
    mesh_pendulum(&mut coarse, 1e5);
    for _ in 0..120 {
        coarse.step_physics();
    }
    assert!(coarse.resource::<PhysicsDiagnostics>().quarantined_total > 0);
}

#[test]
fn the_local_count_is_validated_wherever_it_comes_from() {
    assert!(LocalSubsteps::try_new(0).is_err());
    assert!(LocalSubsteps::try_new(257).is_err());
    assert_eq!(LocalSubsteps::try_new(256).unwrap().count(), 256);
    // From a file (a snapshot, a scenario) too: a count that would hang a step is refused.
    assert!(ron::from_str::<LocalSubsteps>("0").is_err());
    assert!(ron::from_str::<LocalSubsteps>("4294967295").is_err());
    assert_eq!(ron::from_str::<LocalSubsteps>("5").unwrap().count(), 5);
}

#[test]
fn a_spring_whose_masses_change_gets_a_new_count() {
    // Rescued at 3 local substeps; a bob 100 times lighter needs 10 times the rate.
    let mut w = common::default_world();
    let mesh = mesh_pendulum(&mut w, 1e6);
    w.step_physics();
    assert_eq!(w.get::<LocalSubsteps>(mesh).map(|l| l.count()), Some(3));
    {
        let mut nodes = w.get_mut::<Nodes>(mesh).unwrap();
        nodes.set_mass(1, 0.01).unwrap();
    }
    for _ in 0..60 {
        w.step_physics();
    }
    let count = w.get::<LocalSubsteps>(mesh).map(|l| l.count());
    println!("after the bob lost 99% of its mass: {count:?} local substeps");
    assert_eq!(count, Some(24));
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    assert!(bob(&w, mesh).is_finite());
}
