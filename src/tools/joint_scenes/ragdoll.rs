//! A human ragdoll of capsules and the pile of them the issue asks for.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};

use crate::collision::Collider;
use crate::core::error::Result;
use crate::joints::{RevoluteJoint, SphericalJoint};
use crate::particles::Position;
use crate::rigid::{RigidBody, Rotation};

/// One part of a [`Ragdoll`]: a capsule along y standing upright in the ragdoll's own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RagdollPart {
    /// Its name (`"pelvis"`, `"shin_l"`, ...).
    pub name: &'static str,
    /// Half the length of the capsule's core segment (m).
    pub half_height: f32,
    /// Its radius (m).
    pub radius: f32,
    /// Its centre in the ragdoll's frame, standing (m).
    pub centre: Vec3,
}

/// How a [`RagdollJoint`] turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RagdollTurn {
    /// A ball joint about `axis` (the child's direction from the joint, standing), swinging
    /// at most `swing` (rad) from it and twisting within ±`twist` (rad).
    Ball {
        /// The joint's axis in both parts' frames.
        axis: Vec3,
        /// The cone's half-angle (rad).
        swing: f32,
        /// The twist's half range (rad).
        twist: f32,
    },
    /// A hinge about `axis` (both parts' frames) turning within `min..=max` (rad).
    Hinge {
        /// The hinge axis.
        axis: Vec3,
        /// The smallest angle (rad).
        min: f32,
        /// The largest angle (rad).
        max: f32,
    },
}

/// One joint of a [`Ragdoll`]: the parts it joins (indices into [`Ragdoll::PARTS`]), where
/// it stands in the ragdoll's frame (m) and how it turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RagdollJoint {
    /// The part nearer the pelvis.
    pub parent: usize,
    /// The part it holds.
    pub child: usize,
    /// The joint's place, standing (m).
    pub at: Vec3,
    /// How it turns.
    pub turn: RagdollTurn,
}

/// A human ragdoll of 11 capsules (81 kg at 1000 kg/m³, 1.8 m tall), arms hanging, facing
/// +z: ball joints with cone and twist limits at the spine, neck, shoulders and hips, hinges
/// with limits at the elbows and knees (bending forward and back), every joint with
/// [`Self::FRICTION`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ragdoll;

const fn part(name: &'static str, half_height: f32, radius: f32, c: [f32; 3]) -> RagdollPart {
    RagdollPart {
        name,
        half_height,
        radius,
        centre: Vec3::new(c[0], c[1], c[2]),
    }
}

const fn ball(
    parent: usize,
    child: usize,
    at: [f32; 3],
    up: bool,
    cone: f32,
    twist: f32,
) -> RagdollJoint {
    let axis = if up { Vec3::Y } else { Vec3::NEG_Y };
    RagdollJoint {
        parent,
        child,
        at: Vec3::new(at[0], at[1], at[2]),
        turn: RagdollTurn::Ball {
            axis,
            swing: cone,
            twist,
        },
    }
}

const fn hinge(parent: usize, child: usize, at: [f32; 3], axis: Vec3, max: f32) -> RagdollJoint {
    RagdollJoint {
        parent,
        child,
        at: Vec3::new(at[0], at[1], at[2]),
        turn: RagdollTurn::Hinge {
            axis,
            min: 0.0,
            max,
        },
    }
}

impl Ragdoll {
    /// The parts: pelvis first.
    pub const PARTS: [RagdollPart; 11] = [
        part("pelvis", 0.06, 0.13, [0.0, 1.0, 0.0]),
        part("chest", 0.10, 0.15, [0.0, 1.32, 0.0]),
        part("head", 0.03, 0.11, [0.0, 1.72, 0.0]),
        part("upper_arm_l", 0.11, 0.05, [0.22, 1.30, 0.0]),
        part("forearm_l", 0.11, 0.045, [0.22, 0.98, 0.0]),
        part("upper_arm_r", 0.11, 0.05, [-0.22, 1.30, 0.0]),
        part("forearm_r", 0.11, 0.045, [-0.22, 0.98, 0.0]),
        part("thigh_l", 0.16, 0.07, [0.10, 0.62, 0.0]),
        part("shin_l", 0.16, 0.06, [0.10, 0.22, 0.0]),
        part("thigh_r", 0.16, 0.07, [-0.10, 0.62, 0.0]),
        part("shin_r", 0.16, 0.06, [-0.10, 0.22, 0.0]),
    ];

