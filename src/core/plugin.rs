//! The kernel's plugin trait and plugin, its registries, and one step of the kernel.
//!
//! A [`WorldPlugin`] installs an effect into a bare `World`. The kernel never names an
//! effect: an effect tells the kernel what it needs through registries filled in its
//! `build` — the messages it writes ([`add_message`], rotated once per step or frame) and the
//! components of the bodies it moves ([`moves`], so that a world with nothing to move only
//! advances its clock).

use bevy_ecs::component::ComponentId;
use bevy_ecs::message::{Message, Messages};
use bevy_ecs::prelude::*;
use bevy_platform::time::Instant;

use super::diagnostics::PhysicsDiagnostics;
use super::quarantine::{BodyQuarantined, DivergenceGuard};
use super::restore::{self, InvalidSetting, ResourceRestored};
use super::schedule::SubstepSchedule;
use super::schedule::{self, PhysicsSchedule, PhysicsSystems};
use super::time::{FrameReport, PhysicsTime, SubstepTime};
use super::whole_step::WholeStep;
use super::{diagnostics, error::Result};

/// A piece of physics that installs itself into a `World`: resources and systems.
pub trait WorldPlugin: 'static {
    /// Adds the plugin's resources and systems. Called once per world.
    fn build(&self, world: &mut World);
}

/// The plugins already built into a world, so adding one twice is harmless; and the
/// kernel's registries.
#[derive(Resource, Default)]
struct Installed {
    plugins: Vec<core::any::TypeId>,
    /// One per registered message type: swaps its buffers.
    rotations: Vec<fn(&mut World)>,
    /// Components of the bodies the substeps move.
    moving: Vec<ComponentId>,
}

/// The kernel: schedules, the clock, restored resources, quarantine messages and the
/// divergence guard, diagnostics. It moves nothing by itself; the effects do.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsCorePlugin;

impl WorldPlugin for PhysicsCorePlugin {
    fn build(&self, world: &mut World) {
        schedule::init_schedules(world);
        if !world.contains_resource::<PhysicsTime>() {
            world.insert_resource(PhysicsTime::default());
        }
        restore::init::<PhysicsTime>(world);
        add_message::<ResourceRestored>(world);
        add_message::<InvalidSetting>(world);
        schedule::add_own_systems(
            world,
            PhysicsSchedule,
            restore::restore_resources.in_set(PhysicsSystems::Restore),
        );
        restore::init::<SubstepTime>(world);
        restore::init::<WholeStep>(world);
        add_message::<BodyQuarantined>(world);
        restore::init::<DivergenceGuard>(world);
        schedule::add_own_systems(
            world,
            PhysicsSchedule,
            run_substeps.in_set(PhysicsSystems::Step),
        );
        diagnostics::install(world);
    }
}

/// Builds `plugin` into `world` unless a plugin of its type is already there. Returns
/// whether it was built.
pub fn install<P: WorldPlugin>(world: &mut World, plugin: &P) -> bool {
    let id = core::any::TypeId::of::<P>();
    let mut installed = world.get_resource_or_init::<Installed>();
    if installed.plugins.contains(&id) {
        return false;
    }
    installed.plugins.push(id);
    plugin.build(world);
    true
}

/// Installs the messages of type `M`, put back if removed, and rotated with the others:
/// once per step by [`step`], once per frame by [`advance`], so a reader that runs every
/// frame sees every step's messages. Registering twice is harmless.
pub fn add_message<M: Message>(world: &mut World) {
    restore::init::<Messages<M>>(world);
    let rotate: fn(&mut World) = |world| {
        if let Some(mut m) = world.get_resource_mut::<Messages<M>>() {
            m.update();
        }
    };
    let mut installed = world.get_resource_or_init::<Installed>();
    if !installed.rotations.contains(&rotate) {
        installed.rotations.push(rotate);
    }
}

/// Registers `C` as a component of bodies the substeps move: while no entity has any such
/// component, a step only advances the clock.
pub fn moves<C: Component>(world: &mut World) {
    let id = world.register_component::<C>();
    let mut installed = world.get_resource_or_init::<Installed>();
    if !installed.moving.contains(&id) {
        installed.moving.push(id);
    }
}

