//! The kernel: what every effect stands on, and which names no effect.
//!
//! - [`schedule`]: the schedules and system sets, chained in one place;
//! - [`time`]: the fixed step, substeps and the frame accumulator;
//! - [`plugin`]: [`WorldPlugin`], the kernel's [`PhysicsCorePlugin`], its registries (messages,
//!   moving components) and one step;
//! - [`error`]: the typed errors of every constructor;
//! - [`quarantine`]: bodies whose state turned non-finite or ran away, taken out and reported;
//! - [`restore`]: resources game code removed, put back;
//! - [`rest`]: the sleeping state every integrating system skips;
//! - [`diagnostics`]: the diagnostics resource each effect writes its energy into;
//! - [`whole_step`]: the hook through which an effect may run a whole step's substeps.
//!
//! Effects (particles, rigid bodies, integrators, springs, collisions, soft bodies, cloth)
//! are modules above this one; they register what the kernel needs to know of them.

pub mod diagnostics;
pub mod error;
pub(crate) mod order;
pub mod plugin;
pub mod quarantine;
pub mod rest;
pub mod restore;
pub mod schedule;
pub mod time;
pub mod whole_step;

pub use plugin::{PhysicsCorePlugin, WorldPlugin};
