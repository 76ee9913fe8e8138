//! Soft-body nodes against colliders: point projection with a thickness and Coulomb
//! friction, after the positions are integrated.
//!
//! A node closer than [`SoftBody::contact_thickness`] to a collider's surface (or inside it)
//! is moved out along the surface normal n to that distance; its velocity loses its
//! approaching normal part Δvₙ, and its tangential part is reduced by μ Δvₙ (Coulomb's cone,
//! μ the collider's [`crate::Friction`]), stopping it when the cone holds. Colliders are
//! treated as immovable (static and kinematic ones behave right; a dynamic rigid body does not
//! yet feel the nodes: one-way coupling). Soft–soft contact is not handled.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};
use parry3d::math::Pose;

use super::SoftBody;
use crate::collision::{Collider, ColliderAabb, ColliderOf, Friction};
use crate::particles::{Nodes, Position};
use crate::quarantine::Quarantined;
use crate::rigid::{CenterOfMass, Rotation};

type ColliderPose<'a> = (
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a ColliderAabb,
    &'a Friction,
);

/// Projects every soft body's nodes out of the colliders they touch.
pub(crate) fn collide_nodes(
    mut bodies: Query<(&mut Nodes, &mut SoftBody), Without<Quarantined>>,
    colliders: Query<ColliderPose, (Without<Quarantined>, Without<ColliderOf>)>,
) {
    for (mut nodes, mut body) in &mut bodies {
        let body = body.bypass_change_detection();
        body.contacts.clear();
        let thickness = body.contact_thickness;
        let n = nodes.bypass_change_detection();
        let Some((lo, hi)) = bounds(&n.x) else {
            continue;
        };
        let (lo, hi) = (lo - Vec3::splat(thickness), hi + Vec3::splat(thickness));
        for (c, x, q, com, aabb, friction) in &colliders {
            if aabb.min.cmpgt(hi).any() || aabb.max.cmplt(lo).any() {
                continue;
            }
            let pose = crate::collision::shape_pose(x.0, q.0, com);
            push_out(
                n,
                &mut body.contacts,
                c,
                &pose,
                q.0,
                (aabb, thickness, friction.0),
            );
        }
    }
}

fn bounds(x: &[Vec3A]) -> Option<(Vec3, Vec3)> {
    let first = Vec3::from(*x.first()?);
    Some(x.iter().fold((first, first), |(lo, hi), p| {
        (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p)))
    }))
}

fn push_out(
    n: &mut Nodes,
    contacts: &mut Vec<super::NodeContact>,
    collider: &Collider,
    pose: &Pose,
    rotation: Quat,
    (aabb, thickness, mu): (&ColliderAabb, f32, f32),
) {
    let shape = collider.shape();
    let inverse = pose.inverse();
    for i in 0..n.x.len() {
        if n.inv_mass[i] == 0.0 {
            continue;
        }
        let p = Vec3::from(n.x[i]);
        if (p + Vec3::splat(thickness)).cmplt(aabb.min).any()
            || (p - Vec3::splat(thickness)).cmpgt(aabb.max).any()
        {
            continue;
        }
        let local = inverse * p;
        let solid = shape.project_local_point(local, true);
        let (normal_local, depth) = if solid.is_inside {
            // Inside: the solid projection is the point itself; the surface is the way out.
            let out = shape.project_local_point(local, false).point - local;
            let d = out.length();
            if d == 0.0 {
                continue;
            }
            (out / d, -d)
        } else {
            let off = local - solid.point;
            let d = off.length();
            if d >= thickness || d == 0.0 {
                continue;
            }
            (off / d, d)
        };
        let normal = rotation * normal_local;
        n.x[i] += Vec3A::from(normal * (thickness - depth));
        contacts.push(super::NodeContact {
            node: i as u32,
            normal,
            offset: normal.dot(Vec3::from(n.x[i])),
        });
        let v = Vec3::from(n.v[i]);
        let vn = v.dot(normal);
        if vn < 0.0 {
            let tangent = v - vn * normal;
            let speed = tangent.length();
            let slowed = if speed > 0.0 {
                tangent * ((speed + mu * vn).max(0.0) / speed)
            } else {
                tangent
            };
            n.v[i] = Vec3A::from(slowed);
        }
    }
}
