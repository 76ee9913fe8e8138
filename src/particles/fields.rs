//! Uniform gravity and velocity fields.
//!
//! **Gravity** is a resource g (m/s²); each body feels f = m g s, with s its
//! [`crate::particles::GravityScale`] (1 by default).
//!
//! **Velocity fields** carry massless [`crate::particles::Tracer`]s: dx/dt = Σ u_k(x, t), summed over
//! every [`VelocityField`] entity. The lecture's update is Euler, x ← x + h u(x, t); the
//! [`Advection`] resource picks a higher-order scheme. For the vortex u = ω × (x − c) Euler
//! multiplies the distance to the axis by √(1 + (|ω|h)²) every step (tracers spiral out),
//! while RK4 keeps it to within O((|ω|h)⁵) per step.

use std::fmt;
use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::core::error::{Result, finite, finite_vec};

/// Uniform gravitational acceleration (m/s²). Default: (0, −9.81, 0).
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct Gravity(Vec3);

impl Default for Gravity {
    fn default() -> Self {
        Self(Vec3::new(0.0, -9.81, 0.0))
    }
}

impl Gravity {
    /// Standard gravity along −y.
    pub const EARTH: Gravity = Gravity(Vec3::new(0.0, -9.81, 0.0));
    /// No gravity.
    pub const ZERO: Gravity = Gravity(Vec3::ZERO);

    /// Gravity `g` (m/s²).
    ///
    /// # Errors
    /// [`crate::core::error::Error::NonFinite`].
    pub fn new(g: Vec3) -> Result<Self> {
        finite_vec("gravity", g).map(Self)
    }

    /// The acceleration (m/s²).
    #[must_use]
    pub fn get(&self) -> Vec3 {
        self.0
    }
}

/// How tracers integrate dx/dt = u(x, t).
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub enum Advection {
    /// x ← x + h u(x, t): the lecture's scheme, first order.
    #[default]
    Euler,
    /// Midpoint (RK2), second order.
    Midpoint,
    /// Classic RK4, fourth order.
    Rk4,
}

type FieldFn = dyn Fn(Vec3, f32) -> Vec3 + Send + Sync;

/// A velocity field u(x, t) (m/s). Put it on an entity; tracers feel the sum of all fields.
#[derive(serde::Serialize, serde::Deserialize, Component, Clone)]
#[cfg_attr(
    feature = "bevy",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Component, Clone, Debug)
)]
pub enum VelocityField {
    /// The same velocity everywhere.
    Uniform(Vec3),
    /// Rigid rotation u = ω × (x − c) about the line through `center` along ω.
    Vortex {
        /// A point on the axis (m).
        center: Vec3,
        /// Angular velocity ω (rad/s); its direction is the axis.
        omega: Vec3,
    },
    /// Any function of position (m) and time (s) giving m/s. (A closure: snapshots refuse
    /// it.)
    #[serde(skip)]
    Custom(Arc<FieldFn>),
}

impl fmt::Debug for VelocityField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Uniform(u) => f.debug_tuple("Uniform").field(u).finish(),
            Self::Vortex { center, omega } => f
                .debug_struct("Vortex")
                .field("center", center)
                .field("omega", omega)
                .finish(),
            Self::Custom(_) => f.write_str("Custom(..)"),
        }
    }
}

impl VelocityField {
    /// A uniform field.
    ///
    /// # Errors
    /// [`crate::core::error::Error::NonFinite`].
    pub fn uniform(u: Vec3) -> Result<Self> {
        finite_vec("field velocity", u).map(Self::Uniform)
    }

    /// A vortex about `axis` (normalised here) through `center`, turning at `rate` rad/s.
    ///
    /// # Errors
    /// [`crate::core::error::Error::NonFinite`] for non-finite input, [`crate::core::error::Error::NotPositive`] (the
    /// axis length) for a zero axis.
    pub fn vortex(center: Vec3, axis: Vec3, rate: f32) -> Result<Self> {
        let center = finite_vec("vortex center", center)?;
        let rate = finite("vortex rate", rate)?;
        let axis = finite_vec("vortex axis", axis)?;
        // Scaled by its largest component first: a huge finite axis (1e30) would overflow
        // |a|² and be called non-finite.
        let big = axis.abs().max_element();
        let axis = (axis / big)
            .try_normalize()
            .ok_or(crate::core::error::Error::NotPositive {
                what: "vortex axis length",
                value: axis.length(),
            })?;
        Ok(Self::Vortex {
            center,
            omega: axis * rate,
        })
    }

    /// A field from a closure of position (m) and time (s). A closure that returns NaN
    /// quarantines the tracers it touches rather than spreading NaN.
    pub fn custom(u: impl Fn(Vec3, f32) -> Vec3 + Send + Sync + 'static) -> Self {
        Self::Custom(Arc::new(u))
    }

    /// The field's velocity at `x` (m), time `t` (s).
    #[must_use]
    #[inline]
    pub fn velocity(&self, x: Vec3A, t: f32) -> Vec3A {
        match self {
            Self::Uniform(u) => (*u).into(),
            Self::Vortex { center, omega } => Vec3A::from(*omega).cross(x - Vec3A::from(*center)),
            Self::Custom(u) => u(x.into(), t).into(),
        }
    }
}

/// Lecture's Euler advection through a velocity field: x ← x + h u(x, t).
#[must_use]
pub fn advect_euler(x: Vec3A, t: f32, h: f32, u: impl Fn(Vec3A, f32) -> Vec3A) -> Vec3A {
    x + h * u(x, t)
}

/// Midpoint (RK2) advection: second order.
#[must_use]
pub fn advect_midpoint(x: Vec3A, t: f32, h: f32, u: impl Fn(Vec3A, f32) -> Vec3A) -> Vec3A {
    let k1 = u(x, t);
    x + h * u(x + 0.5 * h * k1, t + 0.5 * h)
}

/// Classic RK4 advection: fourth order.
#[must_use]
pub fn advect_rk4(x: Vec3A, t: f32, h: f32, u: impl Fn(Vec3A, f32) -> Vec3A) -> Vec3A {
    let k1 = u(x, t);
    let k2 = u(x + 0.5 * h * k1, t + 0.5 * h);
    let k3 = u(x + 0.5 * h * k2, t + 0.5 * h);
    let k4 = u(x + h * k3, t + h);
    x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rk4_advection_is_exact_for_cubic_in_time() {
        // dx/dt = 3t²: RK4 integrates polynomials up to degree 3 in t exactly.
        let x = advect_rk4(Vec3A::ZERO, 0.0, 1.0, |_, t| Vec3A::splat(3.0 * t * t));
        assert!((x.x - 1.0).abs() < 1e-6);
        let x = advect_euler(Vec3A::ZERO, 0.0, 1.0, |_, t| Vec3A::splat(3.0 * t * t));
        assert_eq!(x.x, 0.0);
    }
}
