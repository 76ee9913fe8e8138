//! A clock that would never return is refused wherever it comes from: `PhysicsTime` with
//! `u32::MAX` substeps used to run a step of four billion substeps (through a scenario file
//! or a snapshot too), and a snapshot with `dt = NaN` was restored and quarantined every
//! body instead of being refused.

use bevy_ecs::prelude::*;
use hooke::core::error::Error;
use hooke::core::time::PhysicsTime;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenario::Scenario;

#[test]
fn substeps_and_steps_per_frame_past_their_bound_are_typed_errors() {
    assert!(matches!(
        PhysicsTime::new(1.0 / 60.0, u32::MAX),
        Err(Error::TooMany { max: 4096, .. })
    ));
    assert!(PhysicsTime::new(1.0 / 60.0, PhysicsTime::MAX_SUBSTEPS).is_ok());
    assert!(matches!(
        PhysicsTime::default().with_max_steps_per_frame(u32::MAX),
        Err(Error::TooMany { max: 1024, .. })
    ));
}

/// A world at the defaults with one falling particle, as RON.
fn saved() -> String {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.spawn(ParticleBundle::new(glam::Vec3::Y, glam::Vec3::ZERO, 1.0).unwrap());
    w.step_physics();
    Snapshot::capture(&w).unwrap().to_ron().unwrap()
}

#[test]
fn a_snapshot_with_a_clock_that_would_never_return_or_is_nan_is_refused() {
    let good = saved();
    assert!(Snapshot::from_ron(&good).is_ok());
    assert!(good.contains("substeps: 4"), "the field as written");
    for (from, to) in [
        ("substeps: 4", "substeps: 4294967295"),
        ("substeps: 4", "substeps: 0"),
        ("max_steps_per_frame: 4", "max_steps_per_frame: 4294967295"),
    ] {
        let bad = good.replacen(from, to, 1);
        assert!(Snapshot::from_ron(&bad).is_err(), "{to} was accepted");
    }
    // dt: whatever digits it was written with, NaN is refused.
    let start = good.find("dt: ").unwrap() + 4;
    let end = start + good[start..].find(',').unwrap();
    let bad = format!("{}NaN{}", &good[..start], &good[end..]);
    assert!(Snapshot::from_ron(&bad).is_err(), "dt NaN was accepted");
}

#[test]
fn a_scenario_asking_for_four_billion_substeps_is_refused_at_load() {
    let text = r#"(
        name: "hang",
        settings: (substeps: 4294967295),
        duration: 1.0,
        entities: [(name: "p", spawn: Particle(at: (0, 1, 0)))],
        expect: [],
    )"#;
    let err = Scenario::from_str(text, "hang.ron").unwrap_err();
    println!("{err}");
    assert!(err.to_string().contains("substeps"), "{err}");
}
