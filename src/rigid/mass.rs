//! Mass properties from parry shapes, and the rigid-body bundle.
//!
//! For a shape of density ρ (kg/m³), parry integrates m = ρ V, the centre of mass c and the
//! inertia tensor about c; compound shapes combine their parts with the parallel-axis
//! theorem, I = I_c + m (|d|² E − d dᵀ) ([`parallel_axis`]). hooke validates the result: a
//! shape with no volume (a flat hull, an open mesh, a heightfield) has no mass and is an
//! error rather than a body that divides by zero.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Mat3, Quat, Vec3};
use parry3d::shape::Shape;

use super::{AngularVelocity, CenterOfMass, Inertia, RigidBody, Rotation, check_density};
use crate::core::error::{Error, Result, finite_vec};
use crate::particles::{LinearVelocity, Mass, Position};

/// The inertia tensor about a point displaced by `d` (m) from the centre of mass:
/// I = I_c + m (|d|² E − d dᵀ).
#[must_use]
pub fn parallel_axis(i_com: Mat3, mass: f32, d: Vec3) -> Mat3 {
    let outer = Mat3::from_cols(d * d.x, d * d.y, d * d.z);
    i_com + mass * (Mat3::from_diagonal(Vec3::splat(d.length_squared())) - outer)
}

/// Mass m (kg), centre of mass c (m, shape frame) and inertia about c.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// m (kg).
    pub mass: f32,
    /// c (m), in the shape's frame.
    pub center_of_mass: Vec3,
    /// Inertia about c, in the shape's frame.
    pub inertia: Inertia,
}

impl MassProperties {
    /// Explicit mass properties (for an override, or a body without a shape).
    ///
    /// # Errors
    /// [`Error::InvalidMass`] or [`Error::NonFinite`].
    pub fn new(mass: f32, center_of_mass: Vec3, inertia: Inertia) -> Result<Self> {
        Mass::new(mass)?;
        Ok(Self {
            mass,
            center_of_mass: finite_vec("center of mass", center_of_mass)?,
            inertia,
        })
    }

    /// From a full inertia tensor about the centre of mass (diagonalised for you).
    ///
    /// # Errors
    /// [`Error::InvalidMass`], [`Error::NonFinite`], or [`Error::NotPositive`] when the
    /// tensor is not positive definite.
    pub fn from_tensor(mass: f32, center_of_mass: Vec3, tensor: Mat3) -> Result<Self> {
        if !tensor.is_finite() {
            return Err(Error::NonFinite {
                what: "inertia tensor",
                value: format!("{tensor}"),
            });
        }
        let sym = 0.5 * (tensor + tensor.transpose());
        let p = parry3d::mass_properties::MassProperties::with_inertia_matrix(
            center_of_mass,
            mass,
            sym,
        );
        // parry clamps negative eigenvalues to zero; read them back to reject them.
        let principal = p.principal_inertia();
        let inertia = Inertia::new(principal, p.principal_inertia_local_frame)?;
        Self::new(mass, center_of_mass, inertia)
    }

    /// Integrates a parry shape at `density` (kg/m³).
    ///
    /// # Errors
    /// [`Error::NotPositive`] for a non-positive density; [`Error::ZeroVolume`] for a shape
    /// with no volume; [`Error::NotPositive`] for a degenerate (not positive-definite)
    /// inertia.
    pub fn from_shape(shape: &dyn Shape, density: f32) -> Result<Self> {
        let density = check_density(density)?;
        let p = shape.mass_properties(density);
        let mass = p.mass();
        if !(mass.is_finite() && mass > 0.0) || p.inv_mass == 0.0 {
            return Err(Error::ZeroVolume(format!("{:?}", shape.shape_type())));
        }
        let inertia = Inertia::new(p.principal_inertia(), p.principal_inertia_local_frame)?;
        Self::new(mass, p.local_com, inertia)
    }

    /// The same body with its mass scaled to `mass` (inertia scales with it).
    ///
    /// # Errors
    /// [`Error::InvalidMass`].
    pub fn with_mass(self, mass: f32) -> Result<Self> {
        Mass::new(mass)?;
        let s = mass / self.mass;
        let inertia = Inertia::new(self.inertia.principal() * s, self.inertia.frame())?;
        Ok(Self {
            mass,
            inertia,
            ..self
        })
    }
}

/// Everything a dynamic or kinematic rigid body needs. Static bodies need only
/// `(RigidBody::Static, Position, Rotation)`; see [`RigidBodyBundle::fixed`].
#[derive(Bundle, Debug, Clone, Copy)]
pub struct RigidBodyBundle {
    /// Dynamic or kinematic.
    pub kind: RigidBody,
    /// Centre of mass in the world (m).
    pub position: Position,
    /// Orientation.
    pub rotation: Rotation,
    /// v (m/s).
    pub velocity: LinearVelocity,
    /// ω (rad/s); sets L = I ω at the first step.
    pub angular_velocity: AngularVelocity,
    /// m.
    pub mass: Mass,
    /// I₀.
    pub inertia: Inertia,
    /// c in the shape frame.
    pub center_of_mass: CenterOfMass,
}

impl RigidBodyBundle {
    /// A dynamic body with the given mass properties, at rest at the origin.
    ///
    /// # Errors
    /// [`Error::InvalidMass`] (only for values built by hand).
    pub fn dynamic(props: MassProperties) -> Result<Self> {
        Ok(Self {
            kind: RigidBody::Dynamic,
            position: Position::default(),
            rotation: Rotation::default(),
            velocity: LinearVelocity::default(),
            angular_velocity: AngularVelocity::default(),
            mass: Mass::new(props.mass)?,
            inertia: props.inertia,
            center_of_mass: CenterOfMass(props.center_of_mass),
        })
    }

