//! # hooke
//!
//! Physics for entity-component-system games, on `bevy_ecs`: particles, tracers in velocity
//! fields, mass–spring ropes, hair and cloth, with an integrator dial and NaN quarantine.
//!
//! A bare `World` is a complete simulation; no app framework is needed:
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! let ball = world
//!     .spawn(ParticleBundle::new(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, 1.0).unwrap())
//!     .id();
//! for _ in 0..60 {
//!     world.step_physics(); // one fixed step of 1/60 s
//! }
//! let y = world.get::<Position>(ball).unwrap().0.y;
//! assert!(y < 10.0 - 4.8 && y > 10.0 - 5.0); // fell ½ g t² ≈ 4.9 m
//! ```
//!
//! ## Effects
//!
//! Each effect is a plugin; [`PhysicsPlugins`] adds them all. An effect's systems carry run
//! conditions, so in a scene without its components they cost one archetype check.
//!
//! | plugin | what | acts on |
//! |---|---|---|
//! | [`PhysicsCorePlugin`] (always) | schedules, time, integrators, external forces and impulses, quarantine, diagnostics | everything |
//! | [`GravityPlugin`] | f = m g s | [`Mass`], [`Nodes`] |
//! | [`DampingPlugin`] | f = −c m v | [`LinearDamping`] |
//! | [`VelocityFieldPlugin`] | dx/dt = Σ u(x, t) | [`Tracer`], [`VelocityField`] |
//! | [`SpringPlugin`] | damped springs | [`Spring`], [`SpringNetwork`] |
//!
//! ## Order
//!
//! [`schedule`] declares it, once: clear forces → apply forces → accumulate torque →
//! integrate velocities → solve constraints → integrate positions → complete stages →
//! renormalise, repeated `substeps` times per step.
//!
//! ## Units
//!
//! SI throughout: m, s, kg, N. Angles in radians.

#![warn(missing_docs)]

#[cfg(feature = "bevy")]
pub mod bevy;
pub mod collision;
pub mod diagnostics;
pub mod error;
pub mod integrator;
pub mod particles;
pub mod quarantine;
pub mod rigid;
pub mod scenes;
pub mod schedule;
pub mod sleep;
pub mod springs;
pub mod time;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;

pub use collision::{
    Collider, ColliderDensity, ColliderOf, ColliderOffset, CollisionEventsEnabled, CollisionLayers,
    CollisionPlugin, CombineRule, ContactEnd, ContactEnded, ContactSettings, ContactStart,
    ContactStarted, Contacts, Friction, Restitution, Sensor, SpatialQuery,
};
pub use diagnostics::{DiagnosticsSettings, PhysicsDiagnostics};
pub use error::{Error, Result};
pub use integrator::{ConstraintsActive, Integrator, IntegratorOverride, IntegratorPlugin};
pub use particles::{
    Advection, DampingPlugin, ExternalForce, ExternalImpulse, Force, Gravity, GravityPlugin,
    GravityScale, LinearDamping, LinearVelocity, Mass, Nodes, ParticleBundle, Position, Tracer,
    VelocityField, VelocityFieldPlugin,
};
pub use quarantine::{BodyQuarantined, QuarantineReason, Quarantined};
pub use rigid::{
    AngularDamping, AngularMomentum, AngularVelocity, CenterOfMass, ExternalForceAtPoint,
    ExternalImpulseAtPoint, ExternalTorque, Inertia, KinematicTarget, MassProperties,
    OrientationUpdate, Renormalization, RigidBody, RigidBodyBundle, RigidBodyPlugin, Rotation,
    SkipRenormalization, Torque,
};
pub use schedule::{
    ForceSchedule, ForceSystems, PhysicsSchedule, PhysicsSystems, StepSystems, SubstepSchedule,
};
pub use sleep::{SleepPlugin, SleepSettings, Sleeping, SleepingDisabled};
pub use springs::{Chain, ChainBuilder, ClothBuilder, Spring, SpringNetwork, SpringPlugin};
pub use time::{FrameReport, PhysicsTime, SubstepTime};

/// Everything a game needs in scope.
pub mod prelude {
    pub use crate::{
        Advection, BodyQuarantined, ChainBuilder, ClothBuilder, DiagnosticsSettings, Error,
        ExternalForce, ExternalImpulse, Force, Gravity, GravityScale, Integrator,
        IntegratorOverride, LinearDamping, LinearVelocity, Mass, Nodes, ParticleBundle,
        PhysicsDiagnostics, PhysicsPlugins, PhysicsTime, PhysicsWorldExt, Position,
        QuarantineReason, Quarantined, Spring, SpringNetwork, Tracer, VelocityField, WorldPlugin,
    };
    pub use crate::{
        AngularVelocity, Collider, CollisionLayers, Contacts, Friction, Inertia, MassProperties,
        Restitution, RigidBody, RigidBodyBundle, Rotation, Sensor, Sleeping, SpatialQuery,
    };
    pub use glam::{Quat, Vec3, Vec3A};
}

