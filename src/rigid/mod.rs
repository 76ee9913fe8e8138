//! Rigid bodies: the lecture's state (x, R, P, L).
//!
//! A rigid body is a particle ([`crate::particles::Position`] = centre of mass x, [`crate::particles::LinearVelocity`]
//! v = P/M, [`crate::particles::Mass`], [`crate::particles::Force`]) plus an orientation and angular momentum:
//!
//! ```text
//! dx/dt = v          dP/dt = f
//! dq/dt = ½ ω ⊗ q    dL/dt = τ
//! I = R I₀ Rᵀ,       ω = I⁻¹ L
//! ```
//!
//! - [`Rotation`] q is a unit quaternion (body → world).
//! - [`AngularMomentum`] L (kg·m²/s, world frame) is the state that is integrated.
//! - [`AngularVelocity`] ω (rad/s, world frame) is derived from L after every substep. Writing
//!   it from game code sets L = I ω at the next step (so "spin at 5 rad/s" just works).
//!   Writing [`AngularMomentum`] instead sets ω = I⁻¹ L. hooke itself updates both without
//!   change ticks, so `Changed<AngularVelocity>` means "a user wrote it".
//! - [`Inertia`] holds I₀ by its principal moments and principal frame, and their inverse.
//! - [`Torque`] τ (N·m) accumulates like [`crate::particles::Force`]: cleared to [`ExternalTorque`], then
//!   springs at anchors and [`ExternalForceAtPoint`]s add r × f.
//! - [`CenterOfMass`] is the centre of mass in the shape's frame: the body's frame origin is
//!   x − R c.
//!
//! **Orientation update** ([`OrientationUpdate`]). With ω fixed over a step, the
//! first-order update q ← q + ½ h ω ⊗ q grows |q| by √(1 + (|ω|h/2)²) per step; the
//! exponential map q ← exp(½ h ω) ⊗ q is exact for constant ω and keeps |q| = 1. Both hold
//! ω = I(q)⁻¹L at the start orientation, and on an asymmetric body that pumps energy in: a
//! spin about the major axis creeps towards the minor axis. The default is therefore a
//! free-rotation splitting ([`free_rotation_split`]): symplectic, |L| exact, energy error
//! bounded. A body with three equal moments (a sphere, a cube) has constant ω = L/I, and the
//! splitting takes the exact single turn exp(½ h ω) for it. RK4 integrates q as a 4-vector
//! with the derivative ½ ω ⊗ q at each stage. The
//! [`StepSystems::Renormalize`](crate::core::schedule::StepSystems::Renormalize) set renormalises q every
//! substep unless [`Renormalization`] is off (to show its effect) or a body has
//! [`SkipRenormalization`].
//!
//! **Kinds.** [`RigidBody::Dynamic`] bodies respond to forces. [`RigidBody::Kinematic`] bodies
//! have infinite mass and inertia and move with the velocities you set, or toward a
//! [`KinematicTarget`]. [`RigidBody::Static`] bodies have no mass components at all, so no
//! physics system ever visits them.

pub(crate) mod dominance;
mod forces;
mod limits;
mod locked;
mod mass;
mod plugin;

pub use dominance::Dominance;
pub use forces::BodyForces;
pub use limits::{MaxAngularSpeed, MaxLinearSpeed, speed_scale};
pub use locked::LockedAxes;
pub(crate) use locked::{free_mask as translation_mask, hold_locked_translations};
pub(crate) use mass::{ComputedMass, insert_computed_mass};
pub use mass::{MassProperties, RigidBodyBundle, default_mass, parallel_axis};
pub use plugin::RigidBodyPlugin;
pub(crate) use plugin::turn;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};

use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::{Validate, validate_on_insert};
use crate::particles::Position;

