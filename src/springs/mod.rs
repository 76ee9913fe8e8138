//! Damped springs: ropes, hair and cloth.
//!
//! The lecture's force on endpoint p of a spring (p, q) with rest length r:
//!
//! ```text
//! f_p = [ k_s (|x_q − x_p| / r − 1) + k_d ((v_q − v_p)·(x_q − x_p)) / (r |x_q − x_p|) ] d̂,   f_q = −f_p
//! ```
//!
//! with d̂ = (x_q − x_p)/|x_q − x_p|. Here k_s is a force per unit strain (N) and k_d a force per
//! unit strain rate (N·s). Dividing by r gives the Hooke form that hooke stores and that also
//! works for zero-length springs:
//!
//! ```text
//! f_p = [ k (l − r) + c (v_q − v_p)·d̂ ] d̂,   k = k_s / r (N/m),   c = k_d / r (N·s/m)
//! ```
//!
//! [`Spring::new`] takes the lecture's (k_s, k_d); [`Spring::new`] takes (k, c) and
//! allows r = 0. When the endpoints coincide the direction is undefined and the force is
//! zero (for r = 0 that is also the limit). The potential energy is ½ k (l − r)².
//!
//! **Anchors.** [`Spring::with_anchors`] attaches the ends at points a given relative to the
//! centre of mass in body axes. The force acts along the line between the world anchors
//! p = x + R a, using the anchor velocity v + ω × r (r = R a) for damping, and a rigid
//! endpoint also feels the torque r × f.
//!
//! Two representations share [`spring_force`]:
//! - [`Spring`], one entity per spring between two body entities: flexible, for ropes,
//!   hair and gameplay tethers.
//! - [`SpringNetwork`] with [`crate::particles::Nodes`] on one entity: arrays of springs over arrays of
//!   nodes, for cloth and anything with thousands of springs. It streams through memory
//!   instead of looking entities up.

mod builders;
mod entity_implicit;
mod implicit;
mod local;
mod plugin;
pub mod stability;

pub(crate) use builders::MAX_BUILDER_NODES;
pub use builders::{Chain, ChainBuilder};
pub(crate) use entity_implicit::EntitySpringFactor;
pub use plugin::SpringPlugin;
pub(crate) use plugin::{Spinning, anchor_state};
pub use stability::{EntitySpringStability, SpringStability};

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Vec3, Vec3A};

use crate::core::error::{Error, Result, finite_vec, non_negative, positive};
use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::particles::{Nodes, Position};

/// The damped spring force on endpoint a (N); the force on b is its negative.
///
/// `rest` in m, `k` in N/m, `c` in N·s/m (the Hooke form; see the module docs for the
/// lecture's strain form). Returns zero when the endpoints coincide.
#[must_use]
#[inline]
pub fn spring_force(
    xa: Vec3A,
    xb: Vec3A,
    va: Vec3A,
    vb: Vec3A,
    rest: f32,
    k: f32,
    c: f32,
) -> Vec3A {
    let d = xb - xa;
    let l2 = d.length_squared();
    // NaN compares as not greater, so a broken endpoint yields no force rather than NaN.
    if l2.partial_cmp(&1e-30) != Some(core::cmp::Ordering::Greater) {
        return Vec3A::ZERO;
    }
    let l = l2.sqrt();
    let dir = d / l;
    (k * (l - rest) + c * (vb - va).dot(dir)) * dir
}

/// Potential energy ½ k (l − r)² of a spring (J), in f64 so that a large finite stretch
/// of a stiff spring does not overflow.
#[must_use]
#[inline]
pub fn spring_energy(xa: Vec3A, xb: Vec3A, rest: f32, k: f32) -> f64 {
    let s = (xb.as_dvec3() - xa.as_dvec3()).length() - f64::from(rest);
    0.5 * f64::from(k) * s * s
}

/// A spring entity between bodies `a` and `b` (entities with a [`Position`]).
///
/// Build it with [`Spring::new`] or [`Spring::new`] and spawn it like any component.
/// If an endpoint is despawned, the spring is despawned at the next step.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_spring)]
pub struct Spring {
    a: Entity,
    b: Entity,
    rest_length: f32,
    stiffness: f32,
    damping: f32,
    anchor_a: Vec3,
    anchor_b: Vec3,
}

impl Spring {
    /// The two endpoints, for a snapshot to map onto its restored entities.
    pub(crate) fn ends_mut(&mut self) -> [&mut Entity; 2] {
        [&mut self.a, &mut self.b]
    }

    /// A spring of rest length `r` (m, ≥ 0), stiffness `k` (N/m) and damping `c` (N·s/m):
    /// force k (l − r) + c l̇ along the line between its ends.
    ///
    /// # Errors
    /// [`Error::SelfSpring`], [`Error::Negative`] or [`Error::NonFinite`].
    pub fn new(a: Entity, b: Entity, r: f32, k: f32, c: f32) -> Result<Self> {
        if a == b {
            return Err(Error::SelfSpring(a));
        }
        Ok(Self {
            a,
            b,
            rest_length: non_negative("rest length", r)?,
            stiffness: non_negative("spring stiffness", k)?,
            damping: non_negative("spring damping", c)?,
            anchor_a: Vec3::ZERO,
            anchor_b: Vec3::ZERO,
        })
    }

