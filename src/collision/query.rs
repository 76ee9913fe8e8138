//! Spatial queries against the colliders: ray casts, shape casts, point projection and
//! overlaps, as a `SystemParam`.
//!
//! Each query tests the colliders' bounding boxes ([`super::ColliderAabb`], as of the last
//! step) before the exact parry test, and walks every collider: O(n) per query. Queries
//! return the nearest hit by distance, ties broken by entity, so results are deterministic.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{Ray, ShapeCastOptions};

use super::{Collider, ColliderAabb, CollisionLayers, Sensor};
use crate::core::quarantine::Quarantined;
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// Which colliders a query sees.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct QueryFilter {
    /// Only colliders whose memberships meet this mask.
    pub mask: u32,
    /// Whether sensors count.
    pub include_sensors: bool,
    /// Colliders to skip (the caster itself, say).
    pub exclude: Vec<Entity>,
}

impl Default for QueryFilter {
    fn default() -> Self {
        Self {
            mask: u32::MAX,
            include_sensors: false,
            exclude: Vec::new(),
        }
    }
}

impl QueryFilter {
    /// Only colliders on `layers` (a [`super::LayerMask`], a `u32`, or
    /// `LayerMask::from_layers([MyLayer::Enemy])?`).
    #[must_use]
    pub fn with_mask(mut self, layers: impl Into<super::LayerMask>) -> Self {
        self.mask = layers.into().0;
        self
    }

    /// The default filter, also skipping `entity`.
    #[must_use]
    pub fn excluding(entity: Entity) -> Self {
        Self {
            exclude: vec![entity],
            ..Default::default()
        }
    }
}

/// A ray or shape cast hit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct Hit {
    /// The collider hit.
    pub entity: Entity,
    /// Distance along the direction (m; the direction is normalised).
    pub distance: f32,
    /// World point of impact (m).
    pub point: Vec3,
    /// World surface normal of the hit collider at the point.
    pub normal: Vec3,
}

/// A collider near a shape ([`SpatialQuery::shape_contacts`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeContact {
    /// The collider.
    pub entity: Entity,
    /// The collider's point nearest the shape (m, world).
    pub point: Vec3,
    /// World normal out of the collider, towards the shape.
    pub normal: Vec3,
    /// Signed distance between the two (m; negative when they overlap).
    pub distance: f32,
}

/// The closest collider point to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// The collider.
    pub entity: Entity,
    /// Closest point on it (m).
    pub point: Vec3,
    /// Whether the query point is inside it.
    pub inside: bool,
    /// Distance from the query point (m; 0 inside a solid).
    pub distance: f32,
}

type QueryCollider<'a> = (
    Entity,
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a CollisionLayers,
    &'a ColliderAabb,
    Has<Sensor>,
);

/// Spatial queries over every live collider. Use it as a system parameter, or from a
/// `World` through `SystemState<SpatialQuery>`.
#[derive(SystemParam)]
pub struct SpatialQuery<'w, 's> {
    colliders:
        Query<'w, 's, QueryCollider<'static>, (Without<Quarantined>, Without<super::ColliderOf>)>,
}

fn pose(x: &Position, q: &Rotation, com: Option<&CenterOfMass>) -> Pose {
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    Pose::from_parts(Vec3::from(x.0) - q.0 * c, q.0)
}

/// Slab test of a ray against a box: the entry distance, if it enters within `max`.
fn ray_aabb(origin: Vec3, inv_dir: Vec3, aabb: &ColliderAabb, max: f32) -> Option<f32> {
    let t1 = (aabb.min - origin) * inv_dir;
    let t2 = (aabb.max - origin) * inv_dir;
    let near = t1.min(t2).max_element().max(0.0);
    let far = t1.max(t2).min_element().min(max);
    (near <= far).then_some(near)
}

fn nearer(best: &mut Option<Hit>, hit: Hit) {
    let better = match best {
        None => true,
        Some(b) => {
            hit.distance < b.distance || (hit.distance == b.distance && hit.entity < b.entity)
        }
    };
    if better {
        *best = Some(hit);
    }
}

/// A candidate collider: entity, shape, pose parts, layers, bounding box, sensor flag.
type Candidate<'a> = (
    Entity,
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a CollisionLayers,
    ColliderAabb,
    bool,
);

/// The collider's box as of the last step, or, for one spawned since (whose box is still
/// the default empty one at the origin), its box now.
fn bounds(
    aabb: &ColliderAabb,
    c: &Collider,
    x: &Position,
    q: &Rotation,
    com: Option<&CenterOfMass>,
) -> ColliderAabb {
    if aabb.min != aabb.max {
        return *aabb;
    }
    let b = c.shape().compute_aabb(&pose(x, q, com));
    ColliderAabb {
        min: b.mins,
        max: b.maxs,
    }
}

