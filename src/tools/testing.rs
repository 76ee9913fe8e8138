//! Helpers for headless tests and scripted scenarios: run for a time or until a condition
//! in whole steps, counted exactly, and short reads of a body's state.
//!
//! Looping on [`PhysicsTime::elapsed`] misleads: the step is an f32 (1/60 s is stored as
//! 0.016666668 s), so 180 steps read 3.0000001564621925 s and a loop `while elapsed < 3.0`
//! runs 180 steps where one `< 1.0` runs 61. These helpers turn a time into a step count
//! once, `round(t / dt)`, and step that many times.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//! use hooke::tools::testing::PhysicsTestExt;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! let ball = world.spawn(ParticleBundle::new(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, 1.0)?).id();
//! assert_eq!(world.run_for_seconds(1.0)?, 60);
//! let fell = world.run_until(5.0, |w| w.position_of(ball).is_some_and(|x| x.y < 0.0))?;
//! assert!(fell.is_some());
//! # Ok::<(), hooke::Error>(())
//! ```

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::core::error::{Error, Result};
use crate::core::time::PhysicsTime;
use crate::particles::{LinearVelocity, Position};
use crate::plugins::PhysicsWorldExt;
use crate::rigid::{AngularVelocity, Rotation};

/// Running a physics world headless, and reading its bodies (implemented for [`World`]).
pub trait PhysicsTestExt {
    /// The whole steps that make `seconds` (s, ≥ 0) at the world's step: `round(seconds / dt)`.
    ///
    /// # Errors
    /// [`Error::NoPhysics`] without the plugins; [`Error::NonFinite`] or [`Error::Negative`]
    /// for a bad time; [`Error::OutOfRange`] past 2³² − 1 steps.
    fn steps_for(&self, seconds: f64) -> Result<u64>;

    /// Steps [`Self::steps_for`]`(seconds)` times; returns that count.
    ///
    /// # Errors
    /// As [`Self::steps_for`].
    fn run_for_seconds(&mut self, seconds: f64) -> Result<u64>;

    /// Steps until `done` holds after a step, for at most `max_seconds`; returns the steps
    /// taken when it held (`Some(0)` when it held before any step), `None` when the time ran
    /// out.
    ///
    /// # Errors
    /// As [`Self::steps_for`].
    fn run_until(
        &mut self,
        max_seconds: f64,
        done: impl FnMut(&World) -> bool,
    ) -> Result<Option<u64>>;

    /// A body's position (m), or None if it has none.
    fn position_of(&self, e: Entity) -> Option<Vec3>;
    /// A body's orientation, or None if it has none.
    fn rotation_of(&self, e: Entity) -> Option<Quat>;
    /// A body's velocity (m/s), or None if it has none.
    fn velocity_of(&self, e: Entity) -> Option<Vec3>;
    /// A body's angular velocity (rad/s), or None if it has none.
    fn angular_velocity_of(&self, e: Entity) -> Option<Vec3>;
    /// A body's mass (kg; computed from its colliders for a rigid body, infinite when
    /// pinned), or None if it has none.
    fn mass_of(&self, e: Entity) -> Option<f32>;
}

impl PhysicsTestExt for World {
    fn steps_for(&self, seconds: f64) -> Result<u64> {
        let time = self.get_resource::<PhysicsTime>().ok_or(Error::NoPhysics)?;
        // Checked as f32 (past f32::MAX it is infinite there too); counted in f64.
        let t = crate::core::error::non_negative("run time", seconds as f32)?;
        let steps = (seconds / f64::from(time.dt())).round();
        // A finite but huge time (1e30 s) would be a loop no test ever leaves.
        if steps > f64::from(u32::MAX) {
            return Err(Error::OutOfRange {
                what: "run time (s)",
                value: t,
                range: "at most 2^32 - 1 steps",
            });
        }
        Ok(steps as u64)
    }

    fn run_for_seconds(&mut self, seconds: f64) -> Result<u64> {
        let n = self.steps_for(seconds)?;
        for _ in 0..n {
            self.step_physics();
        }
        Ok(n)
    }

    fn run_until(
        &mut self,
        max_seconds: f64,
        mut done: impl FnMut(&World) -> bool,
    ) -> Result<Option<u64>> {
        let n = self.steps_for(max_seconds)?;
        if done(self) {
            return Ok(Some(0));
        }
        for step in 1..=n {
            self.step_physics();
            if done(self) {
                return Ok(Some(step));
            }
        }
        Ok(None)
    }

    fn position_of(&self, e: Entity) -> Option<Vec3> {
        self.get::<Position>(e).map(|x| Vec3::from(x.0))
    }

    fn rotation_of(&self, e: Entity) -> Option<Quat> {
        self.get::<Rotation>(e).map(|q| q.0)
    }

    fn velocity_of(&self, e: Entity) -> Option<Vec3> {
        self.get::<LinearVelocity>(e).map(|v| Vec3::from(v.0))
    }

    fn angular_velocity_of(&self, e: Entity) -> Option<Vec3> {
        self.get::<AngularVelocity>(e).map(AngularVelocity::get)
    }

    fn mass_of(&self, e: Entity) -> Option<f32> {
        self.get::<crate::particles::Mass>(e).map(|m| {
            if m.is_pinned() {
                f32::INFINITY
            } else {
                m.value()
            }
        })
    }
}
