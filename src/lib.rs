//! # hooke
//!
//! Physics for entity-component-system games, on `bevy_ecs`: particles, tracers in velocity
//! fields, mass–spring ropes, hair and cloth, rigid bodies with parry collisions, with an
//! integrator dial and NaN quarantine. Works on a bare `World` and, with the `bevy` feature,
//! in a Bevy `App`.
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
//! | [`RigidBodyPlugin`] | orientation, angular momentum, torque, renormalisation | [`Inertia`] ([`RigidBody`]) |
//! | [`CollisionPlugin`] | broad and narrow phase, contact solver, contact messages, [`SpatialQuery`], mass from colliders, child colliders | [`Collider`] |
//! | [`SleepPlugin`] | resting islands stop costing anything | [`Collider`] bodies |
//! | [`soft::SoftBodyPlugin`] | tetrahedral FEM: elastic forces of the four strain models | [`soft::SoftBody`] |
//! | [`cloth::ClothPlugin`] | wind on triangles, strain limiting, node collisions, vertex normals | [`cloth::Cloth`] |
//!
//! With the `bevy` feature, [`PhysicsPlugins`] is also a Bevy `PluginGroup`, every plugin above
//! a Bevy `Plugin`, and [`bevy`] adds the App clock, `Transform` sync, interpolation and
//! diagnostics plugins.
//!
//! | feature | default | what |
//! |---|---|---|
//! | `bevy` | off | `bevy_app`, `bevy_time`, `bevy_transform`, `bevy_diagnostic` 0.20: see [`bevy`] |
//!
//! ## Spawning
//!
//! Required components do the rest: a dynamic body needs a kind and a shape.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! world.spawn((
//!     RigidBody::Static,
//!     Collider::cuboid(10.0, 0.5, 10.0).unwrap(), // half extents (m)
//!     Position::from(Vec3::new(0.0, -0.5, 0.0)),
//! ));
//! let crate_ = world
//!     .spawn((
//!         RigidBody::Dynamic,
//!         Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
//!         Position::from(Vec3::new(0.0, 3.0, 0.0)),
//!     ))
//!     .id();
//! // Mass from the shape at the default 1000 kg/m³.
//! let kg = world.get::<Mass>(crate_).unwrap().value();
//! assert!((kg - 1000.0).abs() < 0.01, "{kg}");
//! for _ in 0..120 {
//!     world.step_physics();
//! }
//! let y = world.get::<Position>(crate_).unwrap().get().y;
//! assert!((y - 0.5).abs() < 0.02, "resting on the ground: {y}");
//! ```
//!
//! A collider on a child entity is a part of its parent body:
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! let body = world.spawn(RigidBody::Dynamic).id();
//! for x in [-1.0, 1.0] {
//!     world.spawn((
//!         Collider::ball(0.5).unwrap(),
//!         ColliderOffset::try_new(Vec3::new(x, 0.0, 0.0), Quat::IDENTITY).unwrap(),
//!         ChildOf(body),
//!     ));
//! }
//! let mass = world.get::<Mass>(body).unwrap().value();
//! assert!((mass - 2.0 * 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.125).abs() < 1.0);
//! ```
//!
//! Ropes, hair and cloth come from builders, on a `World` or from `Commands`:
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! let rope = ChainBuilder::rope(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), 11)
//!     .stiffness(500.0)
//!     .spawn(&mut world)
//!     .unwrap();
//! world.step_physics();
//! let end = world.get::<Position>(*rope.nodes.last().unwrap()).unwrap().get();
//! assert!(end.y < 0.0); // the free end falls; the first node is pinned
//! ```
//!
//! Bad values are typed errors, never panics:
//!
//! ```
//! use hooke::prelude::*;
//! assert!(matches!(Collider::ball(-1.0), Err(Error::NotPositive { .. })));
//! assert!(matches!(Mass::new(f32::NAN), Err(Error::InvalidMass(_))));
//! ```
//!
//! ## Scenarios and tests
//!
//! [`scenario`] runs RON files that build a scene, act on it on a timeline and check
//! expectations (the `hooke` command with the `cli` feature runs them from a shell);
//! [`testing`] has the helpers a `#[test]` steps a world with.
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

pub mod accuracy;
#[cfg(feature = "bevy")]
pub mod bevy;
pub mod cloth;
pub mod collision;
pub mod diagnostics;
pub mod error;
pub mod integrator;
mod order;
pub mod particles;
pub mod quarantine;
pub mod rest;
pub mod restore;
pub mod rigid;
pub mod scenario;
pub mod scenes;
pub mod schedule;
pub mod sleep;
pub mod snapshot;
pub mod soft;
pub mod springs;
pub mod testing;
pub mod time;
pub mod whole_step;

/// parry, re-exported so custom shapes ([`Collider::new`]) need no second dependency.
pub use parry3d;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;