/// A piece of physics that installs itself into a `World`: resources and systems.
pub trait WorldPlugin: 'static {
    /// Adds the plugin's resources and systems. Called once per world.
    fn build(&self, world: &mut World);
}

/// Names of the plugins already built into a world, so adding one twice is harmless.
#[derive(Resource, Default)]
struct InstalledPlugins(Vec<core::any::TypeId>);

/// Schedules, time, integrators, external forces, quarantine and diagnostics. Added
/// automatically before any other plugin.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsCorePlugin;

impl WorldPlugin for PhysicsCorePlugin {
    fn build(&self, world: &mut World) {
        schedule::init_schedules(world);
        if !world.contains_resource::<PhysicsTime>() {
            world.insert_resource(PhysicsTime::default());
        }
        world.init_resource::<SubstepTime>();
        world.init_resource::<Messages<BodyQuarantined>>();
        schedule::add_systems(
            world,
            PhysicsSchedule,
            time::run_substeps.in_set(PhysicsSystems::Step),
        );
        diagnostics::install(world);
        world.add_physics(IntegratorPlugin);
    }
}

/// Every effect: core, gravity, damping, velocity fields, springs, rigid bodies and
/// collisions.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsPlugins;

impl WorldPlugin for PhysicsPlugins {
    fn build(&self, world: &mut World) {
        world
            .add_physics(GravityPlugin)
            .add_physics(DampingPlugin)
            .add_physics(VelocityFieldPlugin)
            .add_physics(SpringPlugin)
            .add_physics(RigidBodyPlugin)
            .add_physics(CollisionPlugin)
            .add_physics(SleepPlugin);
    }
}

/// Physics on a bare `World`.
pub trait PhysicsWorldExt {
    /// Builds `plugin` into this world (once; later calls with the same plugin do nothing).
    /// The core plugin is added first if missing.
    fn add_physics<P: WorldPlugin>(&mut self, plugin: P) -> &mut Self;

    /// Runs one fixed step of [`PhysicsTime::dt`]. Does nothing without the core plugin.
    fn step_physics(&mut self);

    /// Adds `frame_dt` seconds of frame time and runs the whole steps that fit, up to
    /// [`PhysicsTime::max_steps_per_frame`].
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] for a negative or non-finite `frame_dt` (nothing runs).
    fn advance_physics(&mut self, frame_dt: f32) -> Result<FrameReport>;
}

fn mark_installed<P: WorldPlugin>(world: &mut World) -> bool {
    let id = core::any::TypeId::of::<P>();
    let mut installed = world.get_resource_or_init::<InstalledPlugins>();
    if installed.0.contains(&id) {
        false
    } else {
        installed.0.push(id);
        true
    }
}

/// Messages live for two rotations; see [`BodyQuarantined`].
fn rotate_messages(world: &mut World) {
    if let Some(mut m) = world.get_resource_mut::<Messages<BodyQuarantined>>() {
        m.update();
    }
    if let Some(mut m) = world.get_resource_mut::<Messages<ContactStarted>>() {
        m.update();
    }
    if let Some(mut m) = world.get_resource_mut::<Messages<ContactEnded>>() {
        m.update();
    }
}

pub(crate) fn run_step(world: &mut World) {
    let start = std::time::Instant::now();
    let _ = world.try_run_schedule(PhysicsSchedule);
    if let Some(mut d) = world.get_resource_mut::<PhysicsDiagnostics>() {
        d.step_time = start.elapsed();
    }
}

impl PhysicsWorldExt for World {
    fn add_physics<P: WorldPlugin>(&mut self, plugin: P) -> &mut Self {
        if mark_installed::<PhysicsCorePlugin>(self) {
            PhysicsCorePlugin.build(self);
        }
        if mark_installed::<P>(self) {
            plugin.build(self);
        }
        self
    }

    fn step_physics(&mut self) {
        if !self.contains_resource::<PhysicsTime>() {
            return;
        }
        rotate_messages(self);
        run_step(self);
    }

    fn advance_physics(&mut self, frame_dt: f32) -> Result<FrameReport> {
        let Some(mut time) = self.get_resource_mut::<PhysicsTime>() else {
            return Ok(FrameReport::default());
        };
        let (steps, dropped) = time.take_frame(frame_dt)?;
        // Rotate once per frame, so a game reading messages every frame sees every step's.
        rotate_messages(self);
        for _ in 0..steps {
            run_step(self);
        }
        if let Some(mut d) = self.get_resource_mut::<PhysicsDiagnostics>() {
            d.dropped_time = dropped;
        }
        Ok(FrameReport { steps, dropped })
    }
}