/// How a rigid body moves.
///
/// Spawn a body the way Bevy spawns anything, with required components:
/// `(RigidBody::Dynamic, Collider::cuboid(0.5, 0.5, 0.5)?, Position(..))` is a dynamic body
/// whose mass, centre of mass and inertia come from its colliders and their
/// [`crate::collision::ColliderDensity`] (1000 kg/m³ by default). A [`crate::particles::Mass`] you give replaces
/// the mass, and the colliders' inertia is scaled to it (give an [`Inertia`] too, or use
/// [`RigidBodyBundle`], to set both). Inserting another kind later changes the body: kinematic
/// bodies get infinite mass and inertia, static bodies lose their mass and velocity
/// components.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(Position, Rotation)]
#[cfg_attr(feature = "bevy", require(bevy_transform::components::Transform))]
#[component(on_insert = mass::body_kind_changed)]
pub enum RigidBody {
    /// Moved by forces and torques.
    #[default]
    Dynamic,
    /// Moved by the velocities (or [`KinematicTarget`]) you give it; pushes, never pushed.
    Kinematic,
    /// Never moves.
    Static,
}

/// Orientation q, a unit quaternion from body to world frame.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct Rotation(pub Quat);

impl Default for Rotation {
    fn default() -> Self {
        Self(Quat::IDENTITY)
    }
}

impl Validate for Rotation {
    fn validate(&self) -> Result<()> {
        let q = self.0;
        if !q.is_finite() || q.length_squared() < 1e-12 {
            return Err(Error::NonFinite {
                what: "rotation (finite and non-zero)",
                value: format!("{q}"),
            });
        }
        Ok(())
    }
}

impl Rotation {
    /// A validated rotation, normalised.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite or zero quaternion.
    pub fn try_new(q: Quat) -> Result<Self> {
        // Scaled by its largest component first: |q|² of (0, 0, 0, 1e20) overflows f32, and
        // normalising it directly gave the zero quaternion.
        let big = glam::Vec4::from(q).abs().max_element();
        if !(big.is_finite() && big > 0.0) {
            return Err(Error::NonFinite {
                what: "rotation (finite and non-zero)",
                value: format!("{q}"),
            });
        }
        let scaled = Quat::from_vec4(glam::Vec4::from(q) / big);
        Rotation(scaled).validate()?;
        Ok(Self(scaled.normalize()))
    }
}

