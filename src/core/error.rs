//! The crate's typed error.
//!
//! Every fallible constructor in hooke returns `Result<_, hooke::Error>`; nothing at the API
//! edge panics on bad numbers. Each variant names the offending quantity so a game can show
//! the message to a designer as is.

use bevy_ecs::entity::Entity;

/// Everything that can be wrong with input handed to hooke.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A scalar or vector input was NaN or infinite.
    #[error("{what} must be finite, got {value}")]
    NonFinite {
        /// Which input, e.g. `"position"` or `"spring stiffness"`.
        what: &'static str,
        /// The value as text (vectors print all components).
        value: String,
    },
    /// A mass was zero, negative or not finite. Use `Mass::PINNED` for an immovable body.
    #[error("mass must be positive and finite (kg), got {0}")]
    InvalidMass(f32),
    /// A quantity that must not be negative was negative.
    #[error("{what} must be >= 0, got {value}")]
    Negative {
        /// Which input, e.g. `"rest length"`.
        what: &'static str,
        /// The rejected value.
        value: f32,
    },
    /// A quantity that must be strictly positive was zero or negative.
    #[error("{what} must be > 0, got {value}")]
    NotPositive {
        /// Which input, e.g. `"rest length"` for the strain-form spring law.
        what: &'static str,
        /// The rejected value.
        value: f32,
    },
    /// A mesh file could not be read or is malformed.
    #[error("{file}:{line}: {message}")]
    MeshFile {
        /// The file (or `.node`, `.ele`, `.msh` for text given directly).
        file: String,
        /// The 1-based line (0 when the file could not be read at all).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A tetrahedron of a mesh has repeated corners or (almost) no volume.
    #[error("tetrahedron {index} is degenerate (rest volume {volume} m³)")]
    DegenerateElement {
        /// Which tetrahedron.
        index: usize,
        /// Its signed rest volume (m³).
        volume: f32,
    },
    /// A triangle of a cloth mesh has repeated corners or (almost) no area.
    #[error("triangle {index} is degenerate (rest area {area} m²)")]
    DegenerateTriangle {
        /// Which triangle.
        index: usize,
        /// Its rest area (m²).
        area: f32,
    },
    /// A quantity was outside its allowed range.
    #[error("{what} must satisfy {range}, got {value}")]
    OutOfRange {
        /// Which input, e.g. `"Poisson ratio"`.
        what: &'static str,
        /// The rejected value.
        value: f32,
        /// The allowed range, as text.
        range: &'static str,
    },
    /// A spring was asked to join an entity to itself.
    #[error("a spring cannot connect entity {0} to itself")]
    SelfSpring(Entity),
    /// A joint was asked to join an entity to itself.
    #[error("a joint cannot join entity {0} to itself")]
    SelfJoint(Entity),
    /// A spring endpoint does not exist, or is not a body (has no `Position`).
    #[error("spring endpoint {0} does not exist or has no Position")]
    MissingEntity(Entity),
    /// The fixed time step was zero, negative or not finite.
    #[error("time step must be positive and finite (s), got {0}")]
    InvalidTimeStep(f32),
    /// A step was asked to run zero substeps.
    #[error("substeps must be at least 1")]
    ZeroSubsteps,
    /// A builder was asked for fewer elements than it needs (e.g. a rope of 1 node).
    #[error("{what} needs at least {min}, got {got}")]
    TooFew {
        /// What was counted, e.g. `"rope nodes"`.
        what: &'static str,
        /// The smallest accepted count.
        min: usize,
        /// The count given.
        got: usize,
    },
    /// A count past its documented bound (substeps per step, steps per frame, cells, ...):
    /// refused before anything is allocated or run.
    #[error("{what} may be at most {max}, got {got}")]
    TooMany {
        /// What was counted, e.g. `"substeps per step"`.
        what: &'static str,
        /// The largest accepted count.
        max: u64,
        /// The count given.
        got: u64,
    },
    /// A shape has no volume (flat, open or a heightfield), so it has no mass to simulate.
    #[error("shape {0} has no volume, so it has no mass; give explicit mass properties")]
    ZeroVolume(String),
    /// A compound's part (or a body's child collider) is itself composite: a compound,
    /// triangle mesh or heightfield, which parry cannot nest.
    #[error(
        "a {0} cannot be part of a compound (parry does not nest composite shapes); use convex parts"
    )]
    CompositePart(String),
    /// An index into a mesh's node arrays was out of range.
    #[error("{what} index {index} is out of range for {len} nodes")]
    IndexOutOfRange {
        /// Which index, e.g. `"spring endpoint"`.
        what: &'static str,
        /// The rejected index.
        index: usize,
        /// The number of nodes.
        len: usize,
    },
    /// A component a simulated body needs was removed from it (e.g. [`crate::particles::Mass`] from a
    /// particle or a dynamic body).
    #[error("the body's {0} was removed; insert one and remove Quarantined to simulate it again")]
    ComponentRemoved(&'static str),
    /// The world has no physics: add the plugins first (`world.add_physics(PhysicsPlugins)`).
    #[error("the world has no physics: call add_physics(PhysicsPlugins) first")]
    NoPhysics,
    /// A motor was set on a joint that takes none (only hinges and sliders do), or on one
    /// that is gone.
    #[error("{0} is not a hinge or a slider: only they take a motor")]
    NoMotor(Entity),
    /// An error read back from a snapshot (the message of the error it was).
    #[error("{0}")]
    Restored(String),

    /// A Bevy mesh a collider cannot be made from (feature `collider-from-mesh`).
    #[error("cannot make a collider from {0}")]
    UnsupportedMesh(String),
}

/// Shorthand for hooke results.
pub type Result<T, E = Error> = core::result::Result<T, E>;

/// Checks that a scalar is finite.
pub(crate) fn finite(what: &'static str, value: f32) -> Result<f32> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite {
            what,
            value: value.to_string(),
        })
    }
}

/// Checks that a vector is finite.
pub(crate) fn finite_vec(what: &'static str, value: glam::Vec3) -> Result<glam::Vec3> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite {
            what,
            value: format!("{value}"),
        })
    }
}

/// Checks that a scalar is finite and not negative.
pub(crate) fn non_negative(what: &'static str, value: f32) -> Result<f32> {
    finite(what, value)?;
    if value < 0.0 {
        Err(Error::Negative { what, value })
    } else {
        Ok(value)
    }
}

/// Checks that a scalar is finite and strictly positive.
pub(crate) fn positive(what: &'static str, value: f32) -> Result<f32> {
    finite(what, value)?;
    if value <= 0.0 {
        Err(Error::NotPositive { what, value })
    } else {
        Ok(value)
    }
}