pub use cloth::{Cloth, ClothBuilder, ClothMaterial, ClothPlugin};
pub use collision::{
    Collider, ColliderChanges, ColliderDensity, ColliderOf, ColliderOffset, CollisionEventsEnabled,
    CollisionLayers, CollisionPlugin, CombineRule, ContactEnd, ContactEnded, ContactSettings,
    ContactStart, ContactStarted, Contacts, Friction, Restitution, RestitutionThreshold, Sensor,
    SpatialQuery,
};
pub use diagnostics::{DiagnosticsSettings, PhysicsDiagnostics};
pub use error::{Error, Result};
pub use integrator::{
    ConstraintsActive, ImplicitEuler, ImplicitState, Integrator, IntegratorOverride,
    IntegratorPlugin,
};
pub use particles::{
    Advection, DampingPlugin, ExternalForce, ExternalImpulse, Force, Gravity, GravityPlugin,
    GravityScale, LinearDamping, LinearVelocity, Mass, Nodes, ParticleBundle, Position, Tracer,
    VelocityField, VelocityFieldPlugin,
};
pub use quarantine::{BodyQuarantined, DivergenceGuard, QuarantineReason, Quarantined};
pub use rigid::{
    AngularDamping, AngularMomentum, AngularVelocity, CenterOfMass, ExternalForceAtPoint,
    ExternalImpulseAtPoint, ExternalTorque, Inertia, KinematicTarget, MassProperties,
    OrientationUpdate, Renormalization, RigidBody, RigidBodyBundle, RigidBodyPlugin, Rotation,
    SkipRenormalization, Torque,
};
pub use schedule::{
    ForceSchedule, ForceSystems, ImplicitSystems, PhysicsSchedule, PhysicsSystems, RelaxSystems,
    StepSystems, SubstepSchedule,
};
pub use sleep::{SleepPlugin, SleepSettings, Sleeping, SleepingDisabled};
pub use springs::{
    Chain, ChainBuilder, EntitySpringStability, Spring, SpringNetwork, SpringPlugin, SpringReading,
    SpringStability, StabilityPolicy, StabilityWarning,
};
pub use time::{FrameReport, PhysicsTime, SubstepTime};
pub use whole_step::FusedSubsteps;

/// Everything a game needs in scope.
pub mod prelude {
    #[cfg(feature = "bevy")]
    pub use crate::bevy::{
        PhysicsAppSystems, PhysicsDiagnosticsPlugin, PhysicsSchedulePlugin, TransformExtrapolation,
        TransformInterpolation,
    };
    pub use crate::{
        Advection, BodyQuarantined, ChainBuilder, ClothBuilder, DiagnosticsSettings, Error,
        ExternalForce, ExternalImpulse, Force, Gravity, GravityScale, Integrator,
        IntegratorOverride, LinearDamping, LinearVelocity, Mass, Nodes, ParticleBundle,
        PhysicsDiagnostics, PhysicsPlugins, PhysicsTime, PhysicsWorldExt, Position,
        QuarantineReason, Quarantined, Spring, SpringNetwork, Tracer, VelocityField, WorldPlugin,
    };
    pub use crate::{
        AngularVelocity, CenterOfMass, Collider, ColliderDensity, ColliderOf, ColliderOffset,
        CollisionEventsEnabled, ContactEnd, ContactStart, Contacts, Friction, Inertia,
        MassProperties, Restitution, RigidBody, RigidBodyBundle, Rotation, Sensor, Sleeping,
        SpatialQuery,
    };
    pub use crate::{CollisionLayers, ContactEnded, ContactStarted};
    pub use glam::{Quat, Vec3, Vec3A};
}

/// A piece of physics that installs itself into a `World`: resources and systems.
pub trait WorldPlugin: 'static {
    /// Adds the plugin's resources and systems. Called once per world.
    fn build(&self, world: &mut World);
}

/// Anything the substeps could move.
type AnyBody = Or<(With<Mass>, With<Nodes>, With<Tracer>)>;

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
        restore::init::<PhysicsTime>(world);
        restore::init::<Messages<restore::ResourceRestored>>(world);
        restore::init::<Messages<restore::InvalidSetting>>(world);
        schedule::add_own_systems(
            world,
            PhysicsSchedule,
            restore::restore_resources.in_set(PhysicsSystems::Restore),
        );
        schedule::add_own_systems(
            world,
            PhysicsSchedule,
            quarantine::quarantine_runaway_velocities.in_set(schedule::PrepareSystems::Guard),
        );
        crate::restore::init::<SubstepTime>(world);
        crate::restore::init::<FusedSubsteps>(world);
        crate::restore::init::<Messages<BodyQuarantined>>(world);
        crate::restore::init::<quarantine::DivergenceGuard>(world);
        schedule::add_own_systems(
            world,
            PhysicsSchedule,
            time::run_substeps::<AnyBody>.in_set(PhysicsSystems::Step),
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
            .add_physics(SleepPlugin)
            .add_physics(soft::SoftBodyPlugin)
            .add_physics(cloth::ClothPlugin);
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
    if let Some(mut m) = world.get_resource_mut::<Messages<springs::StabilityWarning>>() {
        m.update();
    }
    if let Some(mut m) = world.get_resource_mut::<Messages<restore::ResourceRestored>>() {
        m.update();
    }
    if let Some(mut m) = world.get_resource_mut::<Messages<restore::InvalidSetting>>() {
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
            // The clock itself was removed (the step's own restore pass would not run):
            // put everything back first; without the core plugin this does nothing.
            restore::restore_resources(self);
            if !self.contains_resource::<PhysicsTime>() {
                return;
            }
        }
        rotate_messages(self);
        run_step(self);
    }

    fn advance_physics(&mut self, frame_dt: f32) -> Result<FrameReport> {
        if !self.contains_resource::<PhysicsTime>() {
            restore::restore_resources(self);
        }
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
