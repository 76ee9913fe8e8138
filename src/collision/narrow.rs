//! Narrow phase: persistent contact manifolds per pair, and the contact query API.

use bevy_platform::collections::HashMap;

use bevy_ecs::prelude::*;
use glam::Vec3;
use parry3d::query::{ContactManifold, ContactManifoldsWorkspace};

/// What each contact point carries from step to step: the accumulated impulses, for warm
/// starting. parry moves it to the matching point of the next step's manifold.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactImpulse {
    /// Normal impulse (N·s).
    pub normal: f32,
    /// Friction impulse (N·s, world frame).
    pub tangent: Vec3,
}

pub(crate) type Manifold = ContactManifold<(), ContactImpulse>;

/// One pair's state.
pub(crate) struct PairState {
    pub manifolds: Vec<Manifold>,
    pub workspace: Option<ContactManifoldsWorkspace>,
    pub touching: bool,
    pub sensor: bool,
    pub seen: u64,
}

impl PairState {
    pub fn new() -> Self {
        Self {
            manifolds: Vec::new(),
            workspace: None,
            touching: false,
            sensor: false,
            seen: 0,
        }
    }
}

/// Every pair of colliders whose boxes overlap, with their contact manifolds. A resource:
/// read it after a step to see what touches what.
#[derive(Resource, Default)]
pub struct Contacts {
    pub(crate) pairs: HashMap<(Entity, Entity), PairState>,
    pub(crate) step: u64,
}

/// A touching pair, as reported by [`Contacts`].
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    /// The lower entity.
    pub a: Entity,
    /// The higher entity.
    pub b: Entity,
    /// Contact points on `a`'s surface (m): in `a`'s shape frame from [`Contacts::pair`],
    /// in the world from [`Contacts::pair_in_world`].
    pub points: Vec<Vec3>,

    /// Normal from `a` to `b` of the deepest manifold.
    pub normal: Vec3,
    /// Deepest penetration (m, positive when overlapping).
    pub depth: f32,
    /// Total normal impulse of the last step (N·s): the contact force times dt.
    pub normal_impulse: f32,
    /// Whether one of the two is a sensor (no impulses then).
    pub sensor: bool,
}

fn key(a: Entity, b: Entity) -> (Entity, Entity) {
    if a < b { (a, b) } else { (b, a) }
}

impl Contacts {
    /// Pairs that touch now, sorted.
    #[must_use]
    pub fn touching(&self) -> Vec<(Entity, Entity)> {
        let mut v: Vec<_> = self
            .pairs
            .iter()
            .filter(|(_, s)| s.touching)
            .map(|(k, _)| *k)
            .collect();
        v.sort_unstable();
        v
    }

    /// True when `a` and `b` touch.
    #[must_use]
    pub fn are_touching(&self, a: Entity, b: Entity) -> bool {
        self.pairs.get(&key(a, b)).is_some_and(|s| s.touching)
    }

    /// Everything about the contact between `a` and `b`, if they touch. Points are given
    /// in the frame of the lower entity's shape, so pass world poses through
    /// [`Contacts::pair_in_world`] when positions matter.
    #[must_use]
    pub fn pair(&self, a: Entity, b: Entity) -> Option<ContactPair> {
        let (ka, kb) = key(a, b);
        let s = self.pairs.get(&(ka, kb)).filter(|s| s.touching)?;
        let mut out = ContactPair {
            a: ka,
            b: kb,
            points: Vec::new(),
            normal: Vec3::ZERO,
            depth: 0.0,
            normal_impulse: 0.0,
            sensor: s.sensor,
        };
        for m in &s.manifolds {
            for p in &m.points {
                out.points.push(p.local_p1);
                if -p.dist > out.depth || out.normal == Vec3::ZERO {
                    out.depth = out.depth.max(-p.dist);
                    out.normal = m.local_n1;
                }
                out.normal_impulse += p.data.normal;
            }
        }
        Some(out)
    }

    /// [`Contacts::pair`] with points and normal turned into world coordinates, given the
    /// lower entity's shape pose.
    #[must_use]
    pub fn pair_in_world(
        &self,
        a: Entity,
        b: Entity,
        pose_of_lower: parry3d::math::Pose,
    ) -> Option<ContactPair> {
        let mut p = self.pair(a, b)?;
        for x in &mut p.points {
            *x = pose_of_lower * *x;
        }
        p.normal = pose_of_lower.rotation * p.normal;
        Some(p)
    }

    /// Pairs whose boxes overlap (touching or not).
    #[must_use]
    pub fn pairs_len(&self) -> usize {
        self.pairs.len()
    }

    /// Manifolds and contact points (touching or speculative) over all pairs.
    #[must_use]
    pub fn manifold_stats(&self) -> (usize, usize) {
        let m = self.pairs.values().map(|s| s.manifolds.len()).sum();
        let p = self
            .pairs
            .values()
            .flat_map(|s| &s.manifolds)
            .map(|m| m.points.len())
            .sum();
        (m, p)
    }

    /// Number of touching pairs.
    #[must_use]
    pub fn touching_count(&self) -> usize {
        self.pairs.values().filter(|s| s.touching).count()
    }
}
