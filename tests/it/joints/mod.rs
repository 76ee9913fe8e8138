//! Joints against closed forms, at the defaults.

mod bridge;
mod cones;
mod door;
mod hard_cases;
mod kinematic_carriers;
mod layout;
mod limits;
mod motors;
mod pendulums;
mod ragdolls;
mod stops;
mod vehicle;

/// A world's name and how to make it.
type Setup = (&'static str, fn() -> bevy_ecs::world::World);

/// The defaults, and gravity at 30 Hz × 4 substeps and 120 Hz × 2: the frame rates and
/// substeps a jointed scene is checked at besides the defaults.
fn frame_rates() -> [Setup; 3] {
    fn at(dt: f32, substeps: u32) -> bevy_ecs::world::World {
        hooke::tools::scenes::world_with(
            dt,
            substeps,
            hooke::prelude::Integrator::SymplecticEuler,
            glam::Vec3::new(0.0, -9.81, 0.0),
        )
        .unwrap()
    }
    [
        ("defaults", crate::common::default_world),
        ("30 Hz x 4", || at(1.0 / 30.0, 4)),
        ("120 Hz x 2", || at(1.0 / 120.0, 2)),
    ]
}

/// Why the entity `e` is quarantined: its input error as text.
fn quarantine_reason(world: &bevy_ecs::world::World, e: bevy_ecs::entity::Entity) -> String {
    use hooke::core::quarantine::QuarantineReason;
    match world
        .get::<hooke::prelude::Quarantined>(e)
        .map(|q| &q.reason)
    {
        Some(QuarantineReason::InvalidInput(error)) => error.to_string(),
        other => format!("not quarantined for its input: {other:?}"),
    }
}

/// Asserts that each joint of `cases` is quarantined with a reason naming its text.
fn assert_quarantined_for(
    world: &bevy_ecs::world::World,
    cases: &[(bevy_ecs::entity::Entity, &str)],
) {
    for &(joint, names) in cases {
        let reason = quarantine_reason(world, joint);
        assert!(reason.contains(names), "{reason} does not name {names}");
    }
}
