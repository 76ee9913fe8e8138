//! The plugin group and physics on a bare `World`: the one place that names every effect.

use bevy_ecs::prelude::*;

use crate::character::CharacterControllerPlugin;
use crate::cloth::ClothPlugin;
use crate::collision::CollisionPlugin;
use crate::core::error::Result;
use crate::core::plugin::{self, PhysicsCorePlugin, WorldPlugin};
use crate::core::time::FrameReport;
use crate::integrator::IntegratorPlugin;
use crate::joints::JointPlugin;
use crate::particles::{DampingPlugin, GravityPlugin, VelocityFieldPlugin};
use crate::rigid::RigidBodyPlugin;
use crate::sleep::SleepPlugin;
use crate::soft::SoftBodyPlugin;
use crate::springs::SpringPlugin;

/// Every effect: gravity, damping, velocity fields, springs, rigid bodies, collisions,
/// sleeping, soft bodies, cloth and character controllers, on the kernel and the integrators.
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
            .add_physics(JointPlugin)
            .add_physics(SleepPlugin)
            .add_physics(SoftBodyPlugin)
            .add_physics(ClothPlugin)
            .add_physics(CharacterControllerPlugin);
    }
}

/// Physics on a bare `World`.
pub trait PhysicsWorldExt {
    /// Builds `plugin` into this world (once; later calls with the same plugin do nothing).
    /// The kernel ([`PhysicsCorePlugin`]) and the integrators ([`IntegratorPlugin`]) are
    /// added first if missing, so any one effect alone already moves its bodies.
    fn add_physics<P: WorldPlugin>(&mut self, plugin: P) -> &mut Self;

    /// Runs one fixed step of [`PhysicsTime::dt`](crate::core::time::PhysicsTime::dt). Does nothing without the core plugin.
    fn step_physics(&mut self);

    /// Adds `frame_dt` seconds of frame time and runs the whole steps that fit, up to
    /// [`PhysicsTime::max_steps_per_frame`](crate::core::time::PhysicsTime::max_steps_per_frame).
    ///
    /// # Errors
    /// [`crate::core::error::Error::InvalidTimeStep`] for a negative or non-finite `frame_dt` (nothing
    /// runs).
    fn advance_physics(&mut self, frame_dt: f32) -> Result<FrameReport>;
}

impl PhysicsWorldExt for World {
    fn add_physics<P: WorldPlugin>(&mut self, plugin: P) -> &mut Self {
        plugin::install(self, &PhysicsCorePlugin);
        plugin::install(self, &IntegratorPlugin);
        plugin::install(self, &plugin);
        self
    }

    fn step_physics(&mut self) {
        plugin::step(self);
    }

    fn advance_physics(&mut self, frame_dt: f32) -> Result<FrameReport> {
        plugin::advance(self, frame_dt)
    }
}
