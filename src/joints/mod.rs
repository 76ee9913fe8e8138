//! Joints: constraints that hold two rigid bodies (or a body and the world) together at an
//! anchor, solved in the substep passes beside the contacts.
//!
//! | joint | holds | leaves free |
//! |---|---|---|
//! | [`SphericalJoint`] (ball) | the anchors together | every turn (within a cone and a twist range if limited) |
//! | [`RevoluteJoint`] (hinge) | the anchors together, the hinge axes aligned | the turn about the axis |
//! | [`PrismaticJoint`] (slider) | the relative rotation, `b`'s anchor on `a`'s axis | the slide along the axis |
//! | [`DistanceJoint`] (rod, rope) | the anchors' distance within its limits | every turn |
//! | [`FixedJoint`] | the anchors together, the relative rotation | nothing |
//!
//! A hinge's angle, a slider's offset and a distance joint's length are a joint's free axis:
//! it takes [`JointLimits`] (`with_limits`) and, on hinges and sliders, a motor
//! (`with_motor`: [`AngularMotor`], [`LinearMotor`]), solved before the locked rows. A ball
//! joint takes a cone (`with_swing_limit`), a twist range (`with_twist_limits`) about its
//! axis, and friction (`with_friction`).
//!
//! A joint is an entity of its own: spawn `RevoluteJoint::new(door, frame).with_anchors(..)`
//! (or `::to_world(body)` for a body hinged to the world). Anchors are in each body's shape
//! frame (m), the frame whose origin is `x − R c` ([`crate::rigid::CenterOfMass`]); a world
//! side's anchor is a world point. A static, kinematic or sleeping side is held where it is
//! and takes no impulse. A joint naming a body that is gone or quarantined is inert (its
//! partner runs free, its [`JointImpulse`] reads zero) until the body is back; a joint with a
//! bad input (a non-finite anchor, an axis not of unit length, limits with min > max, a body
//! joined to itself)
//! is quarantined on insert with an [`crate::Error`] saying which.
//!
//! **Solver.** Each substep, after the contacts' passes (see [`JointPlugin`]): the
//! accumulated impulse is applied again (warm start), then one biased pass pulls the anchors
//! together as a spring of [`JointSettings::hertz`] and damping ratio
//! [`JointSettings::damping_ratio`] would (Box2D v3's soft step), then, after the positions
//! move, one pass without bias removes the anchors' relative velocity. The relax pass is
//! rigid, so the soft bias adds no energy to the motion it leaves. Joints connected through
//! moving bodies are solved as one system (dense up to 128 rows, a tree in linear time past
//! that; a net of loops joint after joint), and each pass turns a jointed body with its
//! inertia stiffened by its joints' pull (see `solve.rs`), which keeps light links under
//! heavy loads in line. [`JointDiagnostics`] reports how well the joints hold.
//!
//! [`JointImpulse`] (required by every joint) holds the impulse of the last substep; its
//! [`JointImpulse::force`] and [`JointImpulse::torque`] are the joint's force and torque.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! let rod = world
//!     .spawn((
//!         RigidBody::Dynamic,
//!         Collider::cuboid(0.05, 0.5, 0.05).unwrap(),
//!         Position(Vec3A::new(0.0, 1.5, 0.0)),
//!     ))
//!     .id();
//! // Hinged at its top end (0.5 m above its centre) to the world point (0, 2, 0), about z.
//! let hinge = world
//!     .spawn(
//!         RevoluteJoint::to_world(rod, Vec3::Z)
//!             .with_anchors(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.5, 0.0)),
//!     )
//!     .id();
//! world.step_physics();
//! // Hanging at rest, the hinge carries the rod's weight (1000 kg/m³ × 0.01 m³ × 9.81 m/s²).
//! let force = world.get::<JointImpulse>(hinge).unwrap().force();
//! assert!((force.y - 98.1).abs() < 0.5, "{force}");
//! ```

mod axial;
mod block;
mod breaking;
mod diagnostics;
mod envelope;
mod graph;
mod kinds;
mod plugin;
mod solve;

pub use breaking::{JointBreakForce, JointBroken};
pub use diagnostics::JointDiagnostics;
pub use kinds::{
    AngularMotor, DistanceJoint, FixedJoint, JointLimits, LinearMotor, MotorSpring, PrismaticJoint,
    RevoluteJoint, SphericalJoint,
};
pub(crate) use kinds::{Kinds, bodies};
pub use plugin::JointPlugin;

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::core::error::{Error, Result, finite_vec};
use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::world::DeferredWorld;

use crate::core::quarantine::{Validate, validate_on_insert};

/// The two sides of a joint: `a` (or the world when `None`) and `b`.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct JointBodies {
    /// The first body; `None` joins `b` to the world.
    pub a: Option<Entity>,
    /// The second body.
    pub b: Entity,
    /// Anchor on `a` (m, `a`'s shape frame; a world point when `a` is `None`).
    pub anchor_a: Vec3,
    /// Anchor on `b` (m, `b`'s shape frame).
    pub anchor_b: Vec3,
    /// Whether `a` and `b` still collide with each other (by default they do not).
    pub collide: bool,
}

impl JointBodies {
    fn validate(&self) -> Result<()> {
        finite_vec("joint anchor a", self.anchor_a)?;
        finite_vec("joint anchor b", self.anchor_b)?;
        if self.a == Some(self.b) {
            return Err(Error::SelfJoint(self.b));
        }
        Ok(())
    }
}

/// What every joint kind is.
trait Joint: Component + Validate + kinds::Describe {}