macro_rules! angular_vec {
    ($(#[$doc:meta])* $name:ident, $what:literal) => {
        $(#[$doc])*
        #[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default)]
        #[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
        #[component(on_insert = validate_on_insert::<Self>)]
        pub struct $name(pub Vec3A);

        impl Validate for $name {
            fn validate(&self) -> Result<()> {
                finite_vec($what, self.0.into()).map(|_| ())
            }
        }

        impl From<Vec3> for $name {
            fn from(v: Vec3) -> Self {
                Self(v.into())
            }
        }

        impl $name {
            /// The value as a plain `Vec3`.
            #[must_use]
            pub fn get(&self) -> Vec3 {
                self.0.into()
            }
        }
    };
}

angular_vec!(
    /// ω (rad/s, world frame), derived from L every substep; writing it sets L = I ω.
    AngularVelocity,
    "angular velocity"
);
angular_vec!(
    /// L (kg·m²/s, world frame): the integrated rotational state.
    AngularMomentum,
    "angular momentum"
);
angular_vec!(
    /// A torque (N·m, world frame) added after every clear, until changed or removed
    /// (`commands.entity(body).set_torque(t)`, [`BodyForces`], inserts it).
    ExternalTorque,
    "external torque"
);

/// The torque accumulator τ (N·m, world frame), like [`crate::particles::Force`].
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Torque(pub Vec3A);

/// Centre of mass in the body's shape frame (m). The frame origin in the world is x − R c.
/// Checked on insert, and where contacts read it (a non-finite one quarantines its body).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct CenterOfMass(pub Vec3);

impl Validate for CenterOfMass {
    fn validate(&self) -> Result<()> {
        finite_vec("center of mass", self.0).map(|_| ())
    }
}

/// The body-frame inertia tensor I₀ = F diag(p) Fᵀ, stored by its principal moments p
/// (kg·m²) and principal frame F, with the inverse moments. Infinite moments (inverse 0)
/// make a body that torques cannot turn.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(AngularMomentum, AngularVelocity, Torque, Rotation)]
#[component(on_insert = locked::lock_inserted_inertia)]
pub struct Inertia {
    principal: Vec3A,
    inverse: Vec3A,
    frame: Quat,
    /// The world axes a [`LockedAxes`] holds the body from turning about (bits 0–2: x, y, z);
    /// kept here so that every ω = I⁻¹ L sees them.
    #[serde(default)]
    locked: u8,
}

impl Inertia {
    /// Infinite inertia: torque never changes the spin (kinematic bodies).
    pub const INFINITE: Inertia = Inertia {
        principal: Vec3A::INFINITY,
        inverse: Vec3A::ZERO,
        frame: Quat::IDENTITY,
        locked: 0,
    };

    /// Principal moments `principal` (kg·m²) about the axes of `frame` (body frame).
    ///
    /// # Errors
    /// [`Error::NotPositive`] unless every moment is positive and finite (the tensor must be
    /// positive definite), [`Error::NonFinite`] for a bad frame.
    pub fn new(principal: Vec3, frame: Quat) -> Result<Self> {
        for p in principal.to_array() {
            if !(p.is_finite() && p > 0.0 && (1.0 / p).is_finite()) {
                return Err(Error::NotPositive {
                    what: "principal moment of inertia",
                    value: p,
                });
            }
        }
        let frame = Rotation::try_new(frame)?.0;
        Ok(Self {
            principal: principal.into(),
            inverse: principal.recip().into(),
            frame,
            locked: 0,
        })
    }

    /// Inertia of a diagonal tensor diag(ixx, iyy, izz) in the body frame.
    ///
    /// # Errors
    /// As [`Inertia::new`].
    pub fn diagonal(ixx: f32, iyy: f32, izz: f32) -> Result<Self> {
        Self::new(Vec3::new(ixx, iyy, izz), Quat::IDENTITY)
    }

    /// Principal moments (kg·m²).
    #[must_use]
    pub fn principal(&self) -> Vec3 {
        self.principal.into()
    }

    /// Principal frame in the body frame.
    #[must_use]
    pub fn frame(&self) -> Quat {
        self.frame
    }

    /// The body-frame tensor I₀ as a matrix.
    #[must_use]
    pub fn tensor(&self) -> glam::Mat3 {
        let f = glam::Mat3::from_quat(self.frame);
        f * glam::Mat3::from_diagonal(self.principal.into()) * f.transpose()
    }

    /// The world inverse tensor I⁻¹ = R F diag(1/p) Fᵀ Rᵀ for orientation `q`.
    #[must_use]
    pub fn world_inverse_tensor(&self, q: Quat) -> glam::Mat3 {
        if self.locked != 0 {
            return self.world_tensors(q).1.into();
        }
        let r = glam::Mat3::from_quat(unit(q) * self.frame);
        r * glam::Mat3::from_diagonal(self.inverse.into()) * r.transpose()
    }

    /// The world tensor I = R I₀ Rᵀ and its inverse for orientation `q`, from one rotation
    /// matrix (zero inverse for infinite inertia). Equal moments give exact diagonals: the
    /// product through R left off-diagonal terms of 1e-8 relative and moments off by as
    /// much, which disagreed with [`Self::angular_velocity`]'s exact L/I.
    #[must_use]
    pub fn world_tensors(&self, q: Quat) -> (glam::Mat3A, glam::Mat3A) {
        if self.locked != 0 {
            return self.locked_world_tensors(q);
        }
        if self.is_isotropic() && !self.is_infinite() {
            return (
                glam::Mat3A::from_diagonal(self.principal.into()),
                glam::Mat3A::from_diagonal(self.inverse.into()),
            );
        }
        let r = glam::Mat3A::from_quat(unit(q) * self.frame);
        let scaled =
            |d: Vec3A| glam::Mat3A::from_cols(r.x_axis * d.x, r.y_axis * d.y, r.z_axis * d.z);
        let rt = r.transpose();
        let tensor = if self.is_infinite() {
            glam::Mat3A::ZERO
        } else {
            scaled(self.principal) * rt
        };
        (tensor, scaled(self.inverse) * rt)
    }

    /// The largest inverse principal moment (1/(kg·m²)): the bound on how fast a unit torque
    /// about any axis turns the body.
    #[must_use]
    pub(crate) fn max_inverse_moment(&self) -> f32 {
        self.inverse.max_element()
    }

    /// True for infinite inertia (a body torques cannot turn).
    #[must_use]
    pub fn is_infinite(&self) -> bool {
        self.inverse == Vec3A::ZERO
    }

    /// ω = I⁻¹ L with I = R I₀ Rᵀ, for orientation `q`.
    #[must_use]
    #[inline]
    pub fn angular_velocity(&self, q: Quat, l: Vec3A) -> Vec3A {
        if self.locked != 0 {
            return self.locked_angular_velocity(q, l);
        }
        if self.is_isotropic() {
            return self.inverse.x * l;
        }
        // Rotating by a non-unit quaternion scales by |q|², and q is not unit between a
        // first-order update and the renormalise set (or when that is off).
        let qf = unit(q) * self.frame;
        qf * (self.inverse * (qf.inverse() * l))
    }

    /// True when the three principal moments are equal (a sphere, a cube) and no axis is
    /// locked: then I⁻¹ is a multiple of the identity in every frame.
    #[must_use]
    #[inline]
    pub fn is_isotropic(&self) -> bool {
        let d = self.principal;
        d.x == d.y && d.y == d.z && self.locked == 0
    }

    /// True when a [`LockedAxes`] holds the body from turning about some world axis.
    #[must_use]
    #[inline]
    pub fn is_locked(&self) -> bool {
        self.locked != 0
    }

    /// L = I ω with I = R I₀ Rᵀ, for orientation `q` (zero for infinite inertia, which keeps
    /// no momentum of its own).
    #[must_use]
    #[inline]
    pub fn angular_momentum(&self, q: Quat, omega: Vec3A) -> Vec3A {
        if self.is_infinite() {
            return Vec3A::ZERO;
        }
        if self.is_isotropic() {
            return self.principal.x * omega;
        }
        let qf = unit(q) * self.frame;
        qf * (self.principal * (qf.inverse() * omega))
    }
}

/// `q` normalised, skipping the square root when it already is (the common case: a
/// predictable branch is cheaper than a sqrt and a division on the dependency chain).
#[inline]
fn unit(q: Quat) -> Quat {
    if (q.length_squared() - 1.0).abs() < 1e-6 {
        q
    } else {
        q.normalize()
    }
}

/// How [`Rotation`] advances over a step (for the Euler and Verlet integrators; RK4 always
/// integrates q̇ = ½ ω ⊗ q at its stages).
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub enum OrientationUpdate {
    /// Free-rotation splitting (the default): the kinetic energy Σ Lᵢ²/2Iᵢ is split about
    /// the middle moment I₂ into a turn about the fixed world L at |L|/I₂ and two spins
    /// about the other principal axes at Lᵢ (1/Iᵢ − 1/I₂), each solved exactly (see
    /// [`free_rotation_split`]). Lie–Trotter order for the Euler integrators, Strang order
    /// for Verlet. It is symplectic: |L| is exact and the energy error stays bounded, with
    /// no drift; a body with two equal moments (a rod, a disc) turns exactly. Costs three
    /// (five for Verlet) axis rotations.
    #[default]
    Splitting,
    /// q ← exp(½ h ω) ⊗ q with ω = I(q)⁻¹L held over the step: exact for constant ω and keeps
    /// |q| = 1, but on an asymmetric body the energy drifts steadily up, towards a spin about
    /// the minor axis (measured: +194 % over 10⁴ steps at 60 Hz for I = diag(1, 2, 3)).
    ExpMap,
    /// q ← q + ½ h ω ⊗ q: the lecture's first-order step; |q| grows by √(1 + (|ω|h/2)²)
    /// per step until renormalised, and the energy drifts as with [`OrientationUpdate::ExpMap`].
    FirstOrder,
}

/// Whether the renormalise set restores |q| = 1 every substep (default: on).
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct Renormalization(pub bool);

impl Default for Renormalization {
    fn default() -> Self {
        Self(true)
    }
}

/// Opts one body out of renormalisation (to show the drift it prevents).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SkipRenormalization;

/// A force applied at a point, every step until changed or removed: adds f to the force
/// and (p − x) × f to the torque.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct ExternalForceAtPoint {
    /// Force (N, world frame).
    pub force: Vec3,
    /// Point of application (m): in the body's shape frame if `local`, else in the world.
    pub point: Vec3,
    /// Whether `point` is in the body frame (it then moves with the body).
    pub local: bool,
}

impl Validate for ExternalForceAtPoint {
    fn validate(&self) -> Result<()> {
        finite_vec("force", self.force)?;
        finite_vec("point of application", self.point).map(|_| ())
    }
}

/// A one-shot impulse J (N·s, world frame) at a point: Δv = J/m, ΔL = (p − x) × J at the
/// next substep, then the impulse is reset to zero (like [`crate::particles::ExternalImpulse`]).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct ExternalImpulseAtPoint {
    /// Impulse (N·s, world frame).
    pub impulse: Vec3,
    /// Point (m): body frame if `local`, else world.
    pub point: Vec3,
    /// Whether `point` is in the body frame.
    pub local: bool,
}

