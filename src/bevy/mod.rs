//! hooke in a Bevy `App` (feature `bevy`).
//!
//! ```no_run
//! use bevy_app::prelude::*;
//! use bevy_ecs::prelude::*;
//! use bevy_transform::prelude::*;
//! use hooke::prelude::*;
//!
//! App::new()
//!     .add_plugins((bevy_time::TimePlugin, bevy_transform::TransformPlugin))
//!     .add_plugins(PhysicsPlugins) // every effect, the clock, Transform sync, interpolation
//!     .add_systems(Startup, |mut commands: Commands| {
//!         commands.spawn((
//!             RigidBody::Dynamic,
//!             Collider::cuboid(0.5, 0.5, 0.5).unwrap(), // half extents (m)
//!             Transform::from_xyz(0.0, 5.0, 0.0),
//!         ));
//!     })
//!     .run();
//! ```
//!
//! - **One clock.** [`PhysicsSchedulePlugin`] runs one physics step per tick of its schedule
//!   (`FixedPostUpdate` by default) with dt = `Time<Fixed>::delta`, and sets
//!   [`PhysicsTime::elapsed`](crate::core::time::PhysicsTime::elapsed) to `Time<Fixed>::elapsed` after
//!   each step, so the two never drift. Change the rate with `Time::<Fixed>::from_hz(..)`;
//!   [`PhysicsTime::substeps`](crate::core::time::PhysicsTime::substeps) still splits each step.
//! - **Transforms.** [`PhysicsTransformPlugin`] reads a body's or collider's `Transform` when
//!   something other than hooke wrote it (so writing a `Transform` moves a body or a static
//!   collider: no insert-versus-write trap) and writes it back after every step, with the
//!   centre-of-mass offset accounted for: `Transform.translation` is the frame origin
//!   x − R c. A child collider's `Transform` is its offset in the parent body.
//! - **Interpolation.** [`PhysicsInterpolationPlugin`] moves the `Transform` of entities with
//!   [`TransformInterpolation`] (or [`TransformExtrapolation`]) between fixed steps, every
//!   frame.
//! - **Messages.** [`crate::collision::ContactStarted`], [`crate::collision::ContactEnded`] and
//!   [`crate::core::quarantine::BodyQuarantined`] are registered with the App, which keeps them until two
//!   frames that ran a fixed step have passed: a `MessageReader` in `Update` sees every one
//!   however many steps a frame ran. Bodies with [`crate::collision::CollisionEventsEnabled`] also get
//!   [`crate::collision::ContactStart`] / [`crate::collision::ContactEnd`] entity events for observers.
//! - **Diagnostics.** [`PhysicsDiagnosticsPlugin`] (not in the group; add it beside
//!   `bevy_diagnostic`'s `DiagnosticsPlugin`) feeds [`crate::core::diagnostics::PhysicsDiagnostics`] into the
//!   `DiagnosticsStore`.
//!
//! Every hooke effect plugin is also a Bevy plugin, so `app.add_plugins((GravityPlugin,
//! RigidBodyPlugin, CollisionPlugin))` takes only what a game needs (add
//! [`PhysicsSchedulePlugin`] too, or nothing steps).

#[cfg(feature = "debug-plugin")]
mod debug;
mod diagnostics;
mod interpolation;
mod reflect;
mod transform;

#[cfg(feature = "debug-plugin")]
pub use debug::{ContactGizmoScale, PhysicsDebugPlugin, PhysicsGizmos};
pub use diagnostics::PhysicsDiagnosticsPlugin;
pub use interpolation::{
    PhysicsInterpolationPlugin, PoseHistory, TransformExtrapolation, TransformInterpolation,
};
pub use transform::{PhysicsTransformPlugin, TransformScaleIgnored};

use bevy_app::{App, FixedPostUpdate, Plugin, PluginGroup, PluginGroupBuilder};
use bevy_ecs::intern::Interned;
use bevy_ecs::message::MessageRegistry;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use bevy_time::{Fixed, Time};
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

use crate::character::CharacterControllerPlugin;
use crate::cloth::ClothPlugin;
use crate::collision::CollisionPlugin;
use crate::collision::ContactEnded;
use crate::collision::ContactStarted;
use crate::core::plugin::PhysicsCorePlugin;
use crate::core::quarantine::BodyQuarantined;
use crate::core::time::PhysicsTime;
use crate::joints::JointPlugin;
use crate::particles::DampingPlugin;
use crate::particles::GravityPlugin;
use crate::particles::VelocityFieldPlugin;
use crate::plugins::PhysicsPlugins;
use crate::plugins::PhysicsWorldExt;
use crate::rigid::RigidBodyPlugin;
use crate::sleep::SleepPlugin;
use crate::soft::SoftBodyPlugin;
use crate::springs::SpringPlugin;

/// The sets hooke's App systems run in, in order, inside the physics schedule
/// ([`PhysicsSchedulePlugin::schedule`]). Put gameplay systems that must see the new poses
/// `.after(PhysicsAppSystems::Writeback)`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhysicsAppSystems {
    /// `Transform`s written by game code become physics poses.
    ReadTransforms,
    /// One physics step ([`crate::core::schedule::PhysicsSchedule`]).
    Step,
    /// Physics poses become `Transform`s; interpolation records the step's poses.
    Writeback,
}

/// Steps hooke once per tick of `schedule` (default `FixedPostUpdate`), with the step
/// length and clock of `Time<Fixed>`. Installs the core plugin and registers hooke's
/// messages with the App. Adds bevy's `TimePlugin` at `finish` if no `Time<Fixed>` exists,
/// since without it no fixed step would ever run.
#[derive(Debug, Clone)]
pub struct PhysicsSchedulePlugin {
    /// The schedule whose every run is one physics step.
    pub schedule: Interned<dyn ScheduleLabel>,
}

