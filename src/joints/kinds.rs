//! The joint kinds, their motors and limits.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};

use super::solve::{Angular, Axial, Axis, Linear, Rows, Swing};
use super::{Joint, JointBodies, JointImpulse, joint_discarded, joint_inserted};
use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::Validate;

/// What the solver reads of a joint: its sides, and the rows it holds.
pub(super) trait Describe {
    fn bodies(&self) -> &JointBodies;
    /// Its locked angular rows, locked linear rows, and free axis.
    fn rows(&self) -> (Angular, Linear, Axial);

    /// Its rows with the anchors `local_a`, `local_b` measured from the centres of mass.
    fn rows_at(&self, local_a: Vec3A, local_b: Vec3A) -> Rows {
        let (angular, linear, axial) = self.rows();
        Rows {
            local_a,
            local_b,
            angular,
            linear,
            axial,
        }
    }
}

impl<T: Describe + Component + Validate> Joint for T {}

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
    };
}

fn sides(a: Option<Entity>, b: Entity) -> JointBodies {
    JointBodies {
        a,
        b,
        anchor_a: Vec3::ZERO,
        anchor_b: Vec3::ZERO,
        collide: false,
    }
}

/// Checks that `axis` is a finite unit vector.
fn unit(what: &'static str, axis: Vec3) -> Result<()> {
    finite_vec(what, axis)?;
    if (axis.length() - 1.0).abs() > 1e-3 {
        return Err(Error::OutOfRange {
            what,
            value: axis.length(),
            range: "length 1 (a unit vector)",
        });
    }
    Ok(())
}

/// The range a joint's free axis may move in: `min ≤ value ≤ max`, in rad for a hinge's
/// turn, in m for a slider's offset or a distance joint's length.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct JointLimits {
    /// The smallest value (rad or m).
    pub min: f32,
    /// The largest value (rad or m).
    pub max: f32,
}

impl JointLimits {
    fn validate(&self, what: &'static str, range: Option<(f32, f32, &'static str)>) -> Result<()> {
        finite(what, self.min)?;
        finite(what, self.max)?;
        if self.min > self.max {
            return Err(Error::OutOfRange {
                what,
                value: self.min,
                range: "min ≤ max",
            });
        }
        if let Some((low, high, range)) = range {
            for value in [self.min, self.max] {
                if !(low..=high).contains(&value) {
                    return Err(Error::OutOfRange { what, value, range });
                }
            }
        }
        Ok(())
    }

    fn pair(limits: Option<Self>) -> Option<(f32, f32)> {
        limits.map(|l| (l.min, l.max))
    }
}

/// A motor on a hinge: it drives the turn of `b` relative to `a` about the hinge axis (axis
/// direction, right-handed) towards `target_velocity`, with at most `max_torque`; with a
/// [`MotorSpring`], as a spring–damper towards an angle. Solved in every pass before the
/// joint's other rows, as Box2D solves its motors.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct AngularMotor {
    /// The relative angular velocity it drives towards (rad/s).
    pub target_velocity: f32,
    /// The largest torque it exerts (N·m, ≥ 0).
    pub max_torque: f32,
    /// A spring towards an angle (rad, within [−π, π]; N·m/rad, N·m·s/rad); without one the
    /// motor holds its target velocity rigidly.
    #[serde(default)]
    pub spring: Option<MotorSpring>,
}

/// A motor on a slider: it drives `b`'s slide relative to `a` along the axis towards
/// `target_velocity`, with at most `max_force`; with a [`MotorSpring`], as a spring–damper
/// towards an offset.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct LinearMotor {
    /// The relative velocity along the axis it drives towards (m/s).
    pub target_velocity: f32,
    /// The largest force it exerts (N, ≥ 0).
    pub max_force: f32,
    /// A spring towards an offset (m; N/m, N·s/m); without one the motor holds its target
    /// velocity rigidly.
    #[serde(default)]
    pub spring: Option<MotorSpring>,
}

/// A motor's spring: it exerts `stiffness (target − value) + damping (target velocity −
/// rate)`, within the motor's maximum, integrated implicitly (stable at any stiffness).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct MotorSpring {
    /// The angle (rad) or offset (m) it pulls towards.
    pub target: f32,
    /// Its stiffness (N·m/rad or N/m, ≥ 0).
    pub stiffness: f32,
    /// Its damping (N·m·s/rad or N·s/m, ≥ 0).
    pub damping: f32,
}