    /// A dynamic body from a parry shape and a density (kg/m³).
    ///
    /// # Errors
    /// As [`MassProperties::from_shape`].
    pub fn from_shape(shape: &dyn Shape, density: f32) -> Result<Self> {
        Self::dynamic(MassProperties::from_shape(shape, density)?)
    }

    /// A kinematic body: infinite mass and inertia, moved by the velocities you set.
    #[must_use]
    pub fn kinematic() -> Self {
        Self {
            kind: RigidBody::Kinematic,
            position: Position::default(),
            rotation: Rotation::default(),
            velocity: LinearVelocity::default(),
            angular_velocity: AngularVelocity::default(),
            mass: Mass::PINNED,
            inertia: Inertia::INFINITE,
            center_of_mass: CenterOfMass::default(),
        }
    }

    /// A static body's components: it never moves and no system visits it.
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn fixed(position: Vec3, rotation: Quat) -> Result<(RigidBody, Position, Rotation)> {
        Ok((
            RigidBody::Static,
            Position::try_new(position)?,
            Rotation::try_new(rotation)?,
        ))
    }

    /// Puts the centre of mass at `x` (m).
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn at(mut self, x: Vec3) -> Result<Self> {
        self.position = Position::try_new(x)?;
        Ok(self)
    }

    /// Sets the orientation (normalised).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite or zero quaternion.
    pub fn with_rotation(mut self, q: Quat) -> Result<Self> {
        self.rotation = Rotation::try_new(q)?;
        Ok(self)
    }

    /// Sets the velocity of the centre of mass (m/s).
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn with_velocity(mut self, v: Vec3) -> Result<Self> {
        self.velocity = LinearVelocity::try_new(v)?;
        Ok(self)
    }

    /// Sets the angular velocity (rad/s, world frame).
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn with_angular_velocity(mut self, omega: Vec3) -> Result<Self> {
        self.angular_velocity = AngularVelocity::from(finite_vec("angular velocity", omega)?);
        Ok(self)
    }
}

/// Mass properties hooke computed for a body (from its colliders, or the default for a
/// body with none); a [`Mass`] of a different value is the user's and is left alone.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
pub(crate) struct ComputedMass {
    pub(crate) mass: f32,
}

/// A dynamic body's mass properties when nothing gives any: 1 kg with the inertia of a
/// uniform 1 m cube (m/6 about each axis), centre of mass at the frame origin.
#[must_use]
pub fn default_mass() -> MassProperties {
    MassProperties {
        mass: 1.0,
        center_of_mass: Vec3::ZERO,
        inertia: Inertia::diagonal(1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0).unwrap_or(Inertia::INFINITE),
    }
}

/// Inserts computed mass properties on `body`, keeping its frame origin where it was: the
/// centre of mass x moves by R (c_new − c_old).
pub(crate) fn insert_computed_mass(world: &mut World, body: Entity, props: MassProperties) {
    let Ok(mut e) = world.get_entity_mut(body) else {
        return;
    };
    let Ok(mass) = Mass::new(props.mass) else {
        return;
    };
    let old_c = e.get::<CenterOfMass>().map_or(Vec3::ZERO, |c| c.0);
    let same = e
        .get::<ComputedMass>()
        .is_some_and(|c| c.mass == props.mass)
        && e.get::<Mass>() == Some(&mass)
        && e.get::<Inertia>() == Some(&props.inertia)
        && old_c == props.center_of_mass;
    if same {
        return;
    }
    let q = e.get::<Rotation>().map_or(glam::Quat::IDENTITY, |r| r.0);
    let shift = q * (props.center_of_mass - old_c);
    if shift != Vec3::ZERO
        && let Some(mut x) = e.get_mut::<Position>()
    {
        x.0 += glam::Vec3A::from(shift);
    }
    e.insert((
        mass,
        props.inertia,
        CenterOfMass(props.center_of_mass),
        ComputedMass { mass: props.mass },
    ));
}

/// Insert hook of [`RigidBody`]: the kind decides the mass components. A dynamic body
/// with no [`Mass`] gets [`default_mass`] until its colliders give a better one; a kinematic
/// body gets infinite mass and inertia; a static body loses every mass and velocity
/// component, so no system visits it.
pub(crate) fn body_kind_changed(mut world: DeferredWorld, ctx: HookContext) {
    let body = ctx.entity;
    world
        .commands()
        .queue(move |world: &mut World| apply_body_kind(world, body));
}

fn apply_body_kind(world: &mut World, body: Entity) {
    let Ok(mut e) = world.get_entity_mut(body) else {
        return;
    };
    let Some(kind) = e.get::<RigidBody>().copied() else {
        return;
    };
    let computed = e.get::<ComputedMass>().copied();
    let mass = e.get::<Mass>().copied();
    match kind {
        RigidBody::Dynamic => {
            let stale = match (mass, computed) {
                (None, _) => true,
                // Was kinematic by hooke's doing: dynamic again.
                (Some(m), Some(_)) => m.is_pinned(),
                (Some(_), None) => false,
            };
            if stale {
                insert_computed_mass(world, body, default_mass());
            }
        }
        RigidBody::Kinematic => {
            if mass.is_none_or(|m| !m.is_pinned()) {
                e.insert((
                    Mass::PINNED,
                    Inertia::INFINITE,
                    ComputedMass {
                        mass: f32::INFINITY,
                    },
                ));
            }
        }
        RigidBody::Static => {
            if mass.is_some() || e.contains::<LinearVelocity>() {
                e.remove::<(
                    Mass,
                    Inertia,
                    LinearVelocity,
                    AngularVelocity,
                    crate::rigid::AngularMomentum,
                    crate::particles::Force,
                    crate::rigid::Torque,
                    ComputedMass,
                )>();
            }
        }
    }
}
