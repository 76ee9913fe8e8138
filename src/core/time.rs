//! Fixed time step, substeps and the frame accumulator.
//!
//! A physics step has a fixed length `dt` (s) split into `substeps` substeps of length
//! h = dt / substeps. A game's frames have whatever length they have: [`PhysicsTime`] keeps an
//! accumulator, and [`crate::plugins::PhysicsWorldExt::advance_physics`] runs as many whole steps as
//! fit, at most `max_steps_per_frame`, so that one slow frame cannot make the next one slower
//! still (the "spiral of death"). Time beyond the cap is dropped and reported.

use bevy_ecs::prelude::*;

use crate::core::error::{Error, Result};

/// The fixed step and the simulation clock. Read from a file (a snapshot), it is checked as
/// [`PhysicsTime::new`] checks its input.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
#[serde(try_from = "TimeRecord")]
pub struct PhysicsTime {
    dt: f32,
    substeps: u32,
    max_steps_per_frame: u32,
    accumulator: f32,
    elapsed: f64,
    steps: u64,
}

impl Default for PhysicsTime {
    /// 60 Hz, four substeps (h = 1/240 s), at most 4 steps per frame. Four substeps are what
    /// stiff springs and stacked contacts need at 60 Hz (contacts are capped at an eighth of
    /// the substep rate: 30 Hz here); a scene of loose particles can use one.
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            substeps: 4,
            max_steps_per_frame: 4,
            accumulator: 0.0,
            elapsed: 0.0,
            steps: 0,
        }
    }
}

/// [`PhysicsTime`] as a file holds it, checked on the way in.
#[derive(serde::Deserialize)]
struct TimeRecord {
    dt: f32,
    substeps: u32,
    max_steps_per_frame: u32,
    accumulator: f32,
    elapsed: f64,
    steps: u64,
}

impl TryFrom<TimeRecord> for PhysicsTime {
    type Error = Error;

    fn try_from(r: TimeRecord) -> Result<Self> {
        let time =
            PhysicsTime::new(r.dt, r.substeps)?.with_max_steps_per_frame(r.max_steps_per_frame)?;
        if !(r.accumulator.is_finite() && r.accumulator >= 0.0) {
            return Err(Error::NonFinite {
                what: "time accumulator",
                value: r.accumulator.to_string(),
            });
        }
        if !r.elapsed.is_finite() {
            return Err(Error::NonFinite {
                what: "elapsed time",
                value: r.elapsed.to_string(),
            });
        }
        Ok(Self {
            accumulator: r.accumulator,
            elapsed: r.elapsed,
            steps: r.steps,
            ..time
        })
    }
}

impl PhysicsTime {
    /// The most substeps a step may be split into: 4096 (h = 4 µs at 60 Hz). A count past
    /// it would make a step take minutes, or never return.
    pub const MAX_SUBSTEPS: u32 = 4096;

    /// The most steps one frame may catch up on: 1024.
    pub const MAX_STEPS_PER_FRAME: u32 = 1024;