impl MotorSpring {
    fn validate(&self, target_range: Option<(f32, f32, &'static str)>) -> Result<()> {
        finite("motor spring target", self.target)?;
        if let Some((low, high, range)) = target_range
            && !(low..=high).contains(&self.target)
        {
            return Err(Error::OutOfRange {
                what: "motor spring target",
                value: self.target,
                range,
            });
        }
        for (what, value) in [
            ("motor spring stiffness", self.stiffness),
            ("motor spring damping", self.damping),
        ] {
            finite(what, value)?;
            non_negative(what, value)?;
        }
        Ok(())
    }

    fn numbers(spring: Option<Self>) -> Option<(f32, f32, f32)> {
        spring.map(|s| (s.target, s.stiffness, s.damping))
    }
}

fn validate_motor(target: f32, max: f32, what: &'static str) -> Result<()> {
    finite("motor target velocity", target)?;
    finite(what, max)?;
    non_negative(what, max).map(|_| ())
}

/// A ball joint: `b`'s anchor stays on `a`'s, every turn is free, within its cone and
/// twist limits if it has them.
///
/// The limits are about the joint's axis, `axis_a` on `a` and `axis_b` on `b` (`Vec3::Y`
/// in both shape frames unless set, a limb hanging along y): the **swing** is the angle
/// between the two axes, kept within a cone of half-angle [`Self::swing_limit`]; the
/// **twist** is `b`'s turn about its axis once that axis is swung back onto `a`'s by the
/// shortest arc (right-handed, rad), kept within [`Self::twist_limits`]. Both are zero
/// where `b` stands relative to `a` as when both were spawned with [`Self::new`] and one
/// axis.
///
/// ```
/// # use bevy_ecs::prelude::*;
/// # use hooke::prelude::*;
/// # let mut world = World::new();
/// # let (torso, arm) = (world.spawn_empty().id(), world.spawn_empty().id());
/// // A shoulder: the arm hangs along −y, swings up to 80° from it, twists ±30°.
/// let shoulder = SphericalJoint::new(torso, arm)
///     .with_axis(Vec3::NEG_Y)
///     .with_swing_limit(80_f32.to_radians())
///     .with_twist_limits(-30_f32.to_radians(), 30_f32.to_radians());
/// ```
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct SphericalJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
    /// The joint's axis in `a`'s shape frame (world frame for a world joint); unit length.
    #[serde(default = "y_axis")]
    pub axis_a: Vec3,
    /// The joint's axis in `b`'s shape frame; unit length.
    #[serde(default = "y_axis")]
    pub axis_b: Vec3,
    /// The cone's half-angle (rad, in (0, π)): the swing between the axes stays within it.
    #[serde(default)]
    pub swing_limit: Option<f32>,
    /// The range of the twist about the axis (rad, within [−π, π]).
    #[serde(default)]
    pub twist_limits: Option<JointLimits>,
    /// The largest torque (N·m) with which the joint resists turning (joint friction: a
    /// motor holding the relative spin at zero), if any.
    #[serde(default)]
    pub friction: Option<f32>,
}

fn y_axis() -> Vec3 {
    Vec3::Y
}

impl SphericalJoint {
    /// Joins `b` to `a`, both anchors at the bodies' shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity) -> Self {
        Self {
            bodies: sides(Some(a), b),
            axis_a: Vec3::Y,
            axis_b: Vec3::Y,
            swing_limit: None,
            twist_limits: None,
            friction: None,
        }
    }

    /// Joins `b` to the world; place the world point with [`Self::with_anchors`].
    #[must_use]
    pub fn to_world(b: Entity) -> Self {
        Self {
            bodies: sides(None, b),
            ..Self::new(b, b)
        }
    }

    /// Sets the joint's axis, the same direction in both shape frames (both bodies as
    /// spawned; for a world joint, the world frame and `b`'s frame unturned).
    #[must_use]
    pub fn with_axis(mut self, axis: Vec3) -> Self {
        self.axis_a = axis.normalize_or_zero();
        self.axis_b = self.axis_a;
        self
    }

    /// Keeps the swing, the angle between the sides' axes, within `max` (rad, in (0, π)).
    #[must_use]
    pub fn with_swing_limit(mut self, max: f32) -> Self {
        self.swing_limit = Some(max);
        self
    }

    /// Keeps the twist about the axis within `min..=max` (rad, within [−π, π]).
    #[must_use]
    pub fn with_twist_limits(mut self, min: f32, max: f32) -> Self {
        self.twist_limits = Some(JointLimits { min, max });
        self
    }

    /// Resists any relative turn with up to `max_torque` (N·m): joint friction, which lets a
    /// ragdoll's limbs come to rest (Box3D's humans use the same, a motor towards zero spin).
    #[must_use]
    pub fn with_friction(mut self, max_torque: f32) -> Self {
        self.friction = Some(max_torque);
        self
    }
}
joint_builders!(SphericalJoint);

