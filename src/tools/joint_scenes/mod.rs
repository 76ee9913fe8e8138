//! Jointed scenes shared by the tests, `perf_report` and the rapier comparison: each a spec
//! of plain numbers (sizes, places, anchors) that hooke and rapier build alike.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::collision::Collider;
use crate::core::error::Result;
use crate::joints::SphericalJoint;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::RigidBody;

mod bridge;
mod door;
mod ragdoll;
mod vehicle;

pub use bridge::{ChainBridge, ChainBridgeParts};
pub use door::{HingedDoor, HingedDoorParts};
pub use ragdoll::{Ragdoll, RagdollJoint, RagdollPart, RagdollPile, RagdollTurn};
pub use vehicle::{FourWheeler, FourWheelerParts};

/// A chain of `links` boxes of 0.1 × 0.2 × 0.1 m (2 kg at 1000 kg/m³) on ball joints,
/// hanging from the world point (0, 25, 0), an 8 kg box of 0.2 m at its end kicked sideways
/// at [`HangingChain::KICK`]: the "100-link chain hanging a heavy load".
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HangingChain {
    /// Links above the load.
    pub links: usize,
}

/// One body of a jointed scene: its box's half extents and its centre (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointedBody {
    /// Half extents (m).
    pub half: Vec3,
    /// Centre (m).
    pub position: Vec3,
}

/// One ball joint of a jointed scene: the body above (`None`: the world), the body below,
/// and the anchors on each (m, in each body's frame; a world point for the world).
pub type BallJointSpec = (Option<usize>, usize, Vec3, Vec3);

impl HangingChain {
    /// The load's velocity at the start (m/s).
    pub const KICK: Vec3 = Vec3::new(3.0, 0.0, 0.0);
    /// Where the chain hangs from (m).
    pub const TOP: Vec3 = Vec3::new(0.0, 25.0, 0.0);
    const LINK: Vec3 = Vec3::new(0.05, 0.1, 0.05);
    const LOAD: Vec3 = Vec3::new(0.1, 0.1, 0.1);

    /// The links from the top, then the load.
    #[must_use]
    pub fn bodies(&self) -> Vec<JointedBody> {
        (0..=self.links)
            .map(|k| {
                let half = if k == self.links {
                    Self::LOAD
                } else {
                    Self::LINK
                };
                let y = Self::TOP.y - 2.0 * Self::LINK.y * k as f32 - half.y;
                JointedBody {
                    half,
                    position: Vec3::new(0.0, y, 0.0),
                }
            })
            .collect()
    }

    /// The joints from the top: each body hung from the one above (the first from the world).
    #[must_use]
    pub fn joints(&self) -> Vec<BallJointSpec> {
        self.bodies()
            .iter()
            .enumerate()
            .map(|(k, body)| {
                let below = Vec3::new(0.0, body.half.y, 0.0);
                if k == 0 {
                    (None, 0, Self::TOP, below)
                } else {
                    (Some(k - 1), k, Vec3::new(0.0, -Self::LINK.y, 0.0), below)
                }
            })
            .collect()
    }

    /// Spawns the chain into `world` (dynamic boxes of 1000 kg/m³, the load kicked); returns
    /// the bodies from the top and the joint entities.
    ///
    /// # Errors
    /// None in practice (constructor errors for bad sizes).
    pub fn build(&self, world: &mut World) -> Result<(Vec<Entity>, Vec<Entity>)> {
        let mut bodies = Vec::new();
        for b in self.bodies() {
            let collider = Collider::cuboid(b.half.x, b.half.y, b.half.z)?;
            let e = world.spawn((RigidBody::Dynamic, collider, Position(b.position.into())));
            bodies.push(e.id());
        }
        if let Some(&load) = bodies.last() {
            world
                .entity_mut(load)
                .insert(LinearVelocity(Vec3A::from(Self::KICK)));
        }
        let joints = self
            .joints()
            .into_iter()
            .map(|(a, b, anchor_a, anchor_b)| {
                let joint = match a {
                    None => SphericalJoint::to_world(bodies[b]),
                    Some(a) => SphericalJoint::new(bodies[a], bodies[b]),
                };
                world.spawn(joint.with_anchors(anchor_a, anchor_b)).id()
            })
            .collect();
        Ok((bodies, joints))
    }
}
