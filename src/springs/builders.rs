//! Builders for ropes, hair strands and cloth.

use bevy_ecs::prelude::*;
use glam::Vec3;

use super::Spring;
use crate::core::error::{Error, Result, finite_vec, non_negative, positive};
use crate::particles::ParticleBundle;

/// The most nodes a builder makes (2²⁴): far past any rope or cloth a game steps, and small
/// enough that a typo like `usize::MAX` is an error rather than an allocation failure.
pub(crate) const MAX_BUILDER_NODES: usize = 1 << 24;

/// A chain of particle entities joined by springs: a rope, or with bending springs (node i to
/// node i + 2) a hair strand.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainBuilder {
    start: Vec3,
    end: Vec3,
    nodes: usize,
    node_mass: f32,
    stiffness: f32,
    damping: f32,
    bend_stiffness: f32,
    pin_start: bool,
    pin_end: bool,
    rest_scale: f32,
    end_load: f32,
    node_radius: f32,
}

/// The entities of a spawned chain, from the start node to the end node.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chain {
    /// Particle entities, start first.
    pub nodes: Vec<Entity>,
    /// Springs between neighbours: `springs[i]` joins `nodes[i]` and `nodes[i + 1]`.
    pub springs: Vec<Entity>,
    /// Bending springs: `bend_springs[i]` joins `nodes[i]` and `nodes[i + 2]`.
    pub bend_springs: Vec<Entity>,
}

impl ChainBuilder {
    /// A straight rope of `nodes` particles from `start` to `end` (m), pinned at the start,
    /// 0.1 kg per node, k = 150 N/m and c = 0.5 N·s/m per segment.
    ///
    /// **Stability.** Symplectic Euler needs ω_max h < 2 with ω_max ≈ 2√(k/m) for a chain,
    /// i.e. h < √(m/k). The defaults give ω_max h ≈ 1.3 at 60 Hz with one substep; a stiffer
    /// rope needs substeps (see [`crate::core::time::PhysicsTime::new`]).
    ///
    /// **Stretch.** Hanging under its own weight, a chain of N nodes stretches by about
    /// m g N² / (2k): soft springs make long ropes sag far (20 default nodes: +1.2 m). For a
    /// stiff long rope raise k and the substeps together.
    #[must_use]
    pub fn rope(start: Vec3, end: Vec3, nodes: usize) -> Self {
        Self {
            start,
            end,
            nodes,
            node_mass: 0.1,
            stiffness: 150.0,
            damping: 0.5,
            bend_stiffness: 0.0,
            pin_start: true,
            pin_end: false,
            rest_scale: 1.0,
            end_load: 0.0,
            node_radius: 0.0,
        }
    }

    /// A hair strand: a light rope (0.01 kg per node, k = 15 N/m, c = 0.02 N·s/m) with
    /// bending springs (k_bend = 2 N/m) so it keeps its shape against gravity a little.
    /// Stable at 60 Hz with one substep, like [`ChainBuilder::rope`].
    #[must_use]
    pub fn hair(root: Vec3, tip: Vec3, nodes: usize) -> Self {
        Self {
            node_mass: 0.01,
            stiffness: 15.0,
            damping: 0.02,
            bend_stiffness: 2.0,
            ..Self::rope(root, tip, nodes)
        }
    }

    /// Mass of each free node (kg).
    #[must_use]
    pub fn node_mass(mut self, kg: f32) -> Self {
        self.node_mass = kg;
        self
    }

    /// Segment stiffness k (N/m).
    #[must_use]
    pub fn stiffness(mut self, k: f32) -> Self {
        self.stiffness = k;
        self
    }

    /// Segment damping c (N·s/m).
    #[must_use]
    pub fn damping(mut self, c: f32) -> Self {
        self.damping = c;
        self
    }

    /// Bending stiffness (N/m) of the springs that skip one node; 0 for none.
    #[must_use]
    pub fn bending(mut self, k: f32) -> Self {
        self.bend_stiffness = k;
        self
    }

    /// Whether the start node is pinned.
    #[must_use]
    pub fn pin_start(mut self, pin: bool) -> Self {
        self.pin_start = pin;
        self
    }

    /// Whether the end node is pinned too (a rope strung between two points).
    #[must_use]
    pub fn pin_end(mut self, pin: bool) -> Self {
        self.pin_end = pin;
        self
    }

