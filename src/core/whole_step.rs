//! The whole-step path: one effect runs all of a step's substeps itself, in its own arrays,
//! when nothing else in the world needs the ECS between substeps.
//!
//! Each substep of [`crate::core::schedule::SubstepSchedule`] reads every moving body's state out of the ECS
//! and writes it back, system by system: forces, the velocity half, the contact solver's
//! two passes (each with a gather and a scatter), the position half, renormalisation. For a
//! world of rigid bodies under constant forces that round trip is most of the step's cost
//! outside the solver itself. The collision plugin therefore registers a
//! `WholeStepRunner`: a function that loads the bodies once, runs every substep with the
//! very same arithmetic in the same order, and stores them once. Results are bit-identical
//! with the schedule's (`tests/it/integrators/whole_step.rs` compares the two paths after every step, and
//! lists every substep system with how this path treats it).
//!
//! The runner is tried only when the schedule would do nothing it does not replicate:
//! - [`WholeStep`] is on (the default);
//! - the substep schedule holds only hooke's own systems ([`crate::core::schedule`] counts them):
//!   a game system in the substeps (a force written every substep) keeps the schedule;
//! - no entity holds a component registered with `block_on`. Each effect whose substep
//!   systems the runner does not replicate (springs, damping, meshes, tracers, forces at
//!   points, impulses, integrator overrides) registers the components its systems act on.
//!
//! The runner itself declines (and the schedule runs) for anything else it does not cover,
//! such as a non-default integrator, and for steps of one substep, where loading and storing
//! the bodies costs more than the schedule's round trips it saves.

use bevy_ecs::component::ComponentId;
use bevy_ecs::prelude::*;

use crate::core::schedule::{OwnSubstepSystems, SubstepSchedule};

/// Whether the whole-step path may run (default: on). Off forces every substep through
/// [`crate::core::schedule::SubstepSchedule`]; results are the same bit for bit, so this is only for
/// comparisons and for debugging a game system placed in the substeps.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct WholeStep(pub bool);

impl Default for WholeStep {
    fn default() -> Self {
        Self(true)
    }
}

/// Runs a whole step's substeps, or returns false (having changed nothing) when the world
/// needs the schedule. Registered by the effect that owns the path.
#[derive(Resource, Clone, Copy)]
pub(crate) struct WholeStepRunner(pub fn(&mut World) -> bool);

/// Components whose presence on any entity keeps the substep schedule (see [`block_on`]).
#[derive(Resource, Debug, Default)]
pub(crate) struct WholeStepBlockers(Vec<ComponentId>);

/// Registers `T` as acted on by a substep system the whole-step path does not replicate:
/// while any entity holds a `T`, every substep runs through the schedule.
pub(crate) fn block_on<T: Component>(world: &mut World) {
    let id = world.register_component::<T>();
    let mut blockers = world.get_resource_or_init::<WholeStepBlockers>();
    if !blockers.0.contains(&id) {
        blockers.0.push(id);
    }
}

/// Whether an entity holds one of the blocking components. A look at the archetypes, not
/// the entities: a few dozen set lookups per step.
fn blocked(world: &World) -> bool {
    let Some(blockers) = world.get_resource::<WholeStepBlockers>() else {
        return false;
    };
    world
        .archetypes()
        .iter()
        .any(|a| !a.is_empty() && blockers.0.iter().any(|&id| a.contains(id)))
}

/// Runs the step's substeps through the registered runner if the world allows it; false
/// when the schedule must run them.
pub(crate) fn try_whole_step(world: &mut World) -> bool {
    let runner = world.get_resource::<WholeStepRunner>().copied();
    let on = world.get_resource::<WholeStep>().is_some_and(|f| f.0);
    let (Some(runner), true) = (runner, on) else {
        if let Some(mut d) =
            world.get_resource_mut::<crate::core::diagnostics::PhysicsDiagnostics>()
        {
            d.whole_step = false;
        }
        return false;
    };
    // An uninitialised schedule (before its first run) counts its systems from the graph,
    // like the count was taken; after that from its executable. Either way a system added
    // by anything but hooke's plugins makes the counts differ.
    let own = world.get_resource::<OwnSubstepSystems>().map_or(0, |o| o.0);
    let total = world
        .get_resource::<Schedules>()
        .and_then(|s| s.get(SubstepSchedule))
        .map_or(usize::MAX, Schedule::systems_len);
    let ran = total == own && !blocked(world) && (runner.0)(world);
    if let Some(mut d) = world.get_resource_mut::<crate::core::diagnostics::PhysicsDiagnostics>() {
        d.whole_step = ran;
    }
    ran
}