impl Describe for SphericalJoint {
    fn bodies(&self) -> &JointBodies {
        &self.bodies
    }
    fn rows(&self) -> (Angular, Linear, Axial) {
        let (axis_a, axis_b) = (self.axis_a, self.axis_b);
        let axial = Axial {
            axis: self.twist_limits.map(|_| Axis::Twist { axis_a, axis_b }),
            limits: JointLimits::pair(self.twist_limits),
            swing: self.swing_limit.map(|max| Swing {
                axis_a,
                axis_b,
                max,
            }),
            friction: self.friction,
            ..Axial::NONE
        };
        (Angular::Free, Linear::Point, axial)
    }
}

impl Validate for SphericalJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        unit("ball joint axis a", self.axis_a)?;
        unit("ball joint axis b", self.axis_b)?;
        let pi = std::f32::consts::PI;
        if let Some(max) = self.swing_limit {
            finite("swing limit", max)?;
            if !(max > 0.0 && max < pi) {
                return Err(Error::OutOfRange {
                    what: "swing limit",
                    value: max,
                    range: "0 < swing limit < π",
                });
            }
        }
        if let Some(l) = self.twist_limits {
            l.validate("twist limits", Some((-pi, pi, "−π ≤ angle ≤ π")))?;
        }
        if let Some(f) = self.friction {
            validate_motor(0.0, f, "joint friction torque")?;
        }
        Ok(())
    }
}

/// A hinge: `b`'s anchor stays on `a`'s and `b`'s hinge axis stays along `a`'s; the turn
/// about the axis is free, within its limits if it has them.
///
/// The hinge's angle is `b`'s turn relative to `a` about `a`'s axis (right-handed, rad, in
/// (−π, π]), zero where `b` stands as it did relative to `a` when both were spawned with
/// [`Self::new`] (precisely: where `b`'s rotation is `a`'s times the shortest arc from
/// `axis_b` to `axis_a`).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
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
    /// The range of the hinge's angle (rad, within [−π, π]), if limited.
    #[serde(default)]
    pub limits: Option<JointLimits>,
}

impl RevoluteJoint {
    /// Hinges `b` on `a` about `axis` (the same direction in both shape frames: both bodies
    /// as spawned); anchors at the shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: sides(Some(a), b),
            axis_a: axis.normalize_or_zero(),
            axis_b: axis.normalize_or_zero(),
            motor: None,
            limits: None,
        }
    }

    /// Hinges `b` to the world about `axis` (world frame, and `b`'s shape frame as spawned
    /// unturned); place the world point with [`Self::with_anchors`].
    #[must_use]
    pub fn to_world(b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: sides(None, b),
            ..Self::new(b, b, axis)
        }
    }

    /// Drives the hinge towards `target_velocity` (rad/s, `b` relative to `a`, right-handed
    /// about the axis) with at most `max_torque` (N·m).
    #[must_use]
    pub fn with_motor(mut self, target_velocity: f32, max_torque: f32) -> Self {
        self.motor = Some(AngularMotor {
            target_velocity,
            max_torque,
            spring: None,
        });
        self
    }

    /// Drives the hinge towards the angle `target` (rad, within [−π, π]) as a spring of
    /// `stiffness` (N·m/rad) and `damping` (N·m·s/rad), with at most `max_torque` (N·m): a
    /// servo. Its period about the target is 2π √(I / stiffness) for I about the hinge.
    #[must_use]
    pub fn with_position_motor(
        mut self,
        target: f32,
        stiffness: f32,
        damping: f32,
        max_torque: f32,
    ) -> Self {
        self.motor = Some(AngularMotor {
            target_velocity: 0.0,
            max_torque,
            spring: Some(MotorSpring {
                target,
                stiffness,
                damping,
            }),
        });
        self
    }

    /// Keeps the hinge's angle within `min..=max` (rad, within [−π, π]).
    #[must_use]
    pub fn with_limits(mut self, min: f32, max: f32) -> Self {
        self.limits = Some(JointLimits { min, max });
        self
    }
}
joint_builders!(RevoluteJoint);

impl Describe for RevoluteJoint {
    fn bodies(&self) -> &JointBodies {
        &self.bodies
    }
    fn rows(&self) -> (Angular, Linear, Axial) {
        let (axis_a, axis_b) = (self.axis_a, self.axis_b);
        let axial = Axial {
            axis: Some(Axis::Turn { axis_a, axis_b }),
            limits: JointLimits::pair(self.limits),
            motor: self.motor.map(|m| {
                (
                    m.target_velocity,
                    m.max_torque,
                    MotorSpring::numbers(m.spring),
                )
            }),
            ..Axial::NONE
        };
        (Angular::Hinge { axis_a, axis_b }, Linear::Point, axial)
    }
}