/// The two bodies of the joint on `entity`, when it keeps them from colliding.
fn excluded_pair<T: Joint>(world: &DeferredWorld, entity: Entity) -> Option<(Entity, Entity)> {
    let bodies = world.get::<T>(entity)?.bodies();
    match (bodies.a, bodies.collide) {
        (Some(a), false) => Some((a, bodies.b)),
        _ => None,
    }
}

/// Wakes the bodies of the joint on `entity`: a joint put on or taken off a sleeping body
/// changes what holds it.
fn wake_sides<T: Joint>(world: &mut DeferredWorld, entity: Entity) {
    // A restore writes the joints beside the sleep state it captured.
    if world.contains_resource::<crate::core::restore::Restoring>() {
        return;
    }
    let Some(bodies) = world.get::<T>(entity).map(|j| *j.bodies()) else {
        return;
    };
    for e in bodies.a.into_iter().chain([bodies.b]) {
        crate::core::rest::wake(world, e);
    }
}

/// Insert hook: validates the joint (quarantining it on a bad input), keeps its bodies
/// from colliding and wakes them.
fn joint_inserted<T: Joint>(mut world: DeferredWorld, ctx: HookContext) {
    validate_on_insert::<T>(world.reborrow(), ctx);
    wake_sides::<T>(&mut world, ctx.entity);
    if let Some((a, b)) = excluded_pair::<T>(&world, ctx.entity)
        && let Some(mut excluded) = world.get_resource_mut::<crate::collision::PairExclusions>()
    {
        excluded.add(a, b);
    }
}

/// Discard hook (a new value, a removal, a despawn, a break): the old value's bodies may
/// collide again, and wake.
fn joint_discarded<T: Joint>(mut world: DeferredWorld, ctx: HookContext) {
    wake_sides::<T>(&mut world, ctx.entity);
    if let Some((a, b)) = excluded_pair::<T>(&world, ctx.entity)
        && let Some(mut excluded) = world.get_resource_mut::<crate::collision::PairExclusions>()
    {
        excluded.remove(a, b);
    }
}

/// The impulse a joint applied to `b` in the last substep (`a` took the opposite), kept for
/// the next substep's warm start. [`Self::force`] and [`Self::torque`] read the whole joint;
/// the fields hold its parts.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct JointImpulse {
    /// The locked rows' linear impulse at `b`'s anchor (N·s, world frame).
    pub linear: Vec3,
    /// The locked rows' angular impulse (N·m·s, world frame).
    pub angular: Vec3,
    /// The substep length it was applied over (s).
    pub h: f32,
    /// The motor's impulse along the free axis (N·m·s for a hinge, N·s for a slider).
    #[serde(default)]
    pub motor: f32,
    /// The lower limit's impulse along the free axis (≥ 0, towards larger values).
    #[serde(default)]
    pub lower: f32,
    /// The upper limit's impulse along the free axis (≥ 0, towards smaller values).
    #[serde(default)]
    pub upper: f32,
    /// A ball joint's cone limit's impulse (≥ 0, N·m·s, closing the cone).
    #[serde(default)]
    pub swing: f32,
    /// A ball joint's friction's angular impulse (N·m·s, world frame).
    #[serde(default)]
    pub friction: Vec3,
    /// The motor's and limits' impulse as a world vector: linear (N·s; a slider, a distance
    /// joint) ...
    #[serde(default)]
    pub axial_linear: Vec3,
    /// ... or angular (N·m·s; a hinge).
    #[serde(default)]
    pub axial_angular: Vec3,
}

impl JointImpulse {
    fn per_second<T: std::ops::Div<f32, Output = T> + Default>(&self, impulse: T) -> T {
        if self.h > 0.0 {
            impulse / self.h
        } else {
            T::default()
        }
    }

    /// The force the joint exerts on `b` (N, world frame), its motor and limits included.
    #[must_use]
    pub fn force(&self) -> Vec3 {
        self.per_second(self.linear + self.axial_linear)
    }

    /// The torque the joint exerts on `b` about its anchor (N·m, world frame), its motor
    /// and limits included.
    #[must_use]
    pub fn torque(&self) -> Vec3 {
        self.per_second(self.angular + self.axial_angular)
    }

    /// The torque a hinge's motor exerts on `b` about the hinge axis (N·m).
    #[must_use]
    pub fn motor_torque(&self) -> f32 {
        self.per_second(self.motor)
    }

    /// The force a slider's motor exerts on `b` along the axis (N).
    #[must_use]
    pub fn motor_force(&self) -> f32 {
        self.per_second(self.motor)
    }

    /// What the limits exert on `b` along the free axis (N or N·m; positive towards larger
    /// values): nonzero while the joint stands at a limit.
    #[must_use]
    pub fn limit_force(&self) -> f32 {
        self.per_second(self.lower - self.upper)
    }
}

/// How stiffly the joints' biased pass pulls drifted anchors back.
///
/// Joints solved one at a time (motors, a net's loop joints) are soft springs of this
/// frequency and damping ratio (Box2D's soft step). A group of joints solved as one system
/// takes only the rate at which such a spring closes a gap: it holds its whole load, so a
/// load does not stretch it (see `docs/joints.md`, "Exact groups are not springs").
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct JointSettings {
    /// Frequency of the correcting spring (Hz), capped at a quarter of the substep rate.
    /// Zero or less: no correction of drift (velocities only).
    pub hertz: f32,
    /// Its damping ratio.
    pub damping_ratio: f32,
}

impl Default for JointSettings {
    /// Box2D v3's: 60 Hz, damping ratio 2 (at 60 Hz × 4 substeps the cap is 60 Hz).
    fn default() -> Self {
        Self {
            hertz: 60.0,
            damping_ratio: 2.0,
        }
    }
}
