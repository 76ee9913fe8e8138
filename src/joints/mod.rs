//! Joints: constraints that hold two rigid bodies (or a body and the world) together at an
//! anchor, solved in the substep passes beside the contacts.
//!
//! | joint | holds | leaves free |
//! |---|---|---|
//! | [`SphericalJoint`] (ball) | the anchors together | every turn |
//! | [`RevoluteJoint`] (hinge) | the anchors together, the hinge axes aligned | the turn about the axis |
//! | [`FixedJoint`] | the anchors together, the relative rotation | nothing |
//!
//! A joint is an entity of its own: spawn `RevoluteJoint::new(door, frame).with_anchors(..)`
//! (or `::to_world(body)` for a body hinged to the world). Anchors are in each body's shape
//! frame (m), the frame whose origin is `x − R c` ([`crate::rigid::CenterOfMass`]); a world
//! side's anchor is a world point. A static, kinematic or sleeping side is held where it is
//! and takes no impulse. A joint naming a body that is gone or quarantined is inert (its
//! partner runs free, its [`JointImpulse`] reads zero) until the body is back; a joint with a
//! bad input (a non-finite anchor, a hinge axis not of unit length, a body joined to itself)
//! is quarantined on insert with an [`crate::Error`] saying which.
//!
//! **Solver.** Each substep, after the contacts' passes (see [`JointPlugin`]): the
//! accumulated impulse is applied again (warm start), then one biased pass pulls the anchors
//! together as a spring of [`JointSettings::hertz`] and damping ratio
//! [`JointSettings::damping_ratio`] would (Box2D v3's soft step), then, after the positions
//! move, one pass without bias removes the anchors' relative velocity. The relax pass is
//! rigid, so the soft bias adds no energy to the motion it leaves. Joints connected through
//! moving bodies are solved as one system (dense up to 96 rows, a tree in linear time past
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

mod block;
mod diagnostics;
mod plugin;
mod solve;
mod tree;

pub use diagnostics::JointDiagnostics;
pub use plugin::JointPlugin;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::core::error::{Error, Result, finite_vec};
use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::world::DeferredWorld;

use crate::core::quarantine::{Validate, validate_on_insert};

/// The two sides of a joint: `a` (or the world when `None`) and `b`.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
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

/// What every joint kind holds.
trait Joint: Component + Validate {
    fn bodies(&self) -> &JointBodies;
}

/// The two bodies of the joint on `entity`, when it keeps them from colliding.
fn excluded_pair<T: Joint>(world: &DeferredWorld, entity: Entity) -> Option<(Entity, Entity)> {
    let bodies = world.get::<T>(entity)?.bodies();
    match (bodies.a, bodies.collide) {
        (Some(a), false) => Some((a, bodies.b)),
        _ => None,
    }
}

/// Insert hook: validates the joint (quarantining it on a bad input) and keeps its bodies
/// from colliding.
fn joint_inserted<T: Joint>(mut world: DeferredWorld, ctx: HookContext) {
    validate_on_insert::<T>(world.reborrow(), ctx);
    if let Some((a, b)) = excluded_pair::<T>(&world, ctx.entity)
        && let Some(mut excluded) = world.get_resource_mut::<crate::collision::PairExclusions>()
    {
        excluded.add(a, b);
    }
}

/// Discard hook (a new value, a removal, a despawn): the old value's bodies may collide again.
fn joint_discarded<T: Joint>(mut world: DeferredWorld, ctx: HookContext) {
    if let Some((a, b)) = excluded_pair::<T>(&world, ctx.entity)
        && let Some(mut excluded) = world.get_resource_mut::<crate::collision::PairExclusions>()
    {
        excluded.remove(a, b);
    }
}

macro_rules! joint_builders {
    ($name:ident) => {
        impl $name {
            /// Places the anchors: on `a` (its shape frame, or a world point for a world
            /// joint) and on `b` (its shape frame), in m.
            #[must_use]
            pub fn with_anchors(mut self, anchor_a: Vec3, anchor_b: Vec3) -> Self {
                self.bodies.anchor_a = anchor_a;
                self.bodies.anchor_b = anchor_b;
                self
            }

            /// Lets the two bodies collide with each other (by default a joint's bodies do
            /// not).
            #[must_use]
            pub fn with_collision(mut self, collide: bool) -> Self {
                self.bodies.collide = collide;
                self
            }
        }

        impl Joint for $name {
            fn bodies(&self) -> &JointBodies {
                &self.bodies
            }
        }
    };
}

/// A ball joint: `b`'s anchor stays on `a`'s, every turn is free.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct SphericalJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
}

impl SphericalJoint {
    /// Joins `b` to `a`, both anchors at the bodies' shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity) -> Self {
        Self {
            bodies: JointBodies {
                a: Some(a),
                b,
                anchor_a: Vec3::ZERO,
                anchor_b: Vec3::ZERO,
                collide: false,
            },
        }
    }

    /// Joins `b` to the world; place the world point with [`Self::with_anchors`].
    #[must_use]
    pub fn to_world(b: Entity) -> Self {
        Self {
            bodies: JointBodies {
                a: None,
                b,
                anchor_a: Vec3::ZERO,
                anchor_b: Vec3::ZERO,
                collide: false,
            },
        }
    }
}
joint_builders!(SphericalJoint);