impl Validate for RevoluteJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        unit("hinge axis a", self.axis_a)?;
        unit("hinge axis b", self.axis_b)?;
        if let Some(m) = self.motor {
            validate_motor(m.target_velocity, m.max_torque, "motor max torque")?;
            if let Some(spring) = m.spring {
                let pi = std::f32::consts::PI;
                spring.validate(Some((-pi, pi, "−π ≤ angle ≤ π")))?;
            }
        }
        if let Some(l) = self.limits {
            let pi = std::f32::consts::PI;
            l.validate("hinge limits", Some((-pi, pi, "−π ≤ angle ≤ π")))?;
        }
        Ok(())
    }
}

/// A slider: `b` keeps its rotation relative to `a` and its anchor on the line through
/// `a`'s anchor along `a`'s axis; the slide along the axis is free, within its limits if it
/// has them. The slide's offset is `b`'s anchor's distance from `a`'s along the axis (m).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct PrismaticJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
    /// The slide axis in `a`'s shape frame (world frame for a world joint); unit length.
    pub axis_a: Vec3,
    /// `b`'s rotation in `a`'s frame to hold: q_b = q_a · this.
    pub relative: Quat,
    /// A motor driving the slide, if any.
    #[serde(default)]
    pub motor: Option<LinearMotor>,
    /// The range of the offset along the axis (m), if limited.
    #[serde(default)]
    pub limits: Option<JointLimits>,
}

impl PrismaticJoint {
    /// Slides `b` on `a` along `axis` (`a`'s shape frame), holding the rotation both have as
    /// spawned unturned relative to each other; anchors at the shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: sides(Some(a), b),
            axis_a: axis.normalize_or_zero(),
            relative: Quat::IDENTITY,
            motor: None,
            limits: None,
        }
    }

    /// Slides `b` along the world axis `axis`, holding `b` unturned; place the rail's world
    /// point with [`Self::with_anchors`].
    #[must_use]
    pub fn to_world(b: Entity, axis: Vec3) -> Self {
        Self {
            bodies: sides(None, b),
            ..Self::new(b, b, axis)
        }
    }

    /// Holds `b` at `relative` to `a` (q_b = q_a · relative) instead of unturned.
    #[must_use]
    pub fn with_relative(mut self, relative: Quat) -> Self {
        self.relative = relative;
        self
    }

    /// Drives the slide towards `target_velocity` (m/s along the axis) with at most
    /// `max_force` (N).
    #[must_use]
    pub fn with_motor(mut self, target_velocity: f32, max_force: f32) -> Self {
        self.motor = Some(LinearMotor {
            target_velocity,
            max_force,
            spring: None,
        });
        self
    }

    /// Drives the slide towards the offset `target` (m) as a spring of `stiffness` (N/m) and
    /// `damping` (N·s/m), with at most `max_force` (N).
    #[must_use]
    pub fn with_position_motor(
        mut self,
        target: f32,
        stiffness: f32,
        damping: f32,
        max_force: f32,
    ) -> Self {
        self.motor = Some(LinearMotor {
            target_velocity: 0.0,
            max_force,
            spring: Some(MotorSpring {
                target,
                stiffness,
                damping,
            }),
        });
        self
    }

    /// Keeps the offset along the axis within `min..=max` (m).
    #[must_use]
    pub fn with_limits(mut self, min: f32, max: f32) -> Self {
        self.limits = Some(JointLimits { min, max });
        self
    }
}
joint_builders!(PrismaticJoint);

impl Describe for PrismaticJoint {
    fn bodies(&self) -> &JointBodies {
        &self.bodies
    }
    fn rows(&self) -> (Angular, Linear, Axial) {
        let axial = Axial {
            axis: Some(Axis::Slide {
                axis_a: self.axis_a,
            }),
            limits: JointLimits::pair(self.limits),
            motor: self.motor.map(|m| {
                (
                    m.target_velocity,
                    m.max_force,
                    MotorSpring::numbers(m.spring),
                )
            }),
            ..Axial::NONE
        };
        let angular = Angular::Weld {
            relative: self.relative,
        };
        (
            angular,
            Linear::Slide {
                axis_a: self.axis_a,
            },
            axial,
        )
    }
}

