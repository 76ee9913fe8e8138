//! NaN quarantine: a body whose state turns non-finite stops being simulated, is reported,
//! and the rest of the world goes on.
//!
//! Two paths lead here:
//! - **Bad input.** A component inserted directly with a non-finite or out-of-range value
//!   (constructors can't be bypassed for [`crate::Mass`], but `Position(Vec3::NAN)` can be
//!   written by hand) is caught by the component's insert hook.
//! - **Blow-up.** A body whose position or velocity is non-finite after integration.
//!
//! Either way the entity gets [`Quarantined`], every physics system skips it (an archetype
//! filter, so it costs nothing per body), a [`BodyQuarantined`] message is written, and
//! [`crate::PhysicsDiagnostics`] counts it. Remove [`Quarantined`] after repairing the state
//! to put the body back.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;

use crate::error::Error;

/// Why a body was taken out of the simulation.
#[derive(Debug, Clone, PartialEq)]
pub enum QuarantineReason {
    /// Its position or velocity became NaN or infinite during a step.
    NonFiniteState,
    /// A component was inserted with an invalid value.
    InvalidInput(Error),
}

/// Marks a body that is no longer simulated. See the module docs.
#[derive(Component, Debug, Clone, PartialEq)]
#[component(on_insert = report_quarantine)]
pub struct Quarantined {
    /// Why.
    pub reason: QuarantineReason,
}

/// Written once for every body put into quarantine. Read it with
/// `World::resource::<Messages<BodyQuarantined>>()` or a `MessageReader`; messages live for
/// two `step_physics` / `advance_physics` calls.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct BodyQuarantined {
    /// The body.
    pub entity: Entity,
    /// Why.
    pub reason: QuarantineReason,
}

/// Writes the message. Effects that care (diagnostics' counts, the broad phase's lists)
/// observe the insert themselves: the core calls none of them.
fn report_quarantine(mut world: DeferredWorld, ctx: HookContext) {
    let Some(reason) = world
        .get::<Quarantined>(ctx.entity)
        .map(|q| q.reason.clone())
    else {
        return;
    };
    world.write_message(BodyQuarantined {
        entity: ctx.entity,
        reason,
    });
}

/// Quarantines `entity` because its state turned non-finite during a step.
pub(crate) fn quarantine_non_finite(commands: &mut Commands, entity: Entity) {
    commands.entity(entity).insert(Quarantined {
        reason: QuarantineReason::NonFiniteState,
    });
}

/// A component whose value can be checked after a direct insert.
pub(crate) trait Validate {
    fn validate(&self) -> Result<(), Error>;
}

/// Insert hook shared by every validated component: quarantine on a bad value.
pub(crate) fn validate_on_insert<T: Component + Validate>(
    mut world: DeferredWorld,
    ctx: HookContext,
) {
    let Some(Err(err)) = world.get::<T>(ctx.entity).map(Validate::validate) else {
        return;
    };
    world.commands().entity(ctx.entity).insert(Quarantined {
        reason: QuarantineReason::InvalidInput(err),
    });
}
