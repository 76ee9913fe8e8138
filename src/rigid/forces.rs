//! Forces, torques and impulses from gameplay code without inserting their components first.

use bevy_ecs::system::EntityCommands;
use bevy_ecs::world::EntityWorldMut;
use glam::{Vec3, Vec3A};

use super::ExternalTorque;
use crate::particles::{ExternalForce, ExternalImpulse};

/// Pushes a body from gameplay code, whether or not it has the component yet:
/// `commands.entity(body).set_force(Vec3::Y * 50.0)`. A `Query<&mut ExternalForce>` only
/// matches bodies that already have one; these insert it when missing.
///
/// ```
/// use bevy_ecs::prelude::*;
/// use hooke::prelude::*;
///
/// let mut world = World::new();
/// world.add_physics(PhysicsPlugins);
/// world.insert_resource(Gravity::ZERO);
/// let body = world
///     .spawn((RigidBody::Dynamic, Collider::ball(0.5).unwrap(), Mass::new(2.0).unwrap()))
///     .id();
/// world.entity_mut(body).set_force(Vec3::new(4.0, 0.0, 0.0)); // N, until changed
/// world.entity_mut(body).apply_impulse(Vec3::new(0.0, 0.0, 2.0)); // N·s, once
/// for _ in 0..60 {
///     world.step_physics();
/// }
/// let v = world.get::<LinearVelocity>(body).unwrap().get();
/// assert!((v - Vec3::new(2.0, 0.0, 1.0)).length() < 1e-3, "{v}"); // F t / m, J / m
/// ```
pub trait BodyForces {
    /// Sets the body's [`ExternalForce`] (N, world frame), applied every step until changed.
    fn set_force(&mut self, force: Vec3) -> &mut Self;
    /// Sets the body's [`ExternalTorque`] (N·m, world frame), applied every step until
    /// changed.
    fn set_torque(&mut self, torque: Vec3) -> &mut Self;
    /// Adds a one-shot impulse (N·s, world frame) at the centre of mass: Δv = J / m at the
    /// next step ([`ExternalImpulse`]).
    fn apply_impulse(&mut self, impulse: Vec3) -> &mut Self;
}

impl BodyForces for EntityWorldMut<'_> {
    fn set_force(&mut self, force: Vec3) -> &mut Self {
        self.insert(ExternalForce::from(force))
    }

    fn set_torque(&mut self, torque: Vec3) -> &mut Self {
        self.insert(ExternalTorque(Vec3A::from(torque)))
    }

    fn apply_impulse(&mut self, impulse: Vec3) -> &mut Self {
        let total = self
            .get::<ExternalImpulse>()
            .map_or(Vec3::ZERO, |j| j.get())
            + impulse;
        self.insert(ExternalImpulse::from(total))
    }
}

impl BodyForces for EntityCommands<'_> {
    fn set_force(&mut self, force: Vec3) -> &mut Self {
        self.queue(move |mut e: EntityWorldMut| {
            e.set_force(force);
        })
    }

    fn set_torque(&mut self, torque: Vec3) -> &mut Self {
        self.queue(move |mut e: EntityWorldMut| {
            e.set_torque(torque);
        })
    }

    fn apply_impulse(&mut self, impulse: Vec3) -> &mut Self {
        self.queue(move |mut e: EntityWorldMut| {
            e.apply_impulse(impulse);
        })
    }
}