impl Validate for PrismaticJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        unit("slider axis", self.axis_a)?;
        crate::rigid::Rotation::try_new(self.relative)?;
        if let Some(m) = self.motor {
            validate_motor(m.target_velocity, m.max_force, "motor max force")?;
            if let Some(spring) = m.spring {
                spring.validate(None)?;
            }
        }
        if let Some(l) = self.limits {
            l.validate("slider limits", None)?;
        }
        Ok(())
    }
}

/// A rope or a rod: the anchors stay between `limits.min` and `limits.max` apart (m); every
/// turn is free. Equal limits make a rod, a zero minimum a rope.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(JointImpulse)]
#[component(on_insert = joint_inserted::<Self>, on_discard = joint_discarded::<Self>)]
pub struct DistanceJoint {
    /// The bodies and anchors.
    pub bodies: JointBodies,
    /// The shortest and longest the anchors may stand apart (m, ≥ 0).
    pub limits: JointLimits,
}

impl DistanceJoint {
    /// A rod of `length` (m) from `a`'s anchor to `b`'s; anchors at the shape-frame origins.
    #[must_use]
    pub fn new(a: Entity, b: Entity, length: f32) -> Self {
        Self {
            bodies: sides(Some(a), b),
            limits: JointLimits {
                min: length,
                max: length,
            },
        }
    }

    /// A rod of `length` (m) from a world point (place it with [`Self::with_anchors`]).
    #[must_use]
    pub fn to_world(b: Entity, length: f32) -> Self {
        Self {
            bodies: sides(None, b),
            ..Self::new(b, b, length)
        }
    }

    /// Lets the length range over `min..=max` (m): `with_limits(0.0, l)` is a rope of `l`.
    #[must_use]
    pub fn with_limits(mut self, min: f32, max: f32) -> Self {
        self.limits = JointLimits { min, max };
        self
    }
}
joint_builders!(DistanceJoint);

impl Describe for DistanceJoint {
    fn bodies(&self) -> &JointBodies {
        &self.bodies
    }
    fn rows(&self) -> (Angular, Linear, Axial) {
        let axial = Axial {
            axis: Some(Axis::Length),
            limits: Some((self.limits.min, self.limits.max)),
            ..Axial::NONE
        };
        (Angular::Free, Linear::Free, axial)
    }
}

impl Validate for DistanceJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        self.limits
            .validate("distance limits", Some((0.0, f32::MAX, "0 ≤ length (m)")))
    }
}

/// A weld: `b` keeps its anchor on `a`'s and its rotation relative to `a`.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
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
            bodies: sides(Some(a), b),
            relative,
        }
    }

    /// Welds `b` to the world at rotation `rotation`.
    #[must_use]
    pub fn to_world(b: Entity, rotation: Quat) -> Self {
        Self {
            bodies: sides(None, b),
            relative: rotation,
        }
    }
}
joint_builders!(FixedJoint);

impl Describe for FixedJoint {
    fn bodies(&self) -> &JointBodies {
        &self.bodies
    }
    fn rows(&self) -> (Angular, Linear, Axial) {
        let angular = Angular::Weld {
            relative: self.relative,
        };
        (angular, Linear::Point, Axial::NONE)
    }
}

impl Validate for FixedJoint {
    fn validate(&self) -> Result<()> {
        self.bodies.validate()?;
        crate::rigid::Rotation::try_new(self.relative).map(|_| ())
    }
}

/// The joint kinds a query reads at once.
pub(crate) type Kinds<'a> = AnyOf<(
    &'a SphericalJoint,
    &'a RevoluteJoint,
    &'a FixedJoint,
    &'a PrismaticJoint,
    &'a DistanceJoint,
)>;

/// What a query over [`Kinds`] yields.
pub(crate) type KindsItem<'a> = (
    Option<&'a SphericalJoint>,
    Option<&'a RevoluteJoint>,
    Option<&'a FixedJoint>,
    Option<&'a PrismaticJoint>,
    Option<&'a DistanceJoint>,
);

/// The kind an [`AnyOf`] over [`Kinds`] holds.
pub(super) fn describe(kinds: KindsItem<'_>) -> Option<&'_ dyn Describe> {
    match kinds {
        (Some(j), ..) => Some(j),
        (_, Some(j), ..) => Some(j),
        (_, _, Some(j), ..) => Some(j),
        (_, _, _, Some(j), _) => Some(j),
        (.., Some(j)) => Some(j),
        _ => None,
    }
}

/// The sides of the joint an [`AnyOf`] over [`Kinds`] holds.
pub(crate) fn bodies(kinds: KindsItem<'_>) -> Option<&'_ JointBodies> {
    describe(kinds).map(Describe::bodies)
}