    /// The lecture's spring in strain form: rest length `r` (m, > 0), `ks` (N per unit
    /// strain) and `kd` (N·s per unit strain rate), that is k = ks / r and c = kd / r.
    ///
    /// # Errors
    /// [`Error::SelfSpring`], [`Error::NotPositive`] for r ≤ 0, [`Error::Negative`] or
    /// [`Error::NonFinite`] for bad coefficients.
    pub fn from_strain(a: Entity, b: Entity, r: f32, ks: f32, kd: f32) -> Result<Self> {
        let r = positive("rest length", r)?;
        let ks = non_negative("spring stiffness", ks)?;
        let kd = non_negative("spring damping", kd)?;
        Self::new(a, b, r, ks / r, kd / r)
    }

    /// Attaches the ends at points of the bodies (m, relative to each body's centre of mass
    /// in its body axes; for a particle, a fixed world offset). On a rigid body an anchor away
    /// from the centre of mass makes the spring exert a torque r × f. For a point given in
    /// the shape's frame, subtract the [`crate::rigid::CenterOfMass`].
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn with_anchors(mut self, anchor_a: Vec3, anchor_b: Vec3) -> Result<Self> {
        self.anchor_a = finite_vec("spring anchor", anchor_a)?;
        self.anchor_b = finite_vec("spring anchor", anchor_b)?;
        Ok(self)
    }

    /// Anchors (body frame) of the two ends.
    #[must_use]
    pub fn anchors(&self) -> (Vec3, Vec3) {
        (self.anchor_a, self.anchor_b)
    }

    /// The spring's current length, strain and tension, from its ends' positions in
    /// `world` (anchors included); None if an end has no `Position`.
    #[must_use]
    pub fn reading(&self, world: &World) -> Option<SpringReading> {
        let end = |e: Entity, anchor: Vec3| -> Option<Vec3A> {
            let x = world.get::<Position>(e)?.0;
            let r = world
                .get::<crate::rigid::Rotation>(e)
                .map_or(Vec3A::from(anchor), |q| q.0 * Vec3A::from(anchor));
            Some(x + r)
        };
        let (a, b) = (end(self.a, self.anchor_a)?, end(self.b, self.anchor_b)?);
        Some(SpringReading::new(
            (b - a).length(),
            self.rest_length,
            self.stiffness,
        ))
    }

    /// Spawns this spring after checking that both endpoints are bodies.
    ///
    /// # Errors
    /// [`Error::MissingEntity`] if an endpoint does not exist or has no [`Position`].
    pub fn spawn(self, world: &mut World) -> Result<Entity> {
        for e in [self.a, self.b] {
            if world.get::<Position>(e).is_none() {
                return Err(Error::MissingEntity(e));
            }
        }
        Ok(world.spawn(self).id())
    }

    /// First endpoint.
    #[must_use]
    pub fn a(&self) -> Entity {
        self.a
    }
    /// Second endpoint.
    #[must_use]
    pub fn b(&self) -> Entity {
        self.b
    }
    /// Rest length r (m).
    #[must_use]
    pub fn rest_length(&self) -> f32 {
        self.rest_length
    }
    /// Stiffness k (N/m).
    #[must_use]
    pub fn stiffness(&self) -> f32 {
        self.stiffness
    }
    /// Damping c (N·s/m).
    #[must_use]
    pub fn damping(&self) -> f32 {
        self.damping
    }

    fn check(&self) -> Result<()> {
        Self::new(
            self.a,
            self.b,
            self.rest_length,
            self.stiffness,
            self.damping,
        )
        .map(|_| ())
    }
}

fn validate_spring(mut world: DeferredWorld, ctx: HookContext) {
    if world.contains_resource::<crate::core::restore::Restoring>() {
        return;
    }
    let Some(spring) = world.get::<Spring>(ctx.entity).copied() else {
        return;
    };
    if let Err(err) = spring.check().and_then(|()| ends_exist(&world, &spring)) {
        world.commands().entity(ctx.entity).insert(Quarantined {
            reason: QuarantineReason::InvalidInput(err),
        });
    }
}

/// Both ends of `spring` are bodies (they have a [`Position`]).
pub(crate) fn ends_exist(world: &World, spring: &Spring) -> Result<(), Error> {
    match [spring.a, spring.b]
        .into_iter()
        .find(|&e| world.get::<Position>(e).is_none())
    {
        Some(e) => Err(Error::MissingEntity(e)),
        None => Ok(()),
    }
}

/// A spring's state: its length (m), strain (l − r)/r (dimensionless; infinite for a
/// stretched zero-length spring) and tension k (l − r) (N; negative when compressed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringReading {
    /// Current length (m).
    pub length: f32,
    /// (l − r) / r.
    pub strain: f32,
    /// k (l − r) (N).
    pub tension: f32,
}

