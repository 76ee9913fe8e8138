//! A plank bridge on hinges, spawned in its equilibrium, and a crate pushed across it.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::collision::{Collider, ColliderDensity, Friction};
use crate::core::error::Result;
use crate::joints::RevoluteJoint;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::{ExternalForceAtPoint, RigidBody, Rotation};
use parry3d::shape::SharedShape;

/// A bridge of [`ChainBridge::planks`] wooden planks (0.5 × 0.06 × 1.2 m at 600 kg/m³, so
/// 21.6 kg) hinged end to end about z, its ends hinged to two static abutments whose
/// hinges stand [`ChainBridge::span`] apart at y = 0, and a crate of 0.8 × 0.4 × 0.6 m
/// (300 kg/m³, 57.6 kg, friction 0.3) waiting on the left abutment.
///
/// The planks are spawned in the bridge's equilibrium, the discrete catenary: with the
/// horizontal tension H the same in every hinge and the vertical force growing by one
/// plank's weight W from hinge to hinge, a plank's moments balance when its slope is
/// tan φ_k = (W / H)(k + ½ − n/2); H is the one that makes the planks span the gap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainBridge {
    /// How many planks.
    pub planks: usize,
    /// The distance between the end hinges (m); less than the planks' length, so the bridge
    /// sags.
    pub span: f32,
}

/// What [`ChainBridge::spawn`] made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChainBridgeParts {
    /// The planks from left to right.
    pub planks: Vec<Entity>,
    /// The hinges from left to right: the left abutment's, the planks', the right one's.
    pub hinges: Vec<Entity>,
    /// The crate.
    pub crate_box: Entity,
    /// The left and right abutments.
    pub abutments: [Entity; 2],
}

impl Default for ChainBridge {
    /// 20 planks (10 m) across 9.9 m: about 0.6 m of sag.
    fn default() -> Self {
        Self {
            planks: 20,
            span: 9.9,
        }
    }
}

impl ChainBridge {
    /// A plank's half extents (m).
    pub const PLANK: Vec3 = Vec3::new(0.25, 0.03, 0.6);
    /// The planks' density (kg/m³).
    pub const PLANK_DENSITY: f32 = 600.0;
    /// The crate's half extents (m): a low crate, twice as long as it is tall.
    pub const CRATE: Vec3 = Vec3::new(0.4, 0.2, 0.3);
    /// The rounding of the crate's edges (m): a sharp edge sunk the contacts' few
    /// millimetres into a plank catches on the end face of the next one where two planks
    /// meet at an angle (the contact takes the face with the least overlap).
    pub const CRATE_ROUNDING: f32 = 0.04;
    /// The crate's density (kg/m³).
    pub const CRATE_DENSITY: f32 = 300.0;
    /// An abutment's half extents (m): its top level with the planks' tops, its inner face
    /// 2 cm short of the end hinge, so a plank turning down about it clears it.
    pub const ABUTMENT: Vec3 = Vec3::new(1.5, 0.5, 1.0);

    /// A plank's mass (kg).
    #[must_use]
    pub fn plank_mass() -> f32 {
        8.0 * Self::PLANK.x * Self::PLANK.y * Self::PLANK.z * Self::PLANK_DENSITY
    }

    /// The crate's mass (kg).
    #[must_use]
    pub fn crate_mass() -> f32 {
        8.0 * Self::CRATE.x * Self::CRATE.y * Self::CRATE.z * Self::CRATE_DENSITY
    }

    /// The slope ratio W / H of the equilibrium (dimensionless): the one whose plank slopes
    /// span the gap, found by bisection.
    #[must_use]
    pub fn slope_ratio(&self) -> f32 {
        let length = 2.0 * Self::PLANK.x;
        let n = self.planks as f64;
        let across = |c: f64| -> f64 {
            (0..self.planks)
                .map(|k| {
                    let tan = c * (k as f64 + 0.5 - 0.5 * n);
                    length as f64 / (1.0 + tan * tan).sqrt()
                })
                .sum()
        };
        let (mut lo, mut hi) = (0.0_f64, 10.0_f64);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if across(mid) > self.span as f64 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (0.5 * (lo + hi)) as f32
    }

    /// The hinges' places in the equilibrium (m, x and y; z = 0), from left to right.
    #[must_use]
    pub fn hinge_points(&self) -> Vec<Vec3> {
        let c = self.slope_ratio();
        let n = self.planks as f32;
        let length = 2.0 * Self::PLANK.x;
        let mut p = Vec3::new(-0.5 * self.span, 0.0, 0.0);
        let mut points = vec![p];
        for k in 0..self.planks {
            let phi = (c * (k as f32 + 0.5 - 0.5 * n)).atan();
            p += length * Vec3::new(phi.cos(), phi.sin(), 0.0);
            points.push(p);
        }
        points
    }

    /// The equilibrium's force on each end hinge (N): the horizontal tension H and the
    /// vertical load n W / 2 it carries.
    #[must_use]
    pub fn end_force(&self) -> (f32, f32) {
        let w = Self::plank_mass() * 9.81;
        (w / self.slope_ratio(), 0.5 * self.planks as f32 * w)
    }

