//! Particles: the state every body with a centre of mass shares, and massless tracers.
//!
//! A **particle** is [`Position`] x (m), [`LinearVelocity`] v (m/s), [`Mass`] m (kg) and the
//! [`Force`] accumulator f (N); spawning a [`Mass`] brings the other three along as required
//! components. Newton's second law, as in the lecture:
//!
//! ```text
//! dx/dt = v,    dv/dt = f / m
//! ```
//!
//! Optional per-body effects: [`GravityScale`], [`LinearDamping`] (f = −c m v), a persistent
//! [`ExternalForce`] and a one-shot [`ExternalImpulse`] (Δv = J / m).
//!
//! A **tracer** is massless: a [`Position`] and the [`Tracer`] marker, advected through the
//! sum of all [`VelocityField`]s (see [`fields`]): dx/dt = u(x, t).
//!
//! A **mesh** keeps many particles in one component, [`Nodes`], as structure-of-arrays; the
//! same gravity, damping and integrators act on them.

pub mod fields;
mod nodes;
mod plugin;

pub use fields::{Advection, Gravity, VelocityField};
pub use nodes::Nodes;
pub use plugin::{DampingPlugin, GravityPlugin, VelocityFieldPlugin};

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::{Validate, validate_on_insert};

macro_rules! finite_vec_component {
    ($(#[$doc:meta])* $name:ident($ty:ty), $what:literal) => {
        $(#[$doc])*
        #[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default)]
        #[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
        #[component(on_insert = validate_on_insert::<Self>)]
        pub struct $name(pub $ty);

        impl Validate for $name {
            fn validate(&self) -> Result<()> {
                finite_vec($what, Vec3::from(self.0)).map(|_| ())
            }
        }

        impl $name {
            #[doc = concat!("A validated `", stringify!($name), "`.")]
            ///
            /// # Errors
            /// [`Error::NonFinite`] for NaN or infinite components.
            pub fn try_new(value: Vec3) -> Result<Self> {
                finite_vec($what, value).map(|v| Self(v.into()))
            }

            /// The value as a plain `Vec3`.
            #[must_use]
            pub fn get(&self) -> Vec3 {
                self.0.into()
            }
        }

        impl From<Vec3> for $name {
            fn from(v: Vec3) -> Self {
                Self(v.into())
            }
        }
    };
}

finite_vec_component!(
    /// World position of the centre of mass (m). Stored as `Vec3A` (16 bytes, SIMD): the
    /// integration loops run twice as fast as over 12-byte `Vec3`s.
    Position(Vec3A),
    "position"
);
finite_vec_component!(
    /// Velocity of the centre of mass (m/s). `Vec3A`, like [`Position`].
    LinearVelocity(Vec3A),
    "velocity"
);
finite_vec_component!(
    /// A force (N) added to the body after every force clear, until changed or removed.
    /// Writing it from gameplay code is safe: the step never wipes it. Bodies do not carry
    /// one until given it, so `Query<&mut ExternalForce>` skips them:
    /// `commands.entity(body).set_force(f)` ([`crate::rigid::BodyForces`]) inserts it.
    ExternalForce(Vec3),
    "external force"
);
finite_vec_component!(
    /// A one-shot impulse (N·s): at the next substep Δv = J / m, then it is reset to zero.
    /// `commands.entity(body).apply_impulse(j)` ([`crate::rigid::BodyForces`]) adds one to a
    /// body that has none yet.
    ExternalImpulse(Vec3),
    "impulse"
);

/// The force accumulator (N): reset to [`ExternalForce`] (or zero) at the start of every
/// force evaluation, then every effect adds into it. Read it after a step to see the forces
/// of the last evaluation. `Vec3A`, like [`Position`].
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Force(pub Vec3A);

/// Mass (kg), stored with its inverse. An infinite mass pins the body: forces don't move it,
/// but a velocity you give it does (a kinematic particle).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(Position, LinearVelocity, Force)]
#[component(on_remove = quarantine_massless)]
pub struct Mass {
    /// m, or 0 for pinned bodies so that m·g and m·c·v vanish without a branch.
    mass: f32,
    inverse: f32,
}

/// Bodies that may go without a [`Mass`] on purpose, by the effects that own them (a rigid
/// body made static): each entry says whether an entity is one.
#[derive(Resource, Default)]
pub(crate) struct MassOptional(pub(crate) Vec<fn(&EntityRef) -> bool>);

/// A body whose [`Mass`] is removed is neither integrated nor checked any more: it would
/// hang where it is, and a NaN written into it later would go unseen. It is quarantined
/// instead, and reported. Not a despawn, a tracer (massless by design) or what
/// [`MassOptional`] exempts.
fn quarantine_massless(
    mut world: bevy_ecs::world::DeferredWorld,
    ctx: bevy_ecs::lifecycle::HookContext,
) {
    let entity = ctx.entity;
    world.commands().queue(move |world: &mut World| {
        let Ok(e) = world.get_entity(entity) else {
            return;
        };
        let optional = world
            .get_resource::<MassOptional>()
            .is_some_and(|m| m.0.iter().any(|exempt| exempt(&e)));
        if optional
            || e.contains::<Mass>()
            || e.contains::<Tracer>()
            || e.contains::<crate::core::quarantine::Quarantined>()
            || !e.contains::<LinearVelocity>()
        {
            return;
        }
        world
            .entity_mut(entity)
            .insert(crate::core::quarantine::Quarantined {
                reason: crate::core::quarantine::QuarantineReason::InvalidInput(
                    Error::ComponentRemoved("Mass"),
                ),
            });
    });
}

impl Mass {
    /// A pinned (infinitely massive) body.
    pub const PINNED: Mass = Mass {
        mass: 0.0,
        inverse: 0.0,
    };

    /// A mass of `kg` kilograms.
    ///
    /// # Errors
    /// [`Error::InvalidMass`] unless `kg` is positive and finite.
    pub fn new(kg: f32) -> Result<Self> {
        if kg.is_finite() && kg > 0.0 && (1.0 / kg).is_finite() {
            Ok(Self {
                mass: kg,
                inverse: 1.0 / kg,
            })
        } else {
            Err(Error::InvalidMass(kg))
        }
    }

    /// The mass (kg); infinite for a pinned body.
    #[must_use]
    pub fn value(&self) -> f32 {
        if self.inverse == 0.0 {
            f32::INFINITY
        } else {
            self.mass
        }
    }

    /// 1/m (1/kg); zero for a pinned body.
    #[must_use]
    pub fn inverse(&self) -> f32 {
        self.inverse
    }

    /// m for force laws that scale with mass (gravity, damping); zero for a pinned body.
    #[must_use]
    pub(crate) fn force_scale(&self) -> f32 {
        self.mass
    }

    /// True for a pinned body.
    #[must_use]
    pub fn is_pinned(&self) -> bool {
        self.inverse == 0.0
    }
}

/// Multiplies gravity for one body (dimensionless; 1 by default, 0 to float).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct GravityScale(pub f32);

impl Default for GravityScale {
    fn default() -> Self {
        Self(1.0)
    }
}

impl Validate for GravityScale {
    fn validate(&self) -> Result<()> {
        finite("gravity scale", self.0).map(|_| ())
    }
}

/// Linear drag coefficient c (1/s): f = −c m v, so velocity decays like e^(−c t).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct LinearDamping(pub f32);

impl Validate for LinearDamping {
    fn validate(&self) -> Result<()> {
        non_negative("linear damping", self.0).map(|_| ())
    }
}

/// A massless particle advected by velocity fields.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(Position)]
pub struct Tracer;

/// Spawnable particle: position, velocity and mass, validated together.
#[derive(Bundle, Debug, Clone, Copy)]
pub struct ParticleBundle {
    /// x (m).
    pub position: Position,
    /// v (m/s).
    pub velocity: LinearVelocity,
    /// m (kg).
    pub mass: Mass,
}

impl ParticleBundle {
    /// A particle at `x` (m) moving at `v` (m/s) with mass `kg`.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite `x` or `v`; [`Error::InvalidMass`] for a bad mass.
    pub fn new(x: Vec3, v: Vec3, kg: f32) -> Result<Self> {
        Ok(Self {
            position: Position::try_new(x)?,
            velocity: LinearVelocity::try_new(v)?,
            mass: Mass::new(kg)?,
        })
    }

    /// A pinned particle at `x` (m).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite `x`.
    pub fn pinned(x: Vec3) -> Result<Self> {
        Ok(Self {
            position: Position::try_new(x)?,
            velocity: LinearVelocity::default(),
            mass: Mass::PINNED,
        })
    }
}