impl SpringReading {
    fn new(length: f32, rest: f32, k: f32) -> Self {
        let s = length - rest;
        Self {
            length,
            strain: if rest > 0.0 {
                s / rest
            } else if s == 0.0 {
                0.0
            } else {
                f32::INFINITY
            },
            tension: k * s,
        }
    }
}

/// Springs between the [`Nodes`] of the same entity, as parallel arrays (Hooke form).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(SpringStability)]
pub struct SpringNetwork {
    pub(crate) ends: Vec<[u32; 2]>,
    pub(crate) rest: Vec<f32>,
    pub(crate) k: Vec<f32>,
    pub(crate) c: Vec<f32>,
    /// Largest node index used, so one comparison per step proves every index in range.
    pub(crate) max_index: u32,
    /// The largest stiffness (N/m): springs under a tenth of it stay out of the implicit
    /// solve's factor (see `ImplicitElements::in_factor`).
    pub(crate) max_k: f32,
}

impl SpringNetwork {
    /// Whether the arrays agree and `max_index` is the largest endpoint (see
    /// [`Nodes::consistent`]).
    pub(crate) fn consistent(&self) -> bool {
        let n = self.ends.len();
        let max = self.ends.iter().flatten().copied().max().unwrap_or(0);
        [self.rest.len(), self.k.len(), self.c.len()]
            .iter()
            .all(|&l| l == n)
            && (n == 0 || max == self.max_index)
    }

    /// No springs.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a spring between nodes `a` and `b` (Hooke form: r in m, k in N/m, c in N·s/m).
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] when `a == b` or an index exceeds `u32`,
    /// [`Error::Negative`] or [`Error::NonFinite`] for bad coefficients.
    pub fn push(&mut self, a: usize, b: usize, r: f32, k: f32, c: f32) -> Result<usize> {
        if a == b {
            return Err(Error::IndexOutOfRange {
                what: "second spring endpoint (equal to the first)",
                index: b,
                len: a,
            });
        }
        let (ia, ib) = match (u32::try_from(a), u32::try_from(b)) {
            (Ok(ia), Ok(ib)) => (ia, ib),
            _ => {
                return Err(Error::IndexOutOfRange {
                    what: "spring endpoint",
                    index: a.max(b),
                    len: u32::MAX as usize,
                });
            }
        };
        let (r, k, c) = (
            non_negative("rest length", r)?,
            non_negative("spring stiffness", k)?,
            non_negative("spring damping", c)?,
        );
        self.ends.push([ia, ib]);
        self.rest.push(r);
        self.k.push(k);
        self.c.push(c);
        self.max_index = self.max_index.max(ia).max(ib);
        self.max_k = self.max_k.max(k);
        Ok(self.ends.len() - 1)
    }

    /// Number of springs.
    #[must_use]
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// True when there are no springs.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Node index pairs.
    #[must_use]
    pub fn ends(&self) -> &[[u32; 2]] {
        &self.ends
    }

    /// Spring `i`'s length, strain and tension over `nodes`; None when `i` or its ends are
    /// out of range.
    #[must_use]
    pub fn reading(&self, i: usize, nodes: &Nodes) -> Option<SpringReading> {
        let [a, b] = *self.ends.get(i)?;
        let x = nodes.positions();
        let (pa, pb) = (x.get(a as usize)?, x.get(b as usize)?);
        Some(SpringReading::new(
            (*pb - *pa).length(),
            self.rest[i],
            self.k[i],
        ))
    }

    /// True when every endpoint indexes into `nodes`.
    #[must_use]
    pub fn fits(&self, nodes: &Nodes) -> bool {
        self.is_empty() || (self.max_index as usize) < nodes.len()
    }

    /// Potential energy of all springs over `nodes` (J).
    #[must_use]
    pub fn energy(&self, nodes: &Nodes) -> f64 {
        if !self.fits(nodes) {
            return 0.0;
        }
        let x = nodes.positions();
        (0..self.len())
            .map(|i| {
                let [a, b] = self.ends[i];
                spring_energy(x[a as usize], x[b as usize], self.rest[i], self.k[i])
            })
            .sum()
    }

    /// Why a mesh whose springs index past its nodes leaves the step, if they do.
    pub(crate) fn misfit(&self, nodes: &Nodes) -> Option<QuarantineReason> {
        (!self.fits(nodes)).then(|| {
            QuarantineReason::InvalidInput(Error::IndexOutOfRange {
                what: "spring network endpoint",
                index: self.max_index as usize,
                len: nodes.len(),
            })
        })
    }

    /// Adds every spring force into `nodes`' accumulators. Returns false (and does nothing)
    /// when an index is out of range.
    pub fn accumulate(&self, nodes: &mut Nodes) -> bool {
        if !self.fits(nodes) {
            return false;
        }
        let Nodes { x, v, f, .. } = nodes;
        for (i, &[a, b]) in self.ends.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let fa = spring_force(x[a], x[b], v[a], v[b], self.rest[i], self.k[i], self.c[i]);
            f[a] += fa;
            f[b] -= fa;
        }
        true
    }
}