    /// The equilibrium's sag: how far below the end hinges the lowest hinge hangs (m).
    #[must_use]
    pub fn sag(&self) -> f32 {
        -self
            .hinge_points()
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min)
    }

    /// Where the crate starts (its centre, m): on the left abutment, 1 m short of the gap.
    #[must_use]
    pub fn crate_start(&self) -> Vec3 {
        Vec3::new(-0.5 * self.span - 1.0, Self::PLANK.y + Self::CRATE.y, 0.0)
    }

    /// Spawns the abutments, the planks in equilibrium, their hinges and the crate.
    ///
    /// # Errors
    /// A span too wide for the planks, or constructor errors for bad sizes.
    pub fn spawn(&self, world: &mut World) -> Result<ChainBridgeParts> {
        let length = 2.0 * Self::PLANK.x * self.planks as f32;
        if self.planks == 0 || !(self.span > 0.0 && self.span < length) {
            return Err(crate::Error::OutOfRange {
                what: "bridge span",
                value: self.span,
                range: "(0, the planks' length), with at least one plank",
            });
        }
        let a = Self::ABUTMENT;
        let abutment = |world: &mut World, side: f32| -> Result<Entity> {
            let centre = Vec3::new(
                side * (0.5 * self.span + 0.02 + a.x),
                Self::PLANK.y - a.y,
                0.0,
            );
            Ok(world
                .spawn((
                    RigidBody::Static,
                    Collider::cuboid(a.x, a.y, a.z)?,
                    Position(centre.into()),
                ))
                .id())
        };
        let abutments = [abutment(world, -1.0)?, abutment(world, 1.0)?];
        let points = self.hinge_points();
        let mut planks = Vec::with_capacity(self.planks);
        for pair in points.windows(2) {
            let d = pair[1] - pair[0];
            let p = Self::PLANK;
            planks.push(
                world
                    .spawn((
                        RigidBody::Dynamic,
                        Collider::cuboid(p.x, p.y, p.z)?,
                        ColliderDensity(Self::PLANK_DENSITY),
                        Position((0.5 * (pair[0] + pair[1])).into()),
                        Rotation(Quat::from_rotation_z(d.y.atan2(d.x))),
                    ))
                    .id(),
            );
        }
        let end = Vec3::new(Self::PLANK.x, 0.0, 0.0);
        let centre = |e: Entity, world: &World| -> Vec3 {
            world.get::<Position>(e).map_or(Vec3::ZERO, |p| p.0.into())
        };
        let mut hinges = Vec::with_capacity(self.planks + 1);
        let left = points[0] - centre(abutments[0], world);
        hinges.push(
            world
                .spawn(
                    RevoluteJoint::new(abutments[0], planks[0], Vec3::Z).with_anchors(left, -end),
                )
                .id(),
        );
        for pair in planks.windows(2) {
            hinges.push(
                world
                    .spawn(RevoluteJoint::new(pair[0], pair[1], Vec3::Z).with_anchors(end, -end))
                    .id(),
            );
        }
        let right = points[self.planks] - centre(abutments[1], world);
        hinges.push(
            world
                .spawn(
                    RevoluteJoint::new(planks[self.planks - 1], abutments[1], Vec3::Z)
                        .with_anchors(end, right),
                )
                .id(),
        );
        let c = Self::CRATE;
        let crate_box = world
            .spawn((
                RigidBody::Dynamic,
                Collider::new(SharedShape::round_cuboid(
                    c.x - Self::CRATE_ROUNDING,
                    c.y - Self::CRATE_ROUNDING,
                    c.z - Self::CRATE_ROUNDING,
                    Self::CRATE_ROUNDING,
                ))?,
                ColliderDensity(Self::CRATE_DENSITY),
                Friction(0.3),
                Position(self.crate_start().into()),
                Self::push_at(0.0),
            ))
            .id();
        Ok(ChainBridgeParts {
            planks,
            hinges,
            crate_box,
            abutments,
        })
    }

    /// A push of `force` (N) along x a quarter of the crate's height above its base (where
    /// a player's hands would be on a low crate: pushed at its centre, at 0.8 of its weight
    /// down a slope of 15°, it tips).
    #[must_use]
    pub fn push_at(force: f32) -> ExternalForceAtPoint {
        ExternalForceAtPoint {
            force: Vec3::new(force, 0.0, 0.0),
            point: Vec3::new(0.0, -0.5 * Self::CRATE.y, 0.0),
            local: true,
        }
    }

    /// The push that walks the crate across at `speed` (m/s along x): [`Self::push_at`]
    /// 20/s × (speed − v_x) × its mass, at most 0.8 of its weight either way, as a player
    /// pushing it would. Call it before each step.
    pub fn push(world: &mut World, crate_box: Entity, speed: f32) {
        let m = Self::crate_mass();
        let Some(v) = world.get::<LinearVelocity>(crate_box).map(|v| v.0.x) else {
            return;
        };
        let most = 0.8 * m * 9.81;
        let f = (20.0 * (speed - v) * m).clamp(-most, most);
        if let Some(mut push) = world.get_mut::<ExternalForceAtPoint>(crate_box) {
            *push = Self::push_at(f);
        }
    }
}
