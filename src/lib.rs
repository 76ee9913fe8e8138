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
//! | [`PhysicsCorePlugin`](crate::core::plugin::PhysicsCorePlugin) (always) | the kernel: schedules, time, quarantine, restored resources, diagnostics | everything |
//! | [`IntegratorPlugin`](crate::integrator::IntegratorPlugin) (always) | the integrator dial, external forces and impulses, the divergence guard | [`Mass`](crate::particles::Mass), [`Nodes`](crate::particles::Nodes) |
//! | [`GravityPlugin`](crate::particles::GravityPlugin) | f = m g s | [`Mass`](crate::particles::Mass), [`Nodes`](crate::particles::Nodes) |
//! | [`DampingPlugin`](crate::particles::DampingPlugin) | f = −c m v | [`LinearDamping`](crate::particles::LinearDamping) |
//! | [`VelocityFieldPlugin`](crate::particles::VelocityFieldPlugin) | dx/dt = Σ u(x, t) | [`Tracer`](crate::particles::Tracer), [`VelocityField`](crate::particles::VelocityField) |
//! | [`SpringPlugin`](crate::springs::SpringPlugin) | damped springs | [`Spring`](crate::springs::Spring), [`SpringNetwork`](crate::springs::SpringNetwork) |
//! | [`RigidBodyPlugin`](crate::rigid::RigidBodyPlugin) | orientation, angular momentum, torque, renormalisation | [`Inertia`](crate::rigid::Inertia) ([`RigidBody`](crate::rigid::RigidBody)) |
//! | [`CollisionPlugin`](crate::collision::CollisionPlugin) | broad and narrow phase, contact solver, contact messages, [`SpatialQuery`](crate::collision::SpatialQuery), mass from colliders, child colliders | [`Collider`](crate::collision::Collider) |
//! | [`SleepPlugin`](crate::sleep::SleepPlugin) | resting islands stop costing anything | [`Collider`](crate::collision::Collider) bodies |
//! | [`soft::SoftBodyPlugin`] | tetrahedral FEM: elastic forces of the four strain models | [`soft::SoftBody`] |
//! | [`cloth::ClothPlugin`] | wind on triangles, strain limiting, node collisions, vertex normals | [`cloth::Cloth`] |
//! | [`character::CharacterControllerPlugin`] | move-and-slide, slopes, steps, ground snapping, platforms, pushing | [`character::CharacterController`] |
//!
//! With the `bevy` feature, [`PhysicsPlugins`] is also a Bevy `PluginGroup`, every plugin above
//! a Bevy `Plugin`, and the `bevy` module adds the App clock, `Transform` sync, interpolation and
//! diagnostics plugins.
//!
//! | feature | default | what |
//! |---|---|---|
//! | `bevy` | off | `bevy_app`, `bevy_time`, `bevy_transform`, `bevy_diagnostic` 0.20: the `bevy` module |
//! | `collider-from-mesh` | off | `bevy_mesh` 0.20: colliders from a `Mesh` (`Collider::trimesh_from_mesh`, ...) |
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
//! [`tools::scenario`] runs RON files that build a scene, act on it on a timeline and check
//! expectations (the `hooke` command with the `cli` feature runs them from a shell);
//! [`tools::testing`] has the helpers a `#[test]` steps a world with.
//!
//! ## Order
//!
//! [`core::schedule`] declares it, once: clear forces → apply forces → accumulate torque →
//! integrate velocities → solve constraints → integrate positions → complete stages →
//! renormalise, repeated `substeps` times per step.
//!
//! ## Units
//!
//! SI throughout: m, s, kg, N. Angles in radians.

#![warn(missing_docs)]

#[cfg(feature = "bevy")]
pub mod bevy;
pub mod character;
pub mod cloth;
pub mod collision;
pub mod core;
pub mod integrator;
pub mod joints;
pub mod particles;
mod plugins;
pub mod rigid;
pub mod sleep;
pub mod snapshot;
pub mod soft;
pub mod springs;
#[cfg(feature = "tools")]
pub mod tools;

/// parry, re-exported so custom shapes ([`Collider::new`](crate::collision::Collider::new)) need no second dependency.
pub use parry3d;

/// `bevy_mesh`, re-exported for building the meshes colliders are made from.
#[cfg(feature = "collider-from-mesh")]
pub use bevy_mesh;