impl Validate for ExternalImpulseAtPoint {
    fn validate(&self) -> Result<()> {
        finite_vec("impulse", self.impulse)?;
        finite_vec("point of application", self.point).map(|_| ())
    }
}

/// Angular drag coefficient c (1/s): τ = −c L, so spin decays like e^(−c t).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct AngularDamping(pub f32);

impl Validate for AngularDamping {
    fn validate(&self) -> Result<()> {
        non_negative("angular damping", self.0).map(|_| ())
    }
}

/// A pose a kinematic body should reach by the end of each step: hooke sets its velocities
/// to (target − x)/dt and the rotation difference over dt.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct KinematicTarget {
    /// Target centre-of-mass position (m).
    pub position: Vec3,
    /// Target orientation.
    pub rotation: Quat,
}

impl Validate for KinematicTarget {
    fn validate(&self) -> Result<()> {
        finite_vec("target position", self.position)?;
        Rotation(self.rotation).validate()
    }
}

/// The world point of `local` (m, body shape frame) for a body at `x` with orientation `q`
/// and centre of mass `com` (body frame): x + R (local − com).
#[must_use]
#[inline]
pub fn world_point(x: Vec3A, q: Quat, com: Vec3, local: Vec3) -> Vec3A {
    x + q * Vec3A::from(local - com)
}