    /// The joints (angles in rad): spine 25° cone ±15° twist, neck 40° ±40°, shoulders 80°
    /// ±30°, hips 60° ±20°, elbows 0..140° forward, knees 0..140° back.
    pub const JOINTS: [RagdollJoint; 10] = {
        let deg = std::f32::consts::PI / 180.0;
        [
            ball(0, 1, [0.0, 1.16, 0.0], true, 25.0 * deg, 15.0 * deg),
            ball(1, 2, [0.0, 1.58, 0.0], true, 40.0 * deg, 40.0 * deg),
            ball(1, 3, [0.22, 1.46, 0.0], false, 80.0 * deg, 30.0 * deg),
            hinge(3, 4, [0.22, 1.14, 0.0], Vec3::NEG_X, 140.0 * deg),
            ball(1, 5, [-0.22, 1.46, 0.0], false, 80.0 * deg, 30.0 * deg),
            hinge(5, 6, [-0.22, 1.14, 0.0], Vec3::NEG_X, 140.0 * deg),
            ball(0, 7, [0.10, 0.85, 0.0], false, 60.0 * deg, 20.0 * deg),
            hinge(7, 8, [0.10, 0.42, 0.0], Vec3::X, 140.0 * deg),
            ball(0, 9, [-0.10, 0.85, 0.0], false, 60.0 * deg, 20.0 * deg),
            hinge(9, 10, [-0.10, 0.42, 0.0], Vec3::X, 140.0 * deg),
        ]
    };

    /// The joints' friction (N·m): a hinge's motor towards zero spin, a ball joint's
    /// [`SphericalJoint::with_friction`]. Box3D's rain benchmark gives its humans 5 N·m.
    pub const FRICTION: f32 = 5.0;

    /// Spawns a ragdoll into `world`, its frame turned by `turn` and placed at `origin`
    /// (m); returns its parts (in [`Self::PARTS`]' order) and its joints.
    ///
    /// # Errors
    /// None in practice (constructor errors for bad sizes).
    pub fn spawn(
        world: &mut World,
        origin: Vec3,
        turn: Quat,
    ) -> Result<(Vec<Entity>, Vec<Entity>)> {
        let mut parts = Vec::with_capacity(Self::PARTS.len());
        for p in &Self::PARTS {
            let collider = Collider::capsule_y(p.half_height, p.radius)?;
            let x = origin + turn * p.centre;
            parts.push(
                world
                    .spawn((
                        RigidBody::Dynamic,
                        collider,
                        Position(x.into()),
                        Rotation(turn),
                    ))
                    .id(),
            );
        }
        let joints = Self::JOINTS
            .iter()
            .map(|j| {
                let (pa, pb) = (&Self::PARTS[j.parent], &Self::PARTS[j.child]);
                let (a, b) = (parts[j.parent], parts[j.child]);
                let anchors = (j.at - pa.centre, j.at - pb.centre);
                let e = match j.turn {
                    RagdollTurn::Ball { axis, swing, twist } => world.spawn(
                        SphericalJoint::new(a, b)
                            .with_anchors(anchors.0, anchors.1)
                            .with_axis(axis)
                            .with_swing_limit(swing)
                            .with_twist_limits(-twist, twist)
                            .with_friction(Self::FRICTION),
                    ),
                    RagdollTurn::Hinge { axis, min, max } => world.spawn(
                        RevoluteJoint::new(a, b, axis)
                            .with_anchors(anchors.0, anchors.1)
                            .with_limits(min, max)
                            .with_motor(0.0, Self::FRICTION),
                    ),
                };
                e.id()
            })
            .collect();
        Ok((parts, joints))
    }
}

/// [`RagdollPile::ragdolls`] ragdolls lying on their backs, dropped one above another in a
/// loose column (each 0.5 m above the last, turned 72° further about the vertical, shifted
/// along a small spiral) onto the ground: the ragdoll pile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RagdollPile {
    /// How many ragdolls.
    pub ragdolls: usize,
}

impl RagdollPile {
    /// Where ragdoll `k` starts: its frame's origin (m) and turn.
    #[must_use]
    pub fn placement(k: usize) -> (Vec3, Quat) {
        let t = k as f32;
        let yaw = Quat::from_rotation_y(t * 72f32.to_radians());
        let on_back = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
        let spiral = Vec3::new((2.4 * t).cos(), 0.0, (2.4 * t).sin()) * 0.3;
        // Lying on its back, the ragdoll's frame origin (its feet) sits 0.9 m from its centre.
        let centre = spiral + Vec3::new(0.0, 0.4 + 0.5 * t, 0.0);
        let turn = yaw * on_back;
        (centre - turn * Vec3::new(0.0, 0.9, 0.0), turn)
    }

    /// Spawns the ground (a static 40 × 1 × 40 m box, its top at y = 0) and the ragdolls;
    /// returns every part and every joint.
    ///
    /// # Errors
    /// None in practice (constructor errors for bad sizes).
    pub fn spawn(&self, world: &mut World) -> Result<(Vec<Entity>, Vec<Entity>)> {
        world.spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 20.0)?,
            Position(Vec3A::new(0.0, -0.5, 0.0)),
        ));
        let (mut parts, mut joints) = (Vec::new(), Vec::new());
        for k in 0..self.ragdolls {
            let (origin, turn) = Self::placement(k);
            let (p, j) = Ragdoll::spawn(world, origin, turn)?;
            parts.extend(p);
            joints.extend(j);
        }
        Ok((parts, joints))
    }
}
