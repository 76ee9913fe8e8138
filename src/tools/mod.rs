//! Tools on top of the physics: nothing below names them, and the physics compiles without
//! them (the default `tools` feature).
//!
//! - [`scenes`]: the scene builders shared by tests, examples, benchmarks and scenarios;
//! - [`box3d`]: Box3D's benchmark scenes (large_pyramid, many_pyramids, convex_pile);
//! - [`character_scenes`]: a course of stairs, ramps and a crate for the character controller;
//! - [`hook_scenes`]: collision hooks a platformer writes (a one-way platform, a conveyor
//!   belt) and a scene for them;
//! - [`joint_scenes`]: jointed scenes (a chain hanging a load, ragdolls, a plank bridge, a
//!   door, a car), the chain and the ragdolls built alike in hooke and rapier;
//! - [`scenario`]: RON files that build a scene, act on it on a timeline and check
//!   expectations (the `hooke` command runs them, with the `cli` feature);
//! - [`accuracy`]: the accuracy sweep, error against closed forms for each setting of the dial;
//! - [`testing`]: helpers a `#[test]` steps a world with;
//! - `plot` (feature `plot`): the font, axes and legend every chart of hooke's shares.

pub mod accuracy;
pub mod box3d;
pub mod character_scenes;
pub mod hook_scenes;
pub mod joint_scenes;
#[cfg(feature = "plot")]
pub mod plot;
pub mod scenario;
pub mod scenes;
pub mod testing;
