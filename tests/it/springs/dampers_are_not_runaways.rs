//! The divergence guard tells a runaway from a spring that is soft or only a damper: a pure
//! damper (k = 0) and a soft door spring (k = 1, c = 50) pushed hard were quarantined as
//! `SpringFailed` at strain 0.5 and 0.0, because the guard compared the force (damping
//! included) with k r s_max. It compares the stretch now.

use crate::common;

use glam::Vec3;
use hooke::prelude::*;

#[test]
fn a_pure_damper_and_a_soft_door_spring_pushed_hard_are_not_quarantined() {
    for (k, c) in [(0.0f32, 5.0f32), (1.0, 50.0)] {
        let mut w = common::default_world();
        let hinge = w.spawn(ParticleBundle::pinned(Vec3::ZERO).unwrap()).id();
        // A 1 kg door edge 1 m out, thrown at 10 m/s along the spring.
        let edge = w
            .spawn(ParticleBundle::new(Vec3::X, Vec3::new(10.0, 0.0, 0.0), 1.0).unwrap())
            .id();
        Spring::new(hinge, edge, 1.0, k, c)
            .unwrap()
            .spawn(&mut w)
            .unwrap();
        for _ in 0..120 {
            w.step_physics();
        }
        let d = w.resource::<PhysicsDiagnostics>();
        let x = common::x(&w, edge);
        println!(
            "k {k}, c {c}: quarantined {}, edge at {x}",
            d.quarantined_total
        );
        assert_eq!(d.quarantined_total, 0, "k {k}, c {c}");
        assert!(x.is_finite());
    }
}

#[test]
fn a_spring_stretched_past_the_guard_is_still_caught() {
    // A 1 cm spring whose free end is thrown 10 m away in a step: strain 1000.
    let mut w = common::default_world();
    let pin = w.spawn(ParticleBundle::pinned(Vec3::ZERO).unwrap()).id();
    let end = w
        .spawn(ParticleBundle::new(Vec3::new(0.01, 0.0, 0.0), Vec3::ZERO, 1.0).unwrap())
        .id();
    Spring::new(pin, end, 0.01, 10.0, 1.0)
        .unwrap()
        .spawn(&mut w)
        .unwrap();
    w.step_physics();
    w.get_mut::<Position>(end).unwrap().0 = Vec3::new(10.0, 0.0, 0.0).into();
    w.step_physics();
    assert!(
        w.get::<hooke::core::quarantine::Quarantined>(end).is_some(),
        "torn past the strain limit"
    );
}