/// dq/dt = ½ ω ⊗ q (as a 4-vector).
#[must_use]
#[inline]
pub fn quat_derivative(q: Quat, omega: Vec3A) -> Quat {
    Quat::from_xyzw(omega.x, omega.y, omega.z, 0.0) * q * 0.5
}

/// Half-angles below this take the series of [`turn_by`] and [`small_sin_cos`]: their first
/// dropped terms, x⁶/720 and x⁶/5040 relative, are below 3e-11 here, far under f32's
/// rounding (6e-8), so the series is as exact as `sin_cos` at a fraction of its cost. A
/// body turns by less than 0.1 rad in a substep unless it spins past 24 rad/s at 240 Hz.
const SERIES_HALF_ANGLE: f32 = 0.05;

/// The unit quaternion of a turn by |v| about v/|v| (the rotation vector v),
/// (sin(|v|/2) v/|v|, cos(|v|/2)), as [`Quat::from_scaled_axis`] gives it.
///
/// Small turns take the Taylor series of sin(x)/|v| and cos(x), x = |v|/2, in |v|²: no
/// square root, division or `sin_cos`. Every integrator step turns every spinning body by
/// one small angle.
#[must_use]
#[inline]
pub fn turn_by(v: Vec3A) -> Quat {
    let x2 = 0.25 * v.length_squared();
    if x2 < SERIES_HALF_ANGLE * SERIES_HALF_ANGLE {
        // sin(x)/(2x) = 1/2 − x²/12 + x⁴/240, cos x = 1 − x²/2 + x⁴/24.
        let s = 0.5 - x2 * (1.0 / 12.0) * (1.0 - x2 * 0.05);
        let c = 1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0));
        Quat::from_xyzw(v.x * s, v.y * s, v.z * s, c)
    } else {
        Quat::from_scaled_axis(v.into())
    }
}

