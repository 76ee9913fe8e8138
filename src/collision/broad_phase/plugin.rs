//! The broad phase's systems: bounding boxes of moving and fixed colliders, then the sweep.

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::collision::ContactFilter;
use crate::collision::broad_phase::{BroadPhase, Entry};
use crate::collision::{Collider, ColliderAabb, CollisionLayers, ContactSettings};
use crate::collision::{radius, shape_pose};
use crate::core::rest::Sleeping;
use crate::core::time::PhysicsTime;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Rotation};

type MovingCollider<'a> = (
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a LinearVelocity,
    Option<&'a AngularVelocity>,
    &'a mut ColliderAabb,
);

/// Boxes of moving colliders, swept over how far they can travel in a step.
pub(crate) fn update_moving_aabbs(
    time: Res<PhysicsTime>,
    settings: Res<ContactSettings>,
    mut colliders: Query<MovingCollider, (ContactFilter, Without<Sleeping>)>,
) {
    let dt = time.dt();
    for (c, x, q, com, v, w, mut aabb) in &mut colliders {
        let b = c.shape().compute_aabb(&shape_pose(x.0, q.0, com));
        let spin = w.map_or(0.0, |w| w.0.length() * radius(c, com));
        // Swept along the velocity, not grown by the speed every way: bodies falling side
        // by side (Box3D's convex pile) would otherwise pair with every neighbour.
        let grow = Vec3::splat(settings.margin + spin * dt);
        let sweep = Vec3::from(v.0) * dt;
        *aabb = ColliderAabb {
            min: b.mins - grow + sweep.min(Vec3::ZERO),
            max: b.maxs + grow + sweep.max(Vec3::ZERO),
        };
    }
}

type Fixed = (Without<LinearVelocity>, ContactFilter);

pub(crate) fn fixed_dirty(bp: Res<BroadPhase>) -> bool {
    bp.fixed_dirty
}

type FixedBox<'a> = (
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a mut ColliderAabb,
);

/// Boxes of fixed colliders: recomputed only after a collider was inserted or removed or a
/// pose was inserted (the hooks set the flag), so idle static geometry costs nothing.
pub(crate) fn update_fixed_aabbs(
    settings: Res<ContactSettings>,
    mut colliders: Query<FixedBox, Fixed>,
) {
    for (c, x, q, com, mut aabb) in &mut colliders {
        let b = c.shape().compute_aabb(&shape_pose(x.0, q.0, com));
        *aabb = ColliderAabb {
            min: b.mins - Vec3::splat(settings.margin),
            max: b.maxs + Vec3::splat(settings.margin),
        };
    }
}

type BroadCollider<'a> = (Entity, &'a ColliderAabb, &'a CollisionLayers, Has<Sleeping>);

fn entry(
    (entity, aabb, layers, sleeping): (Entity, &ColliderAabb, &CollisionLayers, bool),
) -> Entry {
    Entry {
        entity,
        min: aabb.min,
        max: aabb.max,
        awake: !sleeping,
        layers: *layers,
        cell: 0,
    }
}

/// Keeps the broad phase's lists current: moving boxes in place, rebuilding a list only
/// when colliders were added, removed or quarantined.
///
/// The broad phase holds each moving box grown by a tenth of the margin, and keeps it while
/// the collider's box stays inside and no face is twice that far in: a resting body then
/// changes nothing, and when no box changed the last step's pairs still hold and the sweep
/// is skipped. The pairs are those of the grown boxes, a superset of the exact ones that the
/// narrow phase sorts out.
pub(crate) fn run_broad_phase(
    mut bp: ResMut<BroadPhase>,
    settings: Res<ContactSettings>,
    moving: Query<BroadCollider, (With<Collider>, With<LinearVelocity>, ContactFilter)>,
    fixed: Query<BroadCollider, (With<Collider>, Without<LinearVelocity>, ContactFilter)>,
    excluded: Res<crate::collision::PairExclusions>,
) {
    let bp = &mut *bp;
    let fat = Vec3::splat(0.1 * settings.margin.max(0.0));
    let grown = |mut e: Entry| {
        (e.min, e.max) = (e.min - fat, e.max + fat);
        e
    };
    let mut changed = bp.moving_dirty || bp.fixed_dirty || excluded.is_changed();
    if !bp.moving_dirty {
        for e in &mut bp.moving {
            match moving.get(e.entity) {
                Ok(c) => {
                    let now = entry(c);
                    // Inside, and not so far inside that the box was grown for a speed
                    // the body no longer has.
                    let (below, above) = (now.min - e.min, e.max - now.max);
                    let fits = below.cmpge(Vec3::ZERO).all()
                        && above.cmpge(Vec3::ZERO).all()
                        && below.max(above).cmple(2.0 * fat).all();
                    if !(fits && now.awake == e.awake && now.layers == e.layers) {
                        *e = grown(now);
                        changed = true;
                    }
                }
                Err(_) => {
                    bp.moving_dirty = true;
                    changed = true;
                    break;
                }
            }
        }
    }
    if bp.moving_dirty {
        bp.moving.clear();
        bp.moving.extend(moving.iter().map(|c| grown(entry(c))));
    }
    if bp.fixed_dirty {
        bp.fixed.clear();
        bp.fixed.extend(fixed.iter().map(entry));
    }
    if changed {
        bp.find_pairs_except(&excluded);
    }
}
