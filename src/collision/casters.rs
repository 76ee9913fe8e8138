//! Ray and shape casters: components whose hits hooke finds again at the end of every step
//! (ground checks, line of sight, a car's wheel rays), read like any component.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use super::Collider;
use super::query::{Hit, QueryFilter, SpatialQuery};
use crate::particles::Position;
use crate::rigid::Rotation;

/// Casts a ray from this entity at the end of every step; its hits are in [`RayHits`].
///
/// On an entity with a [`Position`] (a body) the origin is taken from its centre of mass
/// and both origin and direction turn with its [`Rotation`]; on any other entity they are
/// world coordinates. The entity itself is never hit.
#[derive(Component, Debug, Clone, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(RayHits)]
pub struct RayCaster {
    /// Where the ray starts (m; body frame from the centre of mass, or world).
    pub origin: Vec3,
    /// Its direction (normalised when cast; a zero direction hits nothing).
    pub direction: Vec3,
    /// How far it reaches (m).
    pub max_distance: f32,
    /// The most hits kept, nearest first (1: only the first thing in the way).
    pub max_hits: usize,
    /// Which colliders it sees.
    pub filter: QueryFilter,
}

impl RayCaster {
    /// A ray from `origin` along `direction`, as far as `max_distance` (m), keeping the
    /// nearest hit.
    #[must_use]
    pub fn new(origin: Vec3, direction: Vec3, max_distance: f32) -> Self {
        Self {
            origin,
            direction,
            max_distance,
            max_hits: 1,
            filter: QueryFilter::default(),
        }
    }

    /// Keeps up to `max_hits` hits.
    #[must_use]
    pub fn with_max_hits(mut self, max_hits: usize) -> Self {
        self.max_hits = max_hits;
        self
    }

    /// Sees only what `filter` lets through.
    #[must_use]
    pub fn with_filter(mut self, filter: QueryFilter) -> Self {
        self.filter = filter;
        self
    }
}

/// The hits of this entity's [`RayCaster`] as of the last step, nearest first (ties by
/// entity).
#[derive(Component, Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct RayHits(pub Vec<Hit>);

/// Sweeps a shape from this entity at the end of every step; its hits are in [`ShapeHits`].
/// Placed like a [`RayCaster`]'s ray; `rotation` turns the shape in the same frame.
#[derive(Component, Clone)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(ShapeHits)]
pub struct ShapeCaster {
    /// The swept shape.
    pub shape: Collider,
    /// Where it starts (m).
    pub origin: Vec3,
    /// Its orientation.
    pub rotation: Quat,
    /// The sweep's direction.
    pub direction: Vec3,
    /// How far it sweeps (m).
    pub max_distance: f32,
    /// The most hits kept, nearest first.
    pub max_hits: usize,
    /// Which colliders it sees.
    pub filter: QueryFilter,
}

impl ShapeCaster {
    /// `shape` swept from `origin` along `direction` as far as `max_distance` (m), keeping
    /// the nearest hit.
    #[must_use]
    pub fn new(shape: Collider, origin: Vec3, direction: Vec3, max_distance: f32) -> Self {
        Self {
            shape,
            origin,
            rotation: Quat::IDENTITY,
            direction,
            max_distance,
            max_hits: 1,
            filter: QueryFilter::default(),
        }
    }
}

/// The hits of this entity's [`ShapeCaster`] as of the last step, nearest first.
#[derive(Component, Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct ShapeHits(pub Vec<Hit>);

/// The world pose of a caster's start on an entity with or without a body pose.
fn placed(x: Option<&Position>, q: Option<&Rotation>, origin: Vec3) -> (Vec3, Quat) {
    let q = q.map_or(Quat::IDENTITY, |q| q.0);
    match x {
        Some(x) => (x.get() + q * origin, q),
        None => (origin, Quat::IDENTITY),
    }
}

type Caster<'a, C, H> = (
    Entity,
    &'a C,
    Option<&'a Position>,
    Option<&'a Rotation>,
    &'a mut H,
);

/// Casts every [`RayCaster`]'s ray and stores its hits.
pub(crate) fn update_ray_hits(
    spatial: SpatialQuery,
    mut casters: Query<Caster<RayCaster, RayHits>>,
) {
    for (e, caster, x, q, mut hits) in &mut casters {
        let (origin, turn) = placed(x, q, caster.origin);
        let not_self = |other: Entity| other != e;
        let found = spatial.ray_hits(
            origin,
            turn * caster.direction,
            caster.max_distance,
            caster.max_hits,
            &caster.filter,
            &not_self,
        );
        if hits.0 != found {
            hits.0 = found;
        }
    }
}

/// Sweeps every [`ShapeCaster`]'s shape and stores its hits.
pub(crate) fn update_shape_hits(
    spatial: SpatialQuery,
    mut casters: Query<Caster<ShapeCaster, ShapeHits>>,
) {
    for (e, caster, x, q, mut hits) in &mut casters {
        let (origin, turn) = placed(x, q, caster.origin);
        let not_self = |other: Entity| other != e;
        let found = spatial.shape_hits(
            &caster.shape,
            (origin, turn * caster.rotation),
            turn * caster.direction,
            caster.max_distance,
            caster.max_hits,
            &caster.filter,
            &not_self,
        );
        if hits.0 != found {
            hits.0 = found;
        }
    }
}
