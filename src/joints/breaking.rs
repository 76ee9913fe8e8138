//! Joints that break: past its [`JointBreakForce`], a joint is taken off its entity and a
//! [`JointBroken`] message says so.

use bevy_ecs::prelude::*;
use glam::Vec3;

use super::{
    DistanceJoint, FixedJoint, JointImpulse, PrismaticJoint, RevoluteJoint, SphericalJoint,
};
use crate::core::error::{Error, Result};
use crate::core::quarantine::{Validate, validate_on_insert};

/// The force and torque past which the joint on this entity breaks (N, N·m; either may be
/// `f32::INFINITY`). Checked after each step against [`JointImpulse::force`] and
/// [`JointImpulse::torque`] of the step's last substep; a joint that breaks loses its joint
/// component (its bodies run free and may collide again), keeps this and its
/// [`JointImpulse`] (zeroed), and is reported once in a [`JointBroken`] message. Insert the joint
/// again to mend it.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct JointBreakForce {
    /// The largest force it holds (N, ≥ 0).
    pub force: f32,
    /// The largest torque it holds (N·m, ≥ 0).
    pub torque: f32,
}

impl JointBreakForce {
    /// Breaks past `force` (N), whatever the torque.
    #[must_use]
    pub fn new(force: f32) -> Self {
        Self {
            force,
            torque: f32::INFINITY,
        }
    }

    /// Breaks past `torque` (N·m) as well.
    #[must_use]
    pub fn with_torque(mut self, torque: f32) -> Self {
        self.torque = torque;
        self
    }
}

impl Validate for JointBreakForce {
    fn validate(&self) -> Result<()> {
        for (what, value) in [
            ("joint break force", self.force),
            ("joint break torque", self.torque),
        ] {
            // Infinity (never breaks) is allowed; NaN fails the comparison.
            if value.is_nan() || value < 0.0 {
                return Err(Error::OutOfRange {
                    what,
                    value,
                    range: "≥ 0 (N or N·m; infinity never breaks)",
                });
            }
        }
        Ok(())
    }
}

/// Written once when a joint breaks. Read it with `World::resource::<Messages<JointBroken>>()`
/// or a `MessageReader`; messages live for two `step_physics` / `advance_physics` calls.
#[derive(Message, Debug, Clone, Copy, PartialEq)]
pub struct JointBroken {
    /// The joint's entity (it keeps its [`JointImpulse`] and [`JointBreakForce`]).
    pub joint: Entity,
    /// The force it carried when it broke (N, world frame, on its second body).
    pub force: Vec3,
    /// The torque it carried when it broke (N·m, world frame).
    pub torque: Vec3,
}

type Kinds = (
    SphericalJoint,
    RevoluteJoint,
    FixedJoint,
    PrismaticJoint,
    DistanceJoint,
);

/// Takes every joint past its threshold off its entity and reports it.
pub(super) fn break_joints(
    mut joints: Query<(Entity, &mut JointImpulse, &JointBreakForce)>,
    mut commands: Commands,
    mut broken: MessageWriter<JointBroken>,
) {
    for (joint, mut impulse, limit) in &mut joints {
        let (force, torque) = (impulse.force(), impulse.torque());
        if force.length() > limit.force || torque.length() > limit.torque {
            commands.entity(joint).remove::<Kinds>();
            // A broken joint exerts nothing (and is not found again past its threshold).
            *impulse = JointImpulse::default();
            broken.write(JointBroken {
                joint,
                force,
                torque,
            });
        }
    }
}