pub use crate::core::error::{Error, Result};
pub use crate::plugins::{PhysicsPlugins, PhysicsWorldExt};

/// Everything a game needs in scope.
pub mod prelude {
    pub use crate::Error;
    pub use crate::PhysicsPlugins;
    pub use crate::PhysicsWorldExt;
    #[cfg(feature = "bevy")]
    pub use crate::bevy::{
        PhysicsAppSystems, PhysicsDiagnosticsPlugin, PhysicsSchedulePlugin, TransformExtrapolation,
        TransformInterpolation,
    };
    pub use crate::character::CharacterController;
    pub use crate::character::CharacterInput;
    pub use crate::character::CharacterState;
    pub use crate::cloth::ClothBuilder;
    pub use crate::collision::ActiveCollisionHooks;
    pub use crate::collision::Collider;
    pub use crate::collision::ColliderDensity;
    pub use crate::collision::ColliderOf;
    pub use crate::collision::ColliderOffset;
    pub use crate::collision::CollisionEventsEnabled;
    pub use crate::collision::CollisionHooks;
    pub use crate::collision::CollisionHooksPlugin;
    pub use crate::collision::CollisionLayers;
    pub use crate::collision::ContactEdit;
    pub use crate::collision::ContactEnd;
    pub use crate::collision::ContactEnded;
    pub use crate::collision::ContactReport;
    pub use crate::collision::ContactReporting;
    pub use crate::collision::ContactStart;
    pub use crate::collision::ContactStarted;
    pub use crate::collision::Contacts;
    pub use crate::collision::Friction;
    pub use crate::collision::LayerMask;
    pub use crate::collision::PhysicsLayer;
    pub use crate::collision::Restitution;
    pub use crate::collision::Sensor;
    pub use crate::collision::SpatialQuery;
    pub use crate::core::diagnostics::DiagnosticsSettings;
    pub use crate::core::diagnostics::PhysicsDiagnostics;
    pub use crate::core::plugin::WorldPlugin;
    pub use crate::core::quarantine::BodyQuarantined;
    pub use crate::core::quarantine::QuarantineReason;
    pub use crate::core::quarantine::Quarantined;
    pub use crate::core::rest::Sleeping;
    pub use crate::core::time::PhysicsTime;
    pub use crate::integrator::Integrator;
    pub use crate::integrator::IntegratorOverride;
    pub use crate::joints::AngularMotor;
    pub use crate::joints::DistanceJoint;
    pub use crate::joints::FixedJoint;
    pub use crate::joints::JointBreakForce;
    pub use crate::joints::JointBroken;
    pub use crate::joints::JointDiagnostics;
    pub use crate::joints::JointImpulse;
    pub use crate::joints::JointLimits;
    pub use crate::joints::LinearMotor;
    pub use crate::joints::MotorSpring;
    pub use crate::joints::PrismaticJoint;
    pub use crate::joints::RevoluteJoint;
    pub use crate::joints::SphericalJoint;
    pub use crate::particles::Advection;
    pub use crate::particles::ExternalForce;
    pub use crate::particles::ExternalImpulse;
    pub use crate::particles::Force;
    pub use crate::particles::Gravity;
    pub use crate::particles::GravityScale;
    pub use crate::particles::LinearDamping;
    pub use crate::particles::LinearVelocity;
    pub use crate::particles::Mass;
    pub use crate::particles::Nodes;
    pub use crate::particles::ParticleBundle;
    pub use crate::particles::Position;
    pub use crate::particles::Tracer;
    pub use crate::particles::VelocityField;
    pub use crate::rigid::AngularVelocity;
    pub use crate::rigid::BodyForces;
    pub use crate::rigid::CenterOfMass;
    pub use crate::rigid::Dominance;
    pub use crate::rigid::Inertia;
    pub use crate::rigid::LockedAxes;
    pub use crate::rigid::MassProperties;
    pub use crate::rigid::MaxAngularSpeed;
    pub use crate::rigid::MaxLinearSpeed;
    pub use crate::rigid::RigidBody;
    pub use crate::rigid::RigidBodyBundle;
    pub use crate::rigid::Rotation;
    pub use crate::springs::ChainBuilder;
    pub use crate::springs::Spring;
    pub use crate::springs::SpringNetwork;
    pub use glam::{Quat, Vec3, Vec3A};
}
