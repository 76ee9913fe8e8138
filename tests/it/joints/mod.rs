//! Joints against closed forms, at the defaults.

mod bridge;
mod cones;
mod door;
mod hard_cases;
mod kinematic_carriers;
mod limits;
mod motors;
mod pendulums;
mod ragdolls;
mod stops;

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