/// (sin x, cos x), by their Taylor series below [`SERIES_HALF_ANGLE`] (see there).
#[must_use]
#[inline]
fn small_sin_cos(x: f32) -> (f32, f32) {
    let x2 = x * x;
    if x2 < SERIES_HALF_ANGLE * SERIES_HALF_ANGLE {
        (
            x * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * 0.05)),
            1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0)),
        )
    } else {
        x.sin_cos()
    }
}

/// One orientation step with ω held constant over `h` (the splitting update needs L and
/// the inertia: see [`free_rotation_split`]; here it falls back to the exponential map).
#[must_use]
#[inline]
pub fn integrate_rotation(q: Quat, omega: Vec3A, h: f32, update: OrientationUpdate) -> Quat {
    match update {
        OrientationUpdate::ExpMap | OrientationUpdate::Splitting => turn_by(omega * h) * q,
        OrientationUpdate::FirstOrder => q + quat_derivative(q, omega) * h,
    }
}

/// The free-rotation splitting step for a body with world angular momentum `l` held over
/// `h`. The energy ½ Σ Lᵢ²/Iᵢ is split about the middle moment I₂ as ½ |L|²/I₂ (a turn
/// about the fixed world L at |L|/I₂, which commutes with every other flow since |L| is
/// kept by all of them) plus ½ Lᵢ² (1/Iᵢ − 1/I₂) for the other two axes (spins about
/// them), each solved exactly, in the order 1, 3, L (`strang == false`, first order) or
/// ½1, ½3, L, ½3, ½1 (`strang == true`, second order). A body with two equal moments (a
/// rod, a disc, a square plate) then turns exactly: one spin and the turn about L commute.
/// Splitting about the principal axes alone (1, 2, 3) let a rod spinning at 45 rad/s
/// drift 9.5e-4 in energy over 10 s at 60 Hz (7.5e-6 now, rounding) and precess 0.4 rad/s
/// off the closed form: the spins about the two equal axes do not commute with the fast
/// one. With three equal moments ω = L/I is constant and the step is one exact turn.
#[must_use]
#[inline]
pub fn free_rotation_split(q: Quat, inertia: &Inertia, l: Vec3A, h: f32, strang: bool) -> Quat {
    if inertia.is_locked() {
        // ω = (P I P)⁺ L (see `LockedAxes`): the free flow does not hold, and about a single
        // free axis ω is constant between torques, which one turn follows exactly.
        return turn_by(inertia.angular_velocity(q, l) * h) * unit(q);
    }
    let inv = inertia.inverse;
    if inertia.is_isotropic() {
        // Equal moments (a sphere, a cube): ω = L/I is constant, and the exact flow is one
        // turn by h ω, which both splittings only approximate.
        return turn_by(l * (inv.x * h)) * unit(q);
    }
    // p maps the principal frame to the world; each spin turns it about one of its own
    // axes (right multiplication) at the rate L_body,i (1/Iᵢ − 1/I₂), which leaves world L
    // fixed; the turn about L multiplies it on the left and leaves the body-frame L alone.
    let mut p = unit(q) * inertia.frame;
    let inv = inv.to_array();
    // The middle moment: of two equal ones, one of them.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| inv[a].total_cmp(&inv[b]));
    let (first, mid, last) = (order[0], order[1], order[2]);
    let reference = inv[mid];
    let (first, last) = (first.min(last), first.max(last));

    // L in the principal frame, carried along: turning the body by θ about axis i turns
    // its body-frame L by −θ about the same axis, which only mixes the other two
    // components.
    let mut lb = (p.inverse() * l).to_array();
    let mut spin = |p: &mut Quat, axis: usize, dt: f32| {
        let rate = inv[axis] - reference;
        if rate == 0.0 {
            return;
        }
        let (s, c) = small_sin_cos(0.5 * dt * lb[axis] * rate);
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        let (sin, cos) = (2.0 * s * c, 1.0 - 2.0 * s * s);
        let (a, b) = (lb[j], lb[k]);
        lb[j] = cos * a + sin * b;
        lb[k] = cos * b - sin * a;
        let mut r = [0.0, 0.0, 0.0, c];
        r[axis] = s;
        *p *= Quat::from_array(r);
    };

    if strang {
        let half = 0.5 * h;
        spin(&mut p, first, half);
        spin(&mut p, last, half);
        p = turn_by(l * (reference * h)) * p;
        spin(&mut p, last, half);
        spin(&mut p, first, half);
    } else {
        spin(&mut p, first, h);
        spin(&mut p, last, h);
        p = turn_by(l * (reference * h)) * p;
    }
    p * inertia.frame.inverse()
}