    /// A fixed step of `dt` seconds split into `substeps` substeps.
    ///
    /// # Errors
    /// [`Error::InvalidTimeStep`] if `dt` is not positive and finite, [`Error::ZeroSubsteps`]
    /// if `substeps` is 0, [`Error::TooMany`] past [`PhysicsTime::MAX_SUBSTEPS`].
    pub fn new(dt: f32, substeps: u32) -> Result<Self> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidTimeStep(dt));
        }
        if substeps == 0 {
            return Err(Error::ZeroSubsteps);
        }
        if substeps > Self::MAX_SUBSTEPS {
            return Err(Error::TooMany {
                what: "substeps per step",
                max: Self::MAX_SUBSTEPS.into(),
                got: substeps.into(),
            });
        }
        Ok(Self {
            dt,
            substeps,
            ..Default::default()
        })
    }

    /// Caps how many steps one call to `advance_physics` may run (1 to
    /// [`PhysicsTime::MAX_STEPS_PER_FRAME`]).
    ///
    /// # Errors
    /// [`Error::TooFew`] for 0, [`Error::TooMany`] past the bound.
    pub fn with_max_steps_per_frame(mut self, max: u32) -> Result<Self> {
        if max == 0 {
            return Err(Error::TooFew {
                what: "steps per frame",
                min: 1,
                got: 0,
            });
        }
        if max > Self::MAX_STEPS_PER_FRAME {
            return Err(Error::TooMany {
                what: "steps per frame",
                max: Self::MAX_STEPS_PER_FRAME.into(),
                got: max.into(),
            });
        }
        self.max_steps_per_frame = max;
        Ok(self)
    }

    /// Step length (s).
    #[must_use]
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// Substeps per step.
    #[must_use]
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Substep length h = dt / substeps (s).
    #[must_use]
    pub fn substep_dt(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    /// Simulated time (s), counted in f64 so that long sessions keep their precision.
    #[must_use]
    pub fn elapsed(&self) -> f64 {
        self.elapsed
    }

    /// Advances the clock by one step of `dt`.
    pub(crate) fn end_step(&mut self) {
        self.elapsed += f64::from(self.dt);
        self.steps += 1;
    }

    /// Whole steps taken.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Steps allowed per frame.
    #[must_use]
    pub fn max_steps_per_frame(&self) -> u32 {
        self.max_steps_per_frame
    }

    /// Frame time not yet simulated (s); always less than `dt` after a frame.
    #[must_use]
    pub fn accumulator(&self) -> f32 {
        self.accumulator
    }

    /// Follows an outside fixed clock (Bevy's `Time<Fixed>`): the next step is `dt` long and
    /// starts at `start` (s). An invalid `dt` leaves the step length as it was.
    #[cfg(feature = "bevy")]
    pub(crate) fn follow(&mut self, dt: f32, start: f64) {
        if dt.is_finite() && dt > 0.0 {
            self.dt = dt;
        }
        self.elapsed = start;
    }

    /// Sets the clock to an outside clock's reading after a step, so the two never drift.
    #[cfg(feature = "bevy")]
    pub(crate) fn set_elapsed(&mut self, t: f64) {
        self.elapsed = t;
    }

    /// Adds frame time and returns how many steps to run and how much time was dropped.
    pub(crate) fn take_frame(&mut self, frame_dt: f32) -> Result<(u32, f32)> {
        if !(frame_dt.is_finite() && frame_dt >= 0.0) {
            return Err(Error::InvalidTimeStep(frame_dt));
        }
        self.accumulator += frame_dt;
        let wanted = (self.accumulator / self.dt).floor();
        let steps = wanted.min(self.max_steps_per_frame as f32) as u32;
        self.accumulator -= steps as f32 * self.dt;
        let mut dropped = 0.0;
        if self.accumulator >= self.dt {
            // Keep the fractional remainder so the next frame stays in phase; drop the rest.
            let keep = self.accumulator % self.dt;
            dropped = self.accumulator - keep;
            self.accumulator = keep;
        }
        Ok((steps, dropped))
    }
}

/// The current substep: its length and start time. Read by time-dependent effects.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct SubstepTime {
    /// Substep length h (s).
    pub h: f32,
    /// Simulated time at the start of this substep (s).
    pub t: f32,
    /// Which substep of the step this is, from 0.
    pub index: u32,
    /// Substeps in the step.
    pub count: u32,
}

impl SubstepTime {
    /// True in the last substep of a step.
    #[must_use]
    pub fn is_last(&self) -> bool {
        self.index + 1 >= self.count
    }
}

/// What one call to `advance_physics` did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameReport {
    /// Whole steps run.
    pub steps: u32,
    /// Frame time thrown away because the step cap was reached (s).
    pub dropped: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_steps_are_typed_errors() {
        assert_eq!(
            PhysicsTime::new(0.0, 1).unwrap_err(),
            Error::InvalidTimeStep(0.0)
        );
        assert!(matches!(
            PhysicsTime::new(f32::NAN, 1),
            Err(Error::InvalidTimeStep(_))
        ));
        assert!(matches!(
            PhysicsTime::new(-0.1, 1),
            Err(Error::InvalidTimeStep(_))
        ));
        assert_eq!(PhysicsTime::new(0.01, 0).unwrap_err(), Error::ZeroSubsteps);
        assert!(PhysicsTime::default().with_max_steps_per_frame(0).is_err());
    }

    #[test]
    fn accumulator_caps_steps_and_keeps_phase() {
        let mut t = PhysicsTime::new(0.01, 1)
            .unwrap()
            .with_max_steps_per_frame(3)
            .unwrap();
        assert_eq!(t.take_frame(0.025).unwrap().0, 2);
        assert!((t.accumulator() - 0.005).abs() < 1e-6);
        let (steps, dropped) = t.take_frame(1.0).unwrap();
        assert_eq!(steps, 3);
        assert!(dropped > 0.96 && dropped < 0.98, "dropped {dropped}");
        assert!(t.accumulator() < t.dt());
        assert!(t.take_frame(f32::NAN).is_err());
        assert!(t.take_frame(-1.0).is_err());
    }
}