impl PhysicsSchedulePlugin {
    /// Steps physics in `schedule` (for example `FixedUpdate`).
    #[must_use]
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
        }
    }
}

impl Default for PhysicsSchedulePlugin {
    fn default() -> Self {
        Self::new(FixedPostUpdate)
    }
}

/// Where the App's physics runs, for the other hooke plugins to place their systems.
#[derive(Resource, Debug, Clone)]
pub(crate) struct AppSchedule(pub(crate) Interned<dyn ScheduleLabel>);

/// Registered once: a message registered twice would be rotated twice a frame.
#[derive(Resource)]
struct MessagesRegistered;

fn register_messages(world: &mut World) {
    if world.contains_resource::<MessagesRegistered>() {
        return;
    }
    // `App::add_message` skips registration when the resource exists, and hooke's plugins
    // may have created it already.
    MessageRegistry::register_message::<ContactStarted>(world);
    MessageRegistry::register_message::<ContactEnded>(world);
    MessageRegistry::register_message::<crate::collision::ContactReport>(world);
    MessageRegistry::register_message::<BodyQuarantined>(world);
    MessageRegistry::register_message::<crate::joints::JointBroken>(world);
    MessageRegistry::register_message::<crate::integrator::StabilityWarning>(world);
    MessageRegistry::register_message::<crate::core::restore::ResourceRestored>(world);
    MessageRegistry::register_message::<crate::core::restore::InvalidSetting>(world);
    MessageRegistry::register_message::<TransformScaleIgnored>(world);
    world.insert_resource(MessagesRegistered);
}

impl Plugin for PhysicsSchedulePlugin {
    fn build(&self, app: &mut App) {
        register_messages(app.world_mut());
        reflect::register_types(app);
        app.world_mut().add_physics(PhysicsCorePlugin);
        app.insert_resource(AppSchedule(self.schedule));
        app.configure_sets(
            self.schedule,
            (
                PhysicsAppSystems::ReadTransforms,
                PhysicsAppSystems::Step,
                PhysicsAppSystems::Writeback,
            )
                .chain(),
        );
        app.add_systems(self.schedule, step.in_set(PhysicsAppSystems::Step));
    }

    fn finish(&self, app: &mut App) {
        if !app.world().contains_resource::<Time<Fixed>>() {
            app.add_plugins(bevy_time::TimePlugin);
        }
    }
}

/// One physics step at `Time<Fixed>`'s step, ending on its clock.
fn step(world: &mut World) {
    let Some(fixed) = world.get_resource::<Time<Fixed>>() else {
        return;
    };
    let (dt, end) = (fixed.delta_secs(), fixed.elapsed_secs_f64());
    let start = end - fixed.delta_secs_f64();
    let Some(mut time) = world.get_resource_mut::<PhysicsTime>() else {
        return;
    };
    if dt.is_nan() || dt <= 0.0 {
        return;
    }
    time.follow(dt, start);
    crate::core::plugin::run_step(world);
    if let Some(mut time) = world.get_resource_mut::<PhysicsTime>() {
        time.set_elapsed(end);
    }
}

macro_rules! bevy_plugin {
    ($($name:ident),*) => {$(
        impl Plugin for $name {
            fn build(&self, app: &mut App) {
                register_messages(app.world_mut());
                app.world_mut().add_physics(*self);
            }
        }
    )*};
}

bevy_plugin!(
    GravityPlugin,
    DampingPlugin,
    VelocityFieldPlugin,
    SpringPlugin,
    RigidBodyPlugin,
    CollisionPlugin,
    JointPlugin,
    SleepPlugin,
    SoftBodyPlugin,
    ClothPlugin,
    CharacterControllerPlugin
);

impl<H: crate::collision::CollisionHooks + 'static> Plugin
    for crate::collision::CollisionHooksPlugin<H>
where
    for<'w, 's> bevy_ecs::system::SystemParamItem<'w, 's, H>: crate::collision::CollisionHooks,
{
    fn build(&self, app: &mut App) {
        register_messages(app.world_mut());
        app.world_mut().add_physics(Self::default());
    }
}

/// `app.add_plugins(PhysicsPlugins)`: the clock ([`PhysicsSchedulePlugin`]), every effect,
/// [`PhysicsTransformPlugin`] and [`PhysicsInterpolationPlugin`]. Change one with
/// `PhysicsPlugins.build().set(PhysicsSchedulePlugin::new(FixedUpdate))`, or leave one out
/// with `.disable::<P>()`.
impl PluginGroup for PhysicsPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(PhysicsSchedulePlugin::default())
            .add(GravityPlugin)
            .add(DampingPlugin)
            .add(VelocityFieldPlugin)
            .add(SpringPlugin)
            .add(RigidBodyPlugin)
            .add(CollisionPlugin)
            .add(JointPlugin)
            .add(SleepPlugin)
            .add(SoftBodyPlugin)
            .add(ClothPlugin)
            .add(CharacterControllerPlugin)
            .add(PhysicsTransformPlugin)
            .add(PhysicsInterpolationPlugin)
    }
}

/// The `Transform` hooke last wrote or read for this entity. Added by hooke.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SyncedTransform {
    translation: Vec3,
    rotation: Quat,
}

impl SyncedTransform {
    pub(crate) fn of(t: &Transform) -> Self {
        Self {
            translation: t.translation,
            rotation: t.rotation,
        }
    }

    pub(crate) fn matches(&self, t: &Transform) -> bool {
        self.translation == t.translation && self.rotation == t.rotation
    }
}
