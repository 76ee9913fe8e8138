//! Collision hooks a platformer uses, and a scene for them, shared by
//! `examples/collision_hooks.rs` and the tests: a one-way platform (things pass up through
//! it and land on it) and a conveyor belt (its surface carries what lies on it).
//!
//! The hooks are game code written against the public API, as a game would write its own:
//! [`PlatformHooks`] is a [`CollisionHooks`] system parameter that reads the game's
//! [`OneWayPlatform`] and [`ConveyorBelt`] components.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::Vec3;

use crate::Result;
use crate::collision::{ActiveCollisionHooks, Collider, CollisionHooks, ContactEdit};
use crate::particles::{LinearVelocity, Position};
use crate::rigid::RigidBody;

/// A platform that only holds what comes down onto it from the side `up` points to.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[require(ActiveCollisionHooks = ActiveCollisionHooks::MODIFY_CONTACTS)]
pub struct OneWayPlatform {
    /// Unit vector out of the platform's walkable side.
    pub up: Vec3,
}

/// A collider whose surface moves at this velocity (m/s, world frame) along its contacts.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
#[require(ActiveCollisionHooks = ActiveCollisionHooks::MODIFY_CONTACTS)]
pub struct ConveyorBelt(pub Vec3);

/// The hooks of [`OneWayPlatform`] and [`ConveyorBelt`].
#[derive(SystemParam)]
pub struct PlatformHooks<'w, 's> {
    platforms: Query<'w, 's, &'static OneWayPlatform>,
    belts: Query<'w, 's, &'static ConveyorBelt>,
}

impl CollisionHooks for PlatformHooks<'_, '_> {
    fn modify_contacts(&self, contact: &mut ContactEdit, _: &mut Commands) -> bool {
        for side in [contact.a, contact.b] {
            if let Ok(platform) = self.platforms.get(side) {
                // Only a contact whose normal leaves the walkable side holds: from below or
                // from the edge, the body passes (and once its centre is over the top, the
                // normal turns up and the platform catches it).
                if contact.normal_from(side).dot(platform.up) < 0.7 {
                    return false;
                }
            }
            if let Ok(belt) = self.belts.get(side) {
                contact.set_surface_velocity(side, belt.0);
            }
        }
        true
    }
}

/// The scene: a floor whose top is y = 0, a one-way platform of top `platform_top` over
/// x ∈ [−6, −2], a ball launched straight up from under it, and a belt of top y = 0.5 over
/// x ∈ [1, 7] carrying a crate at `belt_speed`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HooksCourse {
    /// Height of the platform's top (m).
    pub platform_top: f32,
    /// Launch speed of the ball from under the platform (m/s, up).
    pub launch: f32,
    /// Radius of the ball (m).
    pub ball_radius: f32,
    /// The belt's surface speed (m/s, along +x).
    pub belt_speed: f32,
    /// Mass of the crate on the belt (kg; a 0.5 m cube).
    pub crate_kg: f32,
}

impl Default for HooksCourse {
    fn default() -> Self {
        Self {
            platform_top: 2.0,
            launch: 8.0,
            ball_radius: 0.25,
            belt_speed: 2.0,
            crate_kg: 5.0,
        }
    }
}

/// What [`HooksCourse::spawn`] made.
#[derive(Debug, Clone, Copy)]
pub struct HooksParts {
    /// The one-way platform.
    pub platform: Entity,
    /// The ball launched up through it.
    pub ball: Entity,
    /// The belt.
    pub belt: Entity,
    /// The crate on the belt.
    pub crate_: Entity,
}

/// Half thickness of the platform and the belt (m).
pub const SLAB: f32 = 0.1;
/// The platform's span along x (m).
pub const PLATFORM_X: (f32, f32) = (-6.0, -2.0);
/// The belt's span along x (m), and the height of its top.
pub const BELT_X: (f32, f32) = (1.0, 7.0);
/// Height of the belt's top (m).
pub const BELT_TOP: f32 = 0.5;

impl HooksCourse {
    /// Spawns the floor, the platform, the belt, the ball (at rest under the platform with
    /// its launch velocity) and the crate (resting on the belt's left end).
    ///
    /// # Errors
    /// A shape error for a non-positive size.
    pub fn spawn(&self, world: &mut World) -> Result<HooksParts> {
        world.spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 5.0)?,
            Position::from(Vec3::new(0.0, -0.5, 0.0)),
        ));
        let slab = |x: (f32, f32), top: f32| {
            (
                Collider::cuboid(0.5 * (x.1 - x.0), SLAB, 1.0),
                Vec3::new(0.5 * (x.0 + x.1), top - SLAB, 0.0),
            )
        };
        let (shape, at) = slab(PLATFORM_X, self.platform_top);
        let platform = world
            .spawn((
                RigidBody::Static,
                shape?,
                Position::from(at),
                OneWayPlatform { up: Vec3::Y },
            ))
            .id();
        let (shape, at) = slab(BELT_X, BELT_TOP);
        let belt = world
            .spawn((
                RigidBody::Static,
                shape?,
                Position::from(at),
                ConveyorBelt(Vec3::new(self.belt_speed, 0.0, 0.0)),
            ))
            .id();
        let ball = world
            .spawn((
                RigidBody::Dynamic,
                Collider::ball(self.ball_radius)?,
                Position::from(Vec3::new(
                    0.5 * (PLATFORM_X.0 + PLATFORM_X.1),
                    self.ball_radius,
                    0.0,
                )),
                LinearVelocity::from(Vec3::new(0.0, self.launch, 0.0)),
            ))
            .id();
        let crate_ = world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.25, 0.25, 0.25)?,
                crate::particles::Mass::new(self.crate_kg)?,
                Position::from(Vec3::new(BELT_X.0 + 0.5, BELT_TOP + 0.25, 0.0)),
            ))
            .id();
        Ok(HooksParts {
            platform,
            ball,
            belt,
            crate_,
        })
    }

    /// The ball's apex with nothing in its way, v²/2g above its start (m, its centre).
    #[must_use]
    pub fn free_apex(&self, g: f32) -> f32 {
        self.ball_radius + self.launch * self.launch / (2.0 * g)
    }
}