impl Validate for SphericalJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()
    }
}

/// A hinge: `b`'s anchor stays on `a`'s and `b`'s hinge axis stays along `a`'s; the turn
/// about the axis is free.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct RevoluteJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
    /// The hinge axis in `a`'s shape frame (world frame for a world joint); unit length.
    pub axis_a: Vec3,
    /// The hinge axis in `b`'s shape frame; unit length.
    pub axis_b: Vec3,
    /// A motor driving `b`'s turn relative to `a` about the axis, if any.
    #[serde(default)]
    pub motor: Option<AngularMotor>,
}

/// A motor on a hinge: it drives the turn of `b` relative to `a` about the hinge axis (axis
/// direction, right-handed) towards `target_velocity`, with at most `max_torque`. Solved in
/// every pass before the joint's other rows, as Box2D solves its motors.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct AngularMotor {
    /// The relative angular velocity it drives towards (rad/s).
    pub target_velocity: f32,
    /// The largest torque it exerts (N·m, ≥ 0).
    pub max_torque: f32,
}

impl RevoluteJoint {
    /// Hinges `b` on `a` about `axis` (the same direction in both shape frames: both bodies
    /// as spawned); anchors at the shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: SphericalJoint::new(a, b).bodies,
            axis_a: axis.normalize_or_zero(),
            axis_b: axis.normalize_or_zero(),
            motor: None,
        }
    }

    /// Hinges `b` to the world about `axis` (world frame, and `b`'s shape frame as spawned
    /// unturned); place the world point with [`Self::with_anchors`].
    #[must_use]
    pub fn to_world(b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: SphericalJoint::to_world(b).bodies,
            axis_a: axis.normalize_or_zero(),
            axis_b: axis.normalize_or_zero(),
            motor: None,
        }
    }

    /// Drives the hinge towards `target_velocity` (rad/s, `b` relative to `a`, right-handed
    /// about the axis) with at most `max_torque` (N·m).
    #[must_use]
    pub fn with_motor(mut self, target_velocity: f32, max_torque: f32) -> Self {
        self.motor = Some(AngularMotor {
            target_velocity,
            max_torque,
        });
        self
    }
}
joint_builders!(RevoluteJoint);

impl Validate for RevoluteJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        for (what, axis) in [("hinge axis a", self.axis_a), ("hinge axis b", self.axis_b)] {
            finite_vec(what, axis)?;
            if (axis.length() - 1.0).abs() > 1e-3 {
                return Err(Error::OutOfRange {
                    what,
                    value: axis.length(),
                    range: "length 1 (a unit vector)",
                });
            }
        }
        if let Some(m) = self.motor {
            crate::core::error::finite("motor target velocity", m.target_velocity)?;
            crate::core::error::finite("motor max torque", m.max_torque)?;
            crate::core::error::non_negative("motor max torque", m.max_torque)?;
        }
        Ok(())
    }
}

/// A weld: `b` keeps its anchor on `a`'s and its rotation relative to `a`.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct FixedJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
    /// `b`'s rotation in `a`'s frame (world frame for a world joint) to hold: q_b = q_a · this.
    pub relative: Quat,
}

impl FixedJoint {
    /// Welds `b` to `a` at the relative rotation `relative` (q_b = q_a · relative).
    #[must_use]
    pub fn new(a: Entity, b: Entity, relative: Quat) -> Self {
        Self {
            bodies: SphericalJoint::new(a, b).bodies,
            relative,
        }
    }

    /// Welds `b` to the world at rotation `rotation`.
    #[must_use]
    pub fn to_world(b: Entity, rotation: Quat) -> Self {
        Self {
            bodies: SphericalJoint::to_world(b).bodies,
            relative: rotation,
        }
    }
}
joint_builders!(FixedJoint);

impl Validate for FixedJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        crate::rigid::Rotation::try_new(self.relative).map(|_| ())
    }
}

/// The impulse a joint applied to `b` in the last substep (`a` took the opposite), kept for
/// the next substep's warm start.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
pub struct JointImpulse {
    /// Linear impulse at `b`'s anchor (N·s, world frame).
    pub linear: Vec3,
    /// Angular impulse about `b`'s anchor (N·m·s, world frame).
    pub angular: Vec3,
    /// The substep length it was applied over (s).
    pub h: f32,
    /// A hinge motor's angular impulse about the hinge axis (N·m·s).
    #[serde(default)]
    pub motor: f32,
}

impl JointImpulse {
    /// The force the joint exerts on `b` (N, world frame).
    #[must_use]
    pub fn force(&self) -> Vec3 {
        if self.h > 0.0 {
            self.linear / self.h
        } else {
            Vec3::ZERO
        }
    }

    /// The torque a hinge's motor exerts on `b` about the hinge axis (N·m).
    #[must_use]
    pub fn motor_torque(&self) -> f32 {
        if self.h > 0.0 {
            self.motor / self.h
        } else {
            0.0
        }
    }

    /// The torque the joint's rows (not its motor) exert on `b` about its anchor (N·m,
    /// world frame).
    #[must_use]
    pub fn torque(&self) -> Vec3 {
        if self.h > 0.0 {
            self.angular / self.h
        } else {
            Vec3::ZERO
        }
    }
}

/// How stiffly the joints' biased pass pulls drifted anchors back.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
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