/// Whether any entity has a component registered with [`moves`].
pub(crate) fn anything_moves(world: &World) -> bool {
    let Some(installed) = world.get_resource::<Installed>() else {
        return false;
    };
    let index = world.archetypes().component_index();
    installed.moving.iter().any(|id| {
        index.get(id).is_some_and(|archetypes| {
            archetypes
                .keys()
                .any(|&a| !world.archetypes()[a].is_empty())
        })
    })
}

/// Runs the substep schedule `substeps` times. The only system in `PhysicsSystems::Step`.
/// A world where nothing registered as moving ([`crate::core::plugin::moves`]) exists only
/// advances its clock.
fn run_substeps(world: &mut World) {
    if !world.contains_resource::<PhysicsTime>() {
        return;
    }
    let empty = !anything_moves(world);
    // An effect that ran the whole step leaves only the clock to advance.
    let done = empty || crate::core::whole_step::try_whole_step(world);
    let Some(time) = world.get_resource::<PhysicsTime>() else {
        return;
    };
    let (n, h, t0) = (time.substeps(), time.substep_dt(), time.elapsed());
    // One lookup of the schedule for all substeps. The core plugin creates it; a missing
    // one means a user removed it, and the step then does nothing.
    let _ = world.try_schedule_scope(SubstepSchedule, |world, schedule| {
        if done {
            return;
        }
        for i in 0..n {
            let t = (t0 + f64::from(h) * f64::from(i)) as f32;
            // Inserted, not written through: a system of the substep may have removed it.
            world.insert_resource(SubstepTime {
                h,
                t,
                index: i,
                count: n,
            });

            schedule.run(world);
        }
    });
    if let Some(mut time) = world.get_resource_mut::<PhysicsTime>() {
        time.end_step();
    }
}

/// Swaps the buffers of every registered message type (no allocation: the registry is
/// taken out of the world while its functions run).
fn rotate_messages(world: &mut World) {
    world.try_resource_scope::<Installed, _>(|world, installed| {
        for rotate in &installed.rotations {
            rotate(world);
        }
    });
}

/// Runs the physics schedule once and records its wall time.
pub(crate) fn run_step(world: &mut World) {
    let start = Instant::now();
    let _ = world.try_run_schedule(PhysicsSchedule);
    if let Some(mut d) = world.get_resource_mut::<PhysicsDiagnostics>() {
        d.step_time = start.elapsed();
    }
}

/// One fixed step of [`PhysicsTime::dt`]; does nothing without the kernel plugin.
pub fn step(world: &mut World) {
    if !world.contains_resource::<PhysicsTime>() {
        // The clock itself was removed (the step's own restore pass would not run):
        // put everything back first; without the kernel plugin this does nothing.
        restore::restore_resources(world);
        if !world.contains_resource::<PhysicsTime>() {
            return;
        }
    }
    rotate_messages(world);
    run_step(world);
}

/// Adds `frame_dt` seconds of frame time and runs the whole steps that fit, up to
/// [`PhysicsTime::max_steps_per_frame`].
///
/// # Errors
/// [`crate::core::error::Error::InvalidTimeStep`] for a negative or non-finite `frame_dt`
/// (nothing runs).
pub fn advance(world: &mut World, frame_dt: f32) -> Result<FrameReport> {
    if !world.contains_resource::<PhysicsTime>() {
        restore::restore_resources(world);
    }
    let Some(mut time) = world.get_resource_mut::<PhysicsTime>() else {
        return Ok(FrameReport::default());
    };
    let (steps, dropped) = time.take_frame(frame_dt)?;
    // Rotate once per frame, so a game reading messages every frame sees every step's.
    rotate_messages(world);
    for _ in 0..steps {
        run_step(world);
    }
    if let Some(mut d) = world.get_resource_mut::<PhysicsDiagnostics>() {
        d.dropped_time = dropped;
    }
    Ok(FrameReport { steps, dropped })
}