/// Kinetic energy of rotation ½ ω·L (J), in f64 so that a fast heavy spinner does not
/// overflow.
#[must_use]
#[inline]
pub fn rotational_energy(omega: Vec3A, l: Vec3A) -> f64 {
    0.5 * omega.as_dvec3().dot(l.as_dvec3())
}

/// ω for integration: derived from L, except for infinite inertia (kinematic bodies), whose
/// ω is whatever the user set.
#[inline]
pub(crate) fn omega_of(inertia: &Inertia, q: Quat, l: Vec3A, stored: Vec3A) -> Vec3A {
    if inertia.is_infinite() {
        stored
    } else {
        inertia.angular_velocity(q, l)
    }
}

pub(crate) fn check_density(density: f32) -> Result<f32> {
    finite("density", density)?;
    if density <= 0.0 {
        return Err(Error::NotPositive {
            what: "density",
            value: density,
        });
    }
    Ok(density)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_turns_match_the_exact_exponential_map_to_rounding() {
        // Across the series' range and past it, against f64 sin and cos.
        for k in 0..=400 {
            let angle = 0.15 * k as f32 / 400.0;
            let axis = Vec3A::new(1.0, -2.0, 0.5).normalize();
            let q = turn_by(axis * angle);
            let half = f64::from(angle) / 2.0;
            let s = half.sin() as f32;
            let want = Quat::from_xyzw(axis.x * s, axis.y * s, axis.z * s, half.cos() as f32);
            for (a, b) in q.to_array().into_iter().zip(want.to_array()) {
                assert!(
                    (a - b).abs() <= 2.0 * f32::EPSILON,
                    "{angle}: {q} vs {want}"
                );
            }
            let (sin, cos) = small_sin_cos(angle);
            let (s64, c64) = f64::from(angle).sin_cos();
            assert!(
                (f64::from(sin) - s64).abs() <= 1.2e-7 * s64.abs().max(1e-30),
                "{angle}"
            );
            assert!((f64::from(cos) - c64).abs() <= 1.2e-7, "{angle}");
        }
        assert_eq!(turn_by(Vec3A::ZERO), Quat::IDENTITY);
        assert!(!turn_by(Vec3A::splat(f32::NAN)).is_finite());
    }

    #[test]
    fn world_tensors_are_inverse_and_match_the_single_ones() {
        let inertia = Inertia::new(
            Vec3::new(1.0, 2.0, 3.0),
            Quat::from_rotation_z(0.3).normalize(),
        )
        .unwrap();
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.0);
        let (tensor, inverse) = inertia.world_tensors(q);
        let product = tensor * inverse;
        assert!(
            product.abs_diff_eq(glam::Mat3A::IDENTITY, 1e-5),
            "{product}"
        );
        let single = glam::Mat3A::from(inertia.world_inverse_tensor(q));
        assert!(inverse.abs_diff_eq(single, 1e-6));
        let (t, i) = Inertia::INFINITE.world_tensors(q);
        assert_eq!((t, i), (glam::Mat3A::ZERO, glam::Mat3A::ZERO));
    }

    #[test]
    fn equal_moments_give_exact_diagonal_world_tensors_in_any_orientation() {
        let inertia = Inertia::new(Vec3::splat(1.0 / 6.0), Quat::IDENTITY).unwrap();
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.0);
        let (tensor, inverse) = inertia.world_tensors(q);
        assert_eq!(tensor, glam::Mat3A::from_diagonal(Vec3::splat(1.0 / 6.0)));
        assert_eq!(inverse, glam::Mat3A::from_diagonal(Vec3::splat(6.0)));
        // The same ω as the scalar path of `angular_velocity`, bit for bit.
        let l = Vec3A::new(0.3, -2.0, 1.5);
        assert_eq!(inverse * l, inertia.angular_velocity(q, l));
        // Through R the moments came out off by rounding.
        let r = glam::Mat3A::from_quat(q);
        let through_r = r * glam::Mat3A::from_diagonal(Vec3::splat(6.0)) * r.transpose();
        assert_ne!(through_r, inverse);
    }

    #[test]
    fn omega_and_momentum_are_inverse_for_any_orientation() {
        let inertia = Inertia::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_y(0.3)).unwrap();
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.0);
        let omega = Vec3A::new(0.3, -2.0, 1.5);
        let l = inertia.angular_momentum(q, omega);
        assert!((inertia.angular_velocity(q, l) - omega).length() < 1e-5);
        // Against the matrix form I = R I₀ Rᵀ.
        let r = glam::Mat3::from_quat(q);
        let i_world = r * inertia.tensor() * r.transpose();
        assert!((Vec3A::from(i_world * Vec3::from(omega)) - l).length() < 1e-4);
    }

    #[test]
    fn first_order_update_grows_the_norm_by_the_closed_form() {
        let omega = Vec3A::new(0.0, 50.0, 0.0);
        let h = 1.0 / 60.0;
        let q = integrate_rotation(Quat::IDENTITY, omega, h, OrientationUpdate::FirstOrder);
        let expected = (1.0 + (50.0 * h / 2.0f32).powi(2)).sqrt();
        assert!((q.length() - expected).abs() < 1e-6);
        let q = integrate_rotation(Quat::IDENTITY, omega, h, OrientationUpdate::ExpMap);
        assert!((q.length() - 1.0).abs() < 1e-6);
        assert!((q.to_scaled_axis() - Vec3::new(0.0, 50.0 * h, 0.0)).length() < 1e-5);
    }

    #[test]
    fn bad_inertia_is_rejected() {
        assert!(Inertia::diagonal(1.0, 0.0, 1.0).is_err());
        assert!(Inertia::diagonal(1.0, -1.0, 1.0).is_err());
        assert!(Inertia::diagonal(f32::NAN, 1.0, 1.0).is_err());
        assert!(Inertia::new(Vec3::ONE, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).is_err());
        assert!(Rotation::try_new(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0)).is_err());
        assert!(check_density(0.0).is_err() && check_density(-2.0).is_err());
    }
}
