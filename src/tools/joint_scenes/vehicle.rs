//! A four-wheeled car driven by motors on its wheels' hinges.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::collision::{Collider, ColliderDensity};
use crate::core::error::Result;
use crate::joints::RevoluteJoint;
use crate::particles::Position;
use crate::rigid::RigidBody;

/// A car: a chassis of 2 × 0.3 × 1 m (500 kg/m³, 300 kg) on four ball wheels of 0.3 m
/// (500 kg/m³, 56.5 kg each), each on a hinge about z whose motor drives it towards
/// [`FourWheeler::speed`] / r (rad/s) with at most [`FourWheeler::torque`] (N·m), on flat
/// ground (a static box, its top at y = 0). It drives along +x.
///
/// While the motors give all their torque and the wheels roll without slipping, the car
/// gains speed at a = 4 τ / r / (M + 4 I / r²) ([`FourWheeler::acceleration`]); then it holds
/// the target speed (nothing resists it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourWheeler {
    /// The speed the motors drive to (m/s).
    pub speed: f32,
    /// Each motor's largest torque (N·m).
    pub torque: f32,
}

impl Default for FourWheeler {
    /// 5 m/s at 100 N·m a wheel.
    fn default() -> Self {
        Self {
            speed: 5.0,
            torque: 100.0,
        }
    }
}

/// What [`FourWheeler::spawn`] made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FourWheelerParts {
    /// The chassis.
    pub chassis: Entity,
    /// The wheels: rear left, rear right, front left, front right.
    pub wheels: [Entity; 4],
    /// Their hinges, in the same order.
    pub hinges: [Entity; 4],
}

impl FourWheeler {
    /// The chassis' half extents (m).
    pub const CHASSIS: Vec3 = Vec3::new(1.0, 0.15, 0.5);
    /// The wheels' radius (m).
    pub const WHEEL: f32 = 0.3;
    /// The chassis' and the wheels' density (kg/m³).
    pub const DENSITY: f32 = 500.0;
    /// Where the wheels' centres are from the chassis' centre (m): a quarter of the
    /// chassis' length in from its ends, just outside its sides, level with its bottom.
    pub const WHEEL_AT: Vec3 = Vec3::new(0.75, -0.15, 0.65);

    /// The chassis' mass (kg).
    #[must_use]
    pub fn chassis_mass() -> f32 {
        let c = Self::CHASSIS;
        8.0 * c.x * c.y * c.z * Self::DENSITY
    }

    /// A wheel's mass (kg).
    #[must_use]
    pub fn wheel_mass() -> f32 {
        4.0 / 3.0 * std::f32::consts::PI * Self::WHEEL.powi(3) * Self::DENSITY
    }

    /// A wheel's moment of inertia about its axle (kg·m²): 2/5 m r².
    #[must_use]
    pub fn wheel_inertia() -> f32 {
        0.4 * Self::wheel_mass() * Self::WHEEL * Self::WHEEL
    }

    /// The car's acceleration while its motors give all their torque (m/s²).
    #[must_use]
    pub fn acceleration(&self) -> f32 {
        let r = Self::WHEEL;
        let mass = Self::chassis_mass() + 4.0 * Self::wheel_mass();
        4.0 * self.torque / r / (mass + 4.0 * Self::wheel_inertia() / (r * r))
    }

    /// Spawns the ground, the chassis at `x` (m along the road), the wheels just touching
    /// the ground, and their driven hinges.
    ///
    /// # Errors
    /// Constructor errors for bad sizes; a bad speed or torque quarantines the hinges.
    pub fn spawn(&self, world: &mut World, x: f32) -> Result<FourWheelerParts> {
        world.spawn((
            RigidBody::Static,
            Collider::cuboid(200.0, 0.5, 20.0)?,
            Position(Vec3A::new(0.0, -0.5, 0.0)),
        ));
        let c = Self::CHASSIS;
        let centre = Vec3::new(x, Self::WHEEL - Self::WHEEL_AT.y, 0.0);
        let chassis = world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(c.x, c.y, c.z)?,
                ColliderDensity(Self::DENSITY),
                Position(centre.into()),
            ))
            .id();
        let corners = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)];
        let mut wheels = [chassis; 4];
        let mut hinges = [chassis; 4];
        for (k, &(sx, sz)) in corners.iter().enumerate() {
            let at = Self::WHEEL_AT * Vec3::new(sx, 1.0, sz);
            wheels[k] = world
                .spawn((
                    RigidBody::Dynamic,
                    Collider::ball(Self::WHEEL)?,
                    ColliderDensity(Self::DENSITY),
                    Position((centre + at).into()),
                ))
                .id();
            // Rolling along +x turns a wheel about −z.
            hinges[k] = world
                .spawn(
                    RevoluteJoint::new(chassis, wheels[k], Vec3::NEG_Z)
                        .with_anchors(at, Vec3::ZERO)
                        .with_motor(self.speed / Self::WHEEL, self.torque),
                )
                .id();
        }
        Ok(FourWheelerParts {
            chassis,
            wheels,
            hinges,
        })
    }
}
