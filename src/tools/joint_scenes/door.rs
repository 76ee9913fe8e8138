//! A door on a hinge with stops, hit by a thrown ball.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::collision::{Collider, ColliderDensity, Restitution};
use crate::core::error::Result;
use crate::core::quarantine::Validate;
use crate::joints::RevoluteJoint;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::RigidBody;

/// A door of 1 × 2 × 0.05 m (500 kg/m³, 50 kg) hinged about the vertical at its edge
/// x = 0 to the world, opening from 0° to [`HingedDoor::OPEN`] (turning x towards −z), and a
/// ball of 0.12 m (2000 kg/m³, 14.5 kg) thrown at it along −z at [`HingedDoor::speed`],
/// striking square on 0.8 m from the hinge, 1 m up. A static floor lies below, its top at
/// y = 0.
///
/// The blow is short against the swing, so angular momentum about the hinge carries over:
/// with restitution e the impulse is J = (1 + e) v / (1 / m + r² / I) and the door turns
/// at J r / I ([`HingedDoor::after_hit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HingedDoor {
    /// The ball's speed when thrown (m/s).
    pub speed: f32,
    /// The ball's restitution (the contact takes the larger of the two; the door has 0).
    pub restitution: f32,
}

impl Default for HingedDoor {
    /// A ball at 6 m/s that does not bounce (restitution 0, hooke's default).
    fn default() -> Self {
        Self {
            speed: 6.0,
            restitution: 0.0,
        }
    }
}

/// What [`HingedDoor::spawn`] made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HingedDoorParts {
    /// The door.
    pub door: Entity,
    /// The ball.
    pub ball: Entity,
    /// The hinge.
    pub hinge: Entity,
}

impl HingedDoor {
    /// The door's half extents (m).
    pub const DOOR: Vec3 = Vec3::new(0.5, 1.0, 0.025);
    /// The door's density (kg/m³).
    pub const DOOR_DENSITY: f32 = 500.0;
    /// The ball's radius (m).
    pub const BALL: f32 = 0.12;
    /// The ball's density (kg/m³).
    pub const BALL_DENSITY: f32 = 2000.0;
    /// Where the ball strikes, from the hinge (m).
    pub const STRIKE: f32 = 0.8;
    /// The door's open stop (rad): 100°.
    pub const OPEN: f32 = 100.0 * std::f32::consts::PI / 180.0;
    /// How far in front of the door the ball starts (m).
    pub const GAP: f32 = 0.3;
    /// The door's bottom above the floor (m).
    const CLEARANCE: f32 = 0.02;

    /// The door's mass (kg).
    #[must_use]
    pub fn door_mass() -> f32 {
        let d = Self::DOOR;
        8.0 * d.x * d.y * d.z * Self::DOOR_DENSITY
    }

    /// The door's moment of inertia about its hinge (kg·m²): m (w² + t²) / 12 + m (w / 2)².
    #[must_use]
    pub fn door_inertia() -> f32 {
        let (w, t) = (2.0 * Self::DOOR.x, 2.0 * Self::DOOR.z);
        let m = Self::door_mass();
        m * (w * w + t * t) / 12.0 + m * (0.5 * w) * (0.5 * w)
    }

    /// The ball's mass (kg).
    #[must_use]
    pub fn ball_mass() -> f32 {
        4.0 / 3.0 * std::f32::consts::PI * Self::BALL.powi(3) * Self::BALL_DENSITY
    }

    /// The closed form of the blow: the door's spin after it (rad/s, about +y) and the
    /// ball's velocity along z after it (m/s; negative: still going on through).
    #[must_use]
    pub fn after_hit(&self) -> (f32, f32) {
        let (m, i, r) = (Self::ball_mass(), Self::door_inertia(), Self::STRIKE);
        let impulse = (1.0 + self.restitution) * self.speed / (1.0 / m + r * r / i);
        (impulse * r / i, -self.speed + impulse / m)
    }

    /// When the ball strikes (s after it is thrown).
    #[must_use]
    pub fn strike_time(&self) -> f32 {
        Self::GAP / self.speed.max(1e-3)
    }

    /// Spawns the floor, the door (at rest against its closed stop), its hinge and the
    /// ball, 0.3 m in front of the door (a little above the strike, to fall onto it).
    ///
    /// # Errors
    /// A negative speed or a restitution outside [0, 1] (typed), or constructor errors.
    pub fn spawn(&self, world: &mut World) -> Result<HingedDoorParts> {
        crate::core::error::non_negative("thrown ball's speed", self.speed)?;
        Restitution(self.restitution).validate()?;
        world.spawn((
            RigidBody::Static,
            Collider::cuboid(5.0, 0.5, 5.0)?,
            Position(Vec3A::new(0.0, -0.5, 0.0)),
        ));
        let d = Self::DOOR;
        let hinge_y = Self::CLEARANCE + d.y;
        let door = world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(d.x, d.y, d.z)?,
                ColliderDensity(Self::DOOR_DENSITY),
                Position(Vec3A::new(d.x, hinge_y, 0.0)),
            ))
            .id();
        let hinge = world
            .spawn(
                RevoluteJoint::to_world(door, Vec3::Y)
                    .with_anchors(Vec3::new(0.0, hinge_y, 0.0), Vec3::new(-d.x, 0.0, 0.0))
                    .with_limits(0.0, Self::OPEN),
            )
            .id();
        // 0.3 m of flight: it falls g t² / 2 = 1.2 cm on the way.
        let gap = Self::GAP;
        let flight = self.strike_time();
        let drop = 0.5 * 9.81 * flight * flight;
        let ball = world
            .spawn((
                RigidBody::Dynamic,
                Collider::ball(Self::BALL)?,
                ColliderDensity(Self::BALL_DENSITY),
                Restitution(self.restitution),
                Position(Vec3A::new(Self::STRIKE, 1.0 + drop, d.z + Self::BALL + gap)),
                LinearVelocity(Vec3A::new(0.0, 0.0, -self.speed)),
            ))
            .id();
        Ok(HingedDoorParts { door, ball, hinge })
    }
}