impl SpatialQuery<'_, '_> {
    fn candidates<'a>(
        &'a self,
        filter: &'a QueryFilter,
    ) -> impl Iterator<Item = Candidate<'a>> + 'a {
        self.candidates_where(filter, &|_| true)
    }

    /// The colliders `filter` lets through and `predicate` accepts.
    fn candidates_where<'a>(
        &'a self,
        filter: &'a QueryFilter,
        predicate: &'a dyn Fn(Entity) -> bool,
    ) -> impl Iterator<Item = Candidate<'a>> + 'a {
        self.colliders
            .iter()
            .filter(move |c| {
                c.5.memberships & filter.mask != 0
                    && (filter.include_sensors || !c.7)
                    && !filter.exclude.contains(&c.0)
                    && predicate(c.0)
            })
            .map(|(e, c, x, q, com, layers, aabb, sensor)| {
                (e, c, x, q, com, layers, bounds(aabb, c, x, q, com), sensor)
            })
    }

    /// Every collider a ray from `origin` along `direction` hits within `max_distance` (m)
    /// and `predicate` accepts, nearest first (ties by entity), at most `max_hits`: one hit
    /// per collider, where the ray enters it (distance 0 for a ray starting inside).
    #[must_use]
    pub fn ray_hits(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        max_hits: usize,
        filter: &QueryFilter,
        predicate: &dyn Fn(Entity) -> bool,
    ) -> Vec<Hit> {
        let Some(dir) = direction.try_normalize() else {
            return Vec::new();
        };
        if !(origin.is_finite() && max_distance >= 0.0) {
            return Vec::new();
        }
        let ray = Ray::new(origin, dir);
        let inv = dir.recip();
        let mut hits: Vec<Hit> = self
            .candidates_where(filter, predicate)
            .filter(|(.., aabb, _)| ray_aabb(origin, inv, aabb, max_distance).is_some())
            .filter_map(|(e, c, x, q, com, ..)| {
                let i = c.shape().cast_ray_and_get_normal(
                    &pose(x, q, com),
                    &ray,
                    max_distance,
                    true,
                )?;
                Some(Hit {
                    entity: e,
                    distance: i.time_of_impact,
                    point: origin + dir * i.time_of_impact,
                    normal: i.normal,
                })
            })
            .collect();
        sort_and_cap(&mut hits, max_hits);
        hits
    }

    /// The first collider `predicate` accepts along the ray ([`Self::cast_ray`] with a
    /// predicate: skip one-way platforms, the player's own parts, ...).
    #[must_use]
    pub fn cast_ray_predicate(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
        predicate: &dyn Fn(Entity) -> bool,
    ) -> Option<Hit> {
        self.ray_hits(origin, direction, max_distance, 1, filter, predicate)
            .into_iter()
            .next()
    }

    /// Every collider that `shape`, placed at (`position`, `rotation`) and swept along
    /// `direction`, touches within `max_distance` (m) and `predicate` accepts, nearest first
    /// (ties by entity), at most `max_hits`.
    #[must_use]
    #[allow(clippy::too_many_arguments)]
    pub fn shape_hits(
        &self,
        shape: &Collider,
        (position, rotation): (Vec3, Quat),
        direction: Vec3,
        max_distance: f32,
        max_hits: usize,
        filter: &QueryFilter,
        predicate: &dyn Fn(Entity) -> bool,
    ) -> Vec<Hit> {
        let options = ShapeCastOptions::with_max_time_of_impact(max_distance);
        self.sweep(
            shape,
            (position, rotation),
            direction,
            options,
            max_hits,
            filter,
            predicate,
        )
    }

    /// The first collider that `shape`, moved from (`position`, `rotation`) along
    /// `direction`, would come within `gap` (m) of within `max_distance` (m): the distance of
    /// the hit is how far the shape can move and stay `gap` away. Colliders it already
    /// overlaps or is nearer than `gap` to count only if the move closes in on them, so a
    /// shape resting on the ground can slide along it or lift off (what a character
    /// controller needs; see [`crate::character`]).
    #[must_use]
    #[allow(clippy::too_many_arguments)]
    pub fn cast_shape_with_gap(
        &self,
        shape: &Collider,
        (position, rotation): (Vec3, Quat),
        direction: Vec3,
        max_distance: f32,
        gap: f32,
        filter: &QueryFilter,
        predicate: &dyn Fn(Entity) -> bool,
    ) -> Option<Hit> {
        if !(gap >= 0.0 && gap.is_finite()) {
            return None;
        }
        let options = ShapeCastOptions {
            max_time_of_impact: max_distance,
            target_distance: gap,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        };
        self.sweep(
            shape,
            (position, rotation),
            direction,
            options,
            1,
            filter,
            predicate,
        )
        .into_iter()
        .next()
    }

    /// The shared body of the shape casts.
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &self,
        shape: &Collider,
        (position, rotation): (Vec3, Quat),
        direction: Vec3,
        options: ShapeCastOptions,
        max_hits: usize,
        filter: &QueryFilter,
        predicate: &dyn Fn(Entity) -> bool,
    ) -> Vec<Hit> {
        let max_distance = options.max_time_of_impact;
        let Some(dir) = direction.try_normalize() else {
            return Vec::new();
        };
        let Some(rotation) = unit_rotation(rotation) else {
            return Vec::new();
        };
        if !(position.is_finite() && max_distance >= 0.0 && max_distance.is_finite()) {
            return Vec::new();
        }
        let start = Pose::from_parts(position, rotation);
        let mut swept = shape.shape().compute_swept_aabb(
            &start,
            &Pose::from_parts(position + dir * max_distance, rotation),
        );
        swept.mins -= Vec3::splat(options.target_distance);
        swept.maxs += Vec3::splat(options.target_distance);
        let mut hits: Vec<Hit> = self
            .candidates_where(filter, predicate)
            .filter(|(.., aabb, _)| !misses(&swept, aabb))
            .filter_map(|(e, c, x, q, com, ..)| {
                let target = pose(x, q, com);
                let h = guarded(|| {
                    parry3d::query::cast_shapes(
                        &start,
                        dir,
                        &**shape.shape(),
                        &target,
                        Vec3::ZERO,
                        &**c.shape(),
                        options,
                    )
                })?
                .ok()??;
                Some(Hit {
                    entity: e,
                    distance: h.time_of_impact,
                    point: target * h.witness2,
                    normal: target.rotation * h.normal2,
                })
            })
            .collect();
        sort_and_cap(&mut hits, max_hits);
        hits
    }

    /// Every collider within `prediction` (m) of `shape` at (`position`, `rotation`), with
    /// the signed distance and the normal pointing out of the collider towards the shape,
    /// sorted by entity. A negative distance is a penetration depth.
    #[must_use]
    pub fn shape_contacts(
        &self,
        shape: &Collider,
        (position, rotation): (Vec3, Quat),
        prediction: f32,
        filter: &QueryFilter,
    ) -> Vec<ShapeContact> {
        let Some((at, bounds)) = placed(shape, position, rotation, prediction) else {
            return Vec::new();
        };
        let mut out: Vec<ShapeContact> = self
            .candidates(filter)
            .filter(|(.., aabb, _)| !misses(&bounds, aabb))
            .filter_map(|(e, c, x, q, com, ..)| {
                let target = pose(x, q, com);
                let contact = guarded(|| {
                    parry3d::query::contact(
                        &at,
                        &**shape.shape(),
                        &target,
                        &**c.shape(),
                        prediction,
                    )
                })?
                .ok()??;
                Some(ShapeContact {
                    entity: e,
                    point: contact.point2,
                    normal: contact.normal2,
                    distance: contact.dist,
                })
            })
            .collect();
        out.sort_unstable_by_key(|c| c.entity);
        out
    }

    /// Every collider containing `point` (on its surface counts), sorted.
    #[must_use]
    pub fn colliders_at_point(&self, point: Vec3, filter: &QueryFilter) -> Vec<Entity> {
        if !point.is_finite() {
            return Vec::new();
        }
        let mut out: Vec<Entity> = self
            .candidates(filter)
            .filter(|(.., aabb, _)| point.cmpge(aabb.min).all() && point.cmple(aabb.max).all())
            .filter(|(_, c, x, q, com, ..)| {
                parry3d::query::PointQuery::contains_point(&**c.shape(), &pose(x, q, *com), point)
            })
            .map(|c| c.0)
            .collect();
        out.sort_unstable();
        out
    }

    /// The first collider a ray from `origin` along `direction` hits within `max_distance`
    /// (m). A ray starting inside a solid collider hits it at distance 0.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<Hit> {
        let dir = direction.try_normalize()?;
        if !(origin.is_finite() && max_distance >= 0.0) {
            return None;
        }
        let ray = Ray::new(origin, dir);
        let inv = dir.recip();
        let mut best = None;
        for (e, c, x, q, com, _, aabb, _) in self.candidates(filter) {
            let Some(enter) = ray_aabb(origin, inv, &aabb, max_distance) else {
                continue;
            };
            if best.is_some_and(|b: Hit| enter > b.distance) {
                continue;
            }
            if let Some(i) =
                c.shape()
                    .cast_ray_and_get_normal(&pose(x, q, com), &ray, max_distance, true)
            {
                nearer(
                    &mut best,
                    Hit {
                        entity: e,
                        distance: i.time_of_impact,
                        point: origin + dir * i.time_of_impact,
                        normal: i.normal,
                    },
                );
            }
        }
        best
    }

    /// The first collider that `shape`, placed at (`position`, `rotation`) and swept along
    /// `direction`, touches within `max_distance` (m).
    #[must_use]
    pub fn cast_shape(
        &self,
        shape: &Collider,
        position: Vec3,
        rotation: Quat,
        direction: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<Hit> {
        self.shape_hits(
            shape,
            (position, rotation),
            direction,
            max_distance,
            1,
            filter,
            &|_| true,
        )
        .into_iter()
        .next()
    }

    /// The collider nearest to `point` and its closest point, searching within
    /// `max_distance` (m).
    #[must_use]
    pub fn project_point(
        &self,
        point: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<Projection> {
        if !(point.is_finite() && max_distance >= 0.0) {
            return None;
        }
        let mut best: Option<Projection> = None;
        for (e, c, x, q, com, _, aabb, _) in self.candidates(filter) {
            let gap = (aabb.min - point)
                .max(point - aabb.max)
                .max(Vec3::ZERO)
                .length();
            if gap > max_distance || best.is_some_and(|b| gap > b.distance) {
                continue;
            }
            let p = parry3d::query::PointQuery::project_point(
                &**c.shape(),
                &pose(x, q, com),
                point,
                true,
            );
            let distance = if p.is_inside {
                0.0
            } else {
                (p.point - point).length()
            };
            if distance <= max_distance
                && best.is_none_or(|b| {
                    distance < b.distance || (distance == b.distance && e < b.entity)
                })
            {
                best = Some(Projection {
                    entity: e,
                    point: p.point,
                    inside: p.is_inside,
                    distance,
                });
            }
        }
        best
    }

    /// Every collider that overlaps `shape` at (`position`, `rotation`), sorted.
    #[must_use]
    pub fn overlaps(
        &self,
        shape: &Collider,
        position: Vec3,
        rotation: Quat,
        filter: &QueryFilter,
    ) -> Vec<Entity> {
        let Some((at, bounds)) = placed(shape, position, rotation, 0.0) else {
            return Vec::new();
        };
        let mut out: Vec<Entity> = self
            .candidates(filter)
            .filter(|(.., aabb, _)| !misses(&bounds, aabb))
            .filter(|(_, c, x, q, com, ..)| {
                guarded(|| {
                    parry3d::query::intersection_test(
                        &at,
                        &**shape.shape(),
                        &pose(x, q, *com),
                        &**c.shape(),
                    )
                })
                .is_some_and(|i| i.is_ok_and(|i| i.intersecting))
            })
            .map(|c| c.0)
            .collect();
        out.sort_unstable();
        out
    }
}

/// `shape` placed at (`position`, `rotation`) and its bounding box grown by `grow` (m);
/// none for a non-finite position or grow, or a bad rotation.
fn placed(
    shape: &Collider,
    position: Vec3,
    rotation: Quat,
    grow: f32,
) -> Option<(Pose, parry3d::bounding_volume::Aabb)> {
    let rotation = unit_rotation(rotation)?;
    if !(position.is_finite() && grow >= 0.0 && grow.is_finite()) {
        return None;
    }
    let at = Pose::from_parts(position, rotation);
    let mut bounds = shape.shape().compute_aabb(&at);
    bounds.mins -= Vec3::splat(grow);
    bounds.maxs += Vec3::splat(grow);
    Some((at, bounds))
}

/// Whether a query's box and a collider's box are apart.
fn misses(bounds: &parry3d::bounding_volume::Aabb, aabb: &ColliderAabb) -> bool {
    bounds.maxs.cmplt(aabb.min).any() || bounds.mins.cmpgt(aabb.max).any()
}

/// Orders hits nearest first, ties by entity, and keeps the first `max_hits`.
fn sort_and_cap(hits: &mut Vec<Hit>, max_hits: usize) {
    hits.sort_unstable_by(|a, b| {
        a.distance
            .total_cmp(&b.distance)
            .then(a.entity.cmp(&b.entity))
    });
    hits.truncate(max_hits);
}

/// `q` as a unit quaternion; none for a zero or non-finite one (whose "normalised" form is
/// NaN and made every query answer with NaN hits).
fn unit_rotation(q: Quat) -> Option<Quat> {
    crate::rigid::Rotation::try_new(q).ok().map(|r| r.0)
}

/// Runs a parry query, with a panic inside parry (seen on shapes at the edge of its domain)
/// answered as no result instead of unwinding into the caller's system.
fn guarded<T>(f: impl FnOnce() -> T) -> Option<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok()
}