    /// Each segment's rest length over its built length (dimensionless, default 1): above 1
    /// the rope is built with slack (a rope of rest length `scale` × the span), below 1 it is
    /// pre-tensioned (tension k (1 − scale) × segment length when both ends are pinned).
    #[must_use]
    pub fn rest_scale(mut self, scale: f32) -> Self {
        self.rest_scale = scale;
        self
    }

    /// Gives every node a ball collider of `radius` (m; default 0, none), so the rope
    /// collides with the world's colliders (and with itself where it folds). Below half the
    /// node spacing, so neighbours do not touch at rest.
    #[must_use]
    pub fn node_radius(mut self, radius: f32) -> Self {
        self.node_radius = radius;
        self
    }

    /// A load (kg) hung on the end node, added to its mass (0 for none).
    #[must_use]
    pub fn end_load(mut self, kg: f32) -> Self {
        self.end_load = kg;
        self
    }

    /// Spawns the particles and springs.
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 nodes, and the errors of the particle and spring
    /// constructors for bad values. Nothing is spawned on error.
    pub fn spawn(&self, world: &mut World) -> Result<Chain> {
        self.spawn_into(world)
    }

    /// As [`ChainBuilder::spawn`], from a system's `Commands` (the entities exist once the
    /// commands are applied; their ids are known at once).
    ///
    /// # Errors
    /// As [`ChainBuilder::spawn`]; nothing is spawned on an error.
    pub fn spawn_with(&self, commands: &mut Commands) -> Result<Chain> {
        self.spawn_into(commands)
    }

    fn spawn_into(&self, world: &mut impl Spawn) -> Result<Chain> {
        if self.nodes < 2 {
            return Err(Error::TooFew {
                what: "chain nodes",
                min: 2,
                got: self.nodes,
            });
        }
        if self.nodes > MAX_BUILDER_NODES {
            return Err(Error::OutOfRange {
                what: "chain node count",
                value: self.nodes as f32,
                range: "at most 2^24",
            });
        }
        let start = finite_vec("chain start", self.start)?;
        let end = finite_vec("chain end", self.end)?;
        let k = non_negative("spring stiffness", self.stiffness)?;
        let c = non_negative("spring damping", self.damping)?;
        let kb = non_negative("bending stiffness", self.bend_stiffness)?;
        let scale = positive("rest length scale", self.rest_scale)?;
        let load = non_negative("end load", self.end_load)?;
        let step = (end - start) / (self.nodes - 1) as f32;
        let mut bundles = Vec::with_capacity(self.nodes);
        for i in 0..self.nodes {
            let x = start + step * i as f32;
            let last = i + 1 == self.nodes;
            bundles.push(if (i == 0 && self.pin_start) || (last && self.pin_end) {
                ParticleBundle::pinned(x)?
            } else if last {
                ParticleBundle::new(x, Vec3::ZERO, self.node_mass + load)?
            } else {
                ParticleBundle::new(x, Vec3::ZERO, self.node_mass)?
            });
        }
        let radius = non_negative("chain node radius", self.node_radius)?;
        if radius > 0.0 && 2.0 * radius >= step.length() {
            return Err(Error::OutOfRange {
                what: "chain node radius",
                value: radius,
                range: "below half the node spacing",
            });
        }
        let nodes: Vec<Entity> = if radius > 0.0 {
            let ball = crate::collision::Collider::ball(radius)?;
            bundles
                .into_iter()
                .map(|b| world.spawn_one((b, ball.clone())))
                .collect()
        } else {
            bundles.into_iter().map(|b| world.spawn_one(b)).collect()
        };
        let seg = step.length() * scale;
        let mut chain = Chain {
            nodes,
            ..Default::default()
        };
        for w in chain.nodes.windows(2) {
            let s = Spring::new(w[0], w[1], seg, k, c)?;
            chain.springs.push(world.spawn_one(s));
        }
        if kb > 0.0 {
            for w in chain.nodes.windows(3) {
                let s = Spring::new(w[0], w[2], 2.0 * seg, kb, 0.0)?;
                chain.bend_springs.push(world.spawn_one(s));
            }
        }
        Ok(chain)
    }
}

/// Where a builder spawns: a `World` directly, or a system's `Commands`.
trait Spawn {
    fn spawn_one<B: Bundle>(&mut self, bundle: B) -> Entity;
}

impl Spawn for World {
    fn spawn_one<B: Bundle>(&mut self, bundle: B) -> Entity {
        self.spawn(bundle).id()
    }
}

impl Spawn for Commands<'_, '_> {
    fn spawn_one<B: Bundle>(&mut self, bundle: B) -> Entity {
        self.spawn(bundle).id()
    }
}
