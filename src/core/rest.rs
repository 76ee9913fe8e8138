//! Rest state that every integrating system skips: [`Sleeping`] bodies (put to sleep and
//! woken by the sleep plugin), next to [`crate::core::quarantine::Quarantined`] ones.
//!
//! These markers live in the core, not in the sleep plugin, so that particles, rigid bodies
//! and contacts can skip sleeping bodies without depending on the plugin that decides who
//! sleeps.

use bevy_ecs::prelude::*;

/// Marks a body at rest: no system integrates it until it wakes. See [`crate::sleep`].
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Sleeping;

/// Keeps a body from ever sleeping.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SleepingDisabled;

/// How long (s) the body has been slower than the sleep thresholds.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SleepTimer(pub f32);

/// The bodies a substep moves: neither quarantined nor asleep. The query filter of every
/// integrating and force system.
pub type Simulated = (
    Without<crate::core::quarantine::Quarantined>,
    Without<Sleeping>,
);

/// Wakes `e` if it sleeps, with its stillness count started afresh (or it would fall
/// straight back asleep). For the structural changes that wake a body: a joint added to it
/// or taken off it.
pub(crate) fn wake(world: &mut bevy_ecs::world::DeferredWorld, e: Entity) {
    if world.get::<Sleeping>(e).is_some() {
        world
            .commands()
            .entity(e)
            .try_remove::<Sleeping>()
            .try_insert(SleepTimer(0.0));
    }
}
