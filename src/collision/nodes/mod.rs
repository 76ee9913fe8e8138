//! Mesh nodes (soft bodies, cloth) against colliders: point projection with a thickness and
//! Coulomb friction, after the positions are integrated. Each effect whose meshes collide
//! implements [`NodeLayer`] for its component and registers [`collide_nodes`] for it.
//!
//! A node closer than the layer's thickness (e.g. [`crate::soft::SoftBody::contact_thickness`])
//! to a collider's surface (or inside it)
//! is moved out along the surface normal n to that distance; its velocity loses its
//! approaching normal part Δvₙ, and its tangential part is reduced by μ Δvₙ (Coulomb's cone,
//! μ the collider's [`crate::collision::Friction`]), stopping it when the cone holds.
//!
//! **Deep overlaps come out at a bounded speed.** A node is moved out by at most what its
//! approach brought it in this substep plus [`crate::collision::ContactSettings::max_push_velocity`]
//! × h, as rigid bodies are: a mesh spawned deep inside a collider (a jelly inside a 236 m
//! cylinder) walks out whole at that speed instead of every node jumping to its nearest
//! surface in one substep, which flattened it and threw it out at kilometres per second.
//!
//! Against a kinematic collider the same holds relative to its surface's velocity. Under
//! [`crate::integrator::ImplicitEuler`] each such contact is also a plane the next solve holds the node
//! to (moving with the surface).
//!
//! **Two-way with dynamic bodies.** The nodes in a dynamic body's contact layer are pushed out
//! by normal impulses λ ≥ 0 found together: the overlaps C (m, negative inside the layer)
//! must close, G λ ≥ −C / h, with G the coupled response of both sides (see
//! [`crate::collision::nodes::coupling`]: the soft body answers through its implicit solve's factor, so a stiff
//! body moves as a whole; a light body is pushed back by the heavy soft one). Projected
//! Gauss–Seidel on that small system, then Coulomb friction per node capped at μ λ; the body
//! takes −λ at each node. No plane holds a node to a dynamic body inside the solve: such a
//! wall would not give, and a light body loaded with a heavy soft one's weight one substep
//! late bounces off. The body takes its impulses at the start of the next substep
//! ([`NodeImpulse`]), before its own integrator and rigid contacts.
//!
//! **Known limit.** The rigid contacts are solved before the soft ones, not with them. A soft
//! body resting on a light dynamic body that itself rests on others (a 27 kg jelly on a 10 kg
//! crate on the ground) sees the crate tilt by about 1e-3 rad and rock, and creeps sideways:
//! about 2 cm in its first second at rest, faster after. Solving node contacts inside the
//! rigid contact solver would remove it. The same drop integrated explicitly (E = 2e5, 16
//! substeps, lumped masses) peaks at 4.6 m/s at landing against the fall's 2.4 m/s.
//! Soft–soft contact is not handled.

pub(crate) mod coupling;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};
use parry3d::math::Pose;

use crate::collision::nodes::coupling::{NodeImpulse, RigidSide, move_soft, soft_response};
use crate::collision::{Collider, ColliderAabb, ColliderOf, ContactSettings, Friction};
use crate::core::quarantine::Quarantined;
use crate::core::time::SubstepTime;
use crate::integrator::implicit::ContactPlane;
use crate::integrator::skyline::SkylineCholesky;
use crate::integrator::{ImplicitEuler, ImplicitState};
use crate::particles::{LinearVelocity, Mass, Nodes, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Inertia, Rotation};

/// The most nodes in one dynamic body's layer whose impulses are found with the soft body's
/// full response (one factor solve each); past it, with the lumped masses.
const MAX_COUPLED: usize = 64;

/// Projected Gauss–Seidel passes over the nodes touching one dynamic body.
const CONTACT_PASSES: usize = 30;

type ColliderPose<'a> = (
    Entity,
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a ColliderAabb,
    &'a Friction,
    Option<Dynamics<'a>>,
    Option<&'a mut NodeImpulse>,
);

/// What a collider's body needs to take impulses.
type Dynamics<'a> = (
    &'a LinearVelocity,
    &'a AngularVelocity,
    &'a Mass,
    &'a Inertia,
    Option<&'a crate::rigid::LockedAxes>,
);

/// A mesh whose nodes collide: its contact layer's thickness, and where the contacts of the
/// last substep go (for its implicit solve to hold the nodes to).
pub(crate) trait NodeLayer: Component<Mutability = bevy_ecs::component::Mutable> {
    /// The layer's thickness (m): a node closer than this to a surface is in contact.
    fn thickness(&self) -> f32;
    /// The contacts found this substep.
    fn contacts_mut(&mut self) -> &mut Vec<ContactPlane>;
    /// Told when its nodes press on a dynamic body.
    fn touched_a_body(&mut self) {}
}

type Mesh<'a, L> = (
    Entity,
    &'a mut Nodes,
    &'a mut L,
    Option<&'a ImplicitState>,
    Option<&'a ImplicitEuler>,
);

fn side_of(x: &Position, q: &Rotation, d: Option<Dynamics<'_>>) -> Option<RigidSide> {
    let (v, w, m, i, locks) = d?;
    Some(RigidSide {
        x: Vec3::from(x.0),
        v: Vec3::from(v.0),
        w: Vec3::from(w.0),
        inv_mass: crate::rigid::LockedAxes::inverse_mass_of(locks, m.inverse()).into(),
        inv_inertia: i.world_inverse_tensor(q.0),
        dynamic: m.inverse() > 0.0 || !i.is_infinite(),
        linear: Vec3::ZERO,
        angular: Vec3::ZERO,
    })
}

/// The meshes and colliders of one substep, in entity order.
#[derive(Default)]
pub(crate) struct NodeScratch {
    meshes: Vec<Entity>,
    near: Vec<Entity>,
}

/// Projects every soft body's nodes out of the colliders they touch.
///
/// Meshes, and the colliders near each, are taken in entity order, not query order: a node
/// pushed out of one collider is then tested against the next, and a body touched by two
/// meshes sums their impulses, so the order changes the rounding. A query walks tables in
/// the order its system first saw them, which a world restored from a snapshot does not
/// share with the original; entity order it does (restored ids keep the captured order).
pub(crate) fn collide_nodes<L: NodeLayer>(
    mut commands: Commands,
    time: Res<SubstepTime>,
    settings: Option<Res<ContactSettings>>,
    mut scratch: Local<NodeScratch>,
    mut bodies: Query<Mesh<L>, Without<Quarantined>>,
    mut colliders: Query<ColliderPose, (Without<Quarantined>, Without<ColliderOf>)>,
) {
    let h = time.h;
    let push = Push {
        h,
        max_push: settings.map_or(ContactSettings::default().max_push_velocity, |s| {
            s.max_push_velocity
        }),
    };
    let NodeScratch { meshes, near } = &mut *scratch;
    // Bodies that get their first soft impulse this substep (inserted at its end).
    let mut fresh: Vec<(Entity, NodeImpulse)> = Vec::new();
    meshes.clear();
    meshes.extend(bodies.iter().map(|(e, ..)| e));
    meshes.sort_unstable();
    for &mesh in meshes.iter() {
        let Ok((_, mut nodes, mut body, state, implicit)) = bodies.get_mut(mesh) else {
            continue;
        };
        let body = body.bypass_change_detection();
        let n = nodes.bypass_change_detection();
        let factor = state
            .filter(|_| implicit.is_some())
            .and_then(|s| s.factor.as_ref())
            .filter(|f| f.is_factored());
        body.contacts_mut().clear();
        let thickness = body.thickness();
        // Where the nodes were at the substep's start as well (x − h v): a fast node that
        // crossed a collider within the substep is found by its sweep.
        let Some((lo, hi)) = swept_bounds(n, h) else {
            continue;
        };
        let (lo, hi) = (lo - Vec3::splat(thickness), hi + Vec3::splat(thickness));
        near.clear();
        near.extend(colliders.iter().filter_map(|(e, _, _, _, _, aabb, ..)| {
            (!(aabb.min.cmpgt(hi).any() || aabb.max.cmplt(lo).any())).then_some(e)
        }));
        near.sort_unstable();
        for &entity in near.iter() {
            let Ok((_, c, x, q, com, aabb, friction, d, pending)) = colliders.get_mut(entity)
            else {
                continue;
            };
            // A body whose state went bad this substep (a kinematic given an infinite
            // velocity) is quarantined by its own check; touching it would hand its NaN to
            // the nodes, whose check has already run.
            let moving_bad = d.is_some_and(|(v, w, ..)| !(v.0.is_finite() && w.0.is_finite()));
            if moving_bad || !(x.0.is_finite() && q.0.is_finite()) {
                continue;
            }
            // A friction game code wrote (−∞, NaN) is the collider's fault: it leaves,
            // named by its error, as the rigid contacts' check does; the nodes do not read it.
            if let Err(err) = crate::core::quarantine::Validate::validate(friction) {
                commands.entity(entity).try_insert(Quarantined {
                    reason: crate::core::quarantine::QuarantineReason::InvalidInput(err),
                });
                continue;
            }
            let pose = crate::collision::shape_pose(x.0, q.0, com);
            let mut rigid = side_of(x, q, d);
            // Guarded as pair geometry is (parry asserts on some degenerate inputs): a mesh
            // whose contact with this collider fails leaves, named with it.
            let found = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                find_hits(n, c, &pose, q.0, aabb, thickness, h)
            }));
            let Ok(hits) = found else {
                commands.entity(mesh).try_insert(Quarantined {
                    reason: crate::core::quarantine::QuarantineReason::GeometryFailed {
                        other: entity,
                    },
                });
                break;
            };
            if hits.is_empty() {
                continue;
            }
            let mut hits = hits;
            share_the_way_out(&mut hits, n, rigid.as_ref(), push, Vec3::from(x.0));
            match rigid.as_mut() {
                Some(side) if side.dynamic => {
                    push_dynamic(n, side, &hits, factor, friction.0, push);
                    body.touched_a_body();
                }
                other => {
                    let side = other.map(|s| &*s);
                    push_immovable(n, body.contacts_mut(), side, &hits, friction.0, push);
                }
            }
            // The body takes the impulses at the start of the next substep (see
            // `NodeImpulse`). Moving it now as well, as an attachment does, would push it,
            // unseen, into whatever holds it up: the rigid contacts were found at the start
            // of the step.
            if let Some(side) = rigid.filter(RigidSide::touched) {
                let add = NodeImpulse {
                    linear: side.linear,
                    angular: side.angular,
                };
                match pending {
                    Some(mut p) => {
                        let p = p.bypass_change_detection();
                        p.linear += add.linear;
                        p.angular += add.angular;
                    }
                    None => match fresh.iter_mut().find(|f| f.0 == entity) {
                        Some(f) => {
                            f.1.linear += add.linear;
                            f.1.angular += add.angular;
                        }
                        None => fresh.push((entity, add)),
                    },
                }
            }
        }
    }
    for (entity, add) in fresh {
        commands.entity(entity).insert(add);
    }
}

/// A node in a collider's contact layer: its outward normal (world) and its overlap with
/// the layer (m, positive inside).
struct Hit {
    node: usize,
    normal: Vec3,
    overlap: f32,
}

/// How far overlaps are closed in one substep.
#[derive(Clone, Copy)]
struct Push {
    /// The substep (s).
    h: f32,
    /// The fastest an overlap older than this substep is closed (m/s).
    max_push: f32,
}

impl Push {
    /// The part of `overlap` (m) closed this substep for a node approaching the surface at
    /// `approach` (m/s, relative to it; negative leaving): all its approach brought in, and
    /// older overlap at `max_push`. Bounds the speed a mesh spawned deep inside a collider
    /// comes out at, as the rigid contacts do.
    #[must_use]
    fn closed(self, overlap: f32, approach: f32) -> f32 {
        overlap.min((approach.max(0.0) + self.max_push) * self.h)
    }
}

/// Deep hits (more overlap than one substep's push closes) of one mesh in one collider
/// leave the same way: along the mean of their normals, or, when those cancel (a mesh
/// centred in a box), from the collider's centre through theirs. Each node's own nearest
/// surface would tear a mesh that straddles the shape's medial axis apart at the push speed
/// (a jelly inside a box was pulled to all six faces and went non-finite in three steps).
/// Shallow hits, every contact of a mesh that did not start inside, keep their own normals.
fn share_the_way_out(
    hits: &mut [Hit],
    n: &Nodes,
    side: Option<&RigidSide>,
    push: Push,
    center: Vec3,
) {
    let deep: Vec<bool> = hits
        .iter()
        .map(|hit| {
            let p = Vec3::from(n.x[hit.node]);
            let base = side.map_or(Vec3::ZERO, |s| s.point_velocity(p));
            let approach = -(Vec3::from(n.v[hit.node]) - base).dot(hit.normal);
            push.closed(hit.overlap, approach) < hit.overlap
        })
        .collect();
    let count = deep.iter().filter(|d| **d).count();
    if count < 2 {
        return;
    }
    let (mut sum, mut centroid, mut first) = (Vec3::ZERO, Vec3::ZERO, None);
    for (hit, _) in hits.iter().zip(&deep).filter(|(_, d)| **d) {
        sum += hit.normal;
        centroid += Vec3::from(n.x[hit.node]);
        first.get_or_insert(hit.normal);
    }
    let way = if sum.length() >= 0.25 * count as f32 {
        sum.normalize()
    } else {
        (centroid / count as f32 - center)
            .try_normalize()
            .or(first)
            .unwrap_or(Vec3::Y)
    };
    if !way.is_finite() {
        return;
    }
    for (hit, _) in hits.iter_mut().zip(&deep).filter(|(_, d)| **d) {
        hit.normal = way;
    }
}

/// The bounds of the nodes now and at the substep's start (x − h v).
fn swept_bounds(n: &Nodes, h: f32) -> Option<(Vec3, Vec3)> {
    let first = Vec3::from(*n.x.first()?);
    Some(
        n.x.iter()
            .zip(&n.v)
            .fold((first, first), |(lo, hi), (x, v)| {
                let (x, back) = (Vec3::from(*x), Vec3::from(*x - *v * h));
                (lo.min(x).min(back), hi.max(x).max(back))
            }),
    )
}

/// The surface a fast node crossed within the substep: its sweep from `start` to `end` (in
/// the collider's frame, `start` outside the shape) enters the shape. The hit's outward
/// normal and the overlap that puts the node back `thickness` outside the entry point.
fn crossed(
    shape: &dyn parry3d::shape::Shape,
    start: Vec3,
    end: Vec3,
    thickness: f32,
) -> Option<(Vec3, f32)> {
    if shape.contains_local_point(start) {
        return None;
    }
    let ray = parry3d::query::Ray::new(start, end - start);
    let hit = shape.cast_local_ray_and_get_normal(&ray, 1.0, true)?;
    let n = hit.normal;
    let entry = ray.point_at(hit.time_of_impact);
    (n.is_finite() && n != Vec3::ZERO).then(|| (n, thickness + (entry - end).dot(n)))
}

fn find_hits(
    n: &Nodes,
    collider: &Collider,
    pose: &Pose,
    rotation: Quat,
    aabb: &ColliderAabb,
    thickness: f32,
    h: f32,
) -> Vec<Hit> {
    let shape = collider.shape();
    let inverse = pose.inverse();
    let mut hits = Vec::new();
    for i in 0..n.x.len() {
        if n.inv_mass[i] == 0.0 {
            continue;
        }
        let p = Vec3::from(n.x[i]);
        let step = Vec3::from(n.v[i]) * h;
        let back = p - step;
        let (lo, hi) = (p.min(back), p.max(back));
        if (hi + Vec3::splat(thickness)).cmplt(aabb.min).any()
            || (lo - Vec3::splat(thickness)).cmpgt(aabb.max).any()
        {
            continue;
        }
        let local = inverse * p;
        if !local.is_finite() || !step.is_finite() {
            // A node gone non-finite is caught by its own check; projecting it would trip
            // parry's asserts (NaN against a capsule of half height 0).
            continue;
        }
        // A node that moved more than the contact distance this substep may have crossed
        // the surface, or a thin shape whole: the sweep's entry decides, since a point test
        // at its end would push it out of the far side (a soft cube at 300 m/s under
        // implicit integration went through the ground).
        if step.length_squared() > thickness * thickness
            && let Some((normal_local, overlap)) =
                crossed(&**shape, inverse * back, local, thickness)
        {
            hits.push(Hit {
                node: i,
                normal: rotation * normal_local,
                overlap,
            });
            continue;
        }
        let Some((normal_local, depth)) = nearest_surface(&**shape, local, thickness) else {
            continue;
        };
        hits.push(Hit {
            node: i,
            normal: rotation * normal_local,
            overlap: thickness - depth,
        });
    }
    hits
}

/// The outward normal at the surface nearest to `local` and its signed distance from it
/// (m, negative inside), if it is closer than `thickness` or inside.
///
/// Inside a convex hull the nearest face plane decides, exactly: parry's projection onto a
/// hull runs GJK with a tolerance that grows with the shape, and called a point 2.7 cm
/// below a 720 m hull inside, so a jelly falling out of it had nodes pulled back and
/// stopped (a 79 m/s jolt).
fn nearest_surface(
    shape: &dyn parry3d::shape::Shape,
    local: Vec3,
    thickness: f32,
) -> Option<(Vec3, f32)> {
    let inside = match shape.as_convex_polyhedron() {
        Some(hull) => match deepest_face(hull, local) {
            Some((normal, distance)) if distance <= 0.0 => return Some((normal, distance)),
            _ => false,
        },
        None => shape.project_local_point(local, true).is_inside,
    };
    if inside {
        // Inside: the solid projection is the point itself; the surface is the way out.
        let out = shape.project_local_point(local, false).point - local;
        let d = out.length();
        return (d > 0.0).then(|| (out / d, -d));
    }
    let off = local - shape.project_local_point(local, false).point;
    let d = off.length();
    (d < thickness && d > 0.0).then(|| (off / d, d))
}

/// The face of `hull` whose plane `p` is farthest out of (or least deep behind): its outward
/// normal and that signed distance (m). For a point inside, the nearest surface.
fn deepest_face(hull: &parry3d::shape::ConvexPolyhedron, p: Vec3) -> Option<(Vec3, f32)> {
    let (points, corners) = (hull.points(), hull.vertices_adj_to_face());
    hull.faces()
        .iter()
        .filter_map(|face| {
            let corner = points.get(*corners.get(face.first_vertex_or_edge as usize)? as usize)?;
            Some((face.normal, face.normal.dot(p - *corner)))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// A static or kinematic collider: each node is moved out and stops on its own, relative to
/// the surface's velocity, and leaves a plane for the implicit solve.
fn push_immovable(
    n: &mut Nodes,
    contacts: &mut Vec<ContactPlane>,
    side: Option<&RigidSide>,
    hits: &[Hit],
    mu: f32,
    push: Push,
) {
    for hit in hits {
        let i = hit.node;
        let at = Vec3::from(n.x[i]);
        let base = side.map_or(Vec3::ZERO, |b| b.point_velocity(at));
        let approach = -(Vec3::from(n.v[i]) - base).dot(hit.normal);
        let closed = push.closed(hit.overlap, approach);
        n.x[i] += Vec3A::from(hit.normal * closed);
        let p = Vec3::from(n.x[i]);
        let base = side.map_or(Vec3::ZERO, |b| b.point_velocity(p));
        let rel = Vec3::from(n.v[i]) - base;
        let vn = rel.dot(hit.normal);
        // Only the approach bears friction. The push out of older overlap does not: a
        // deeply embedded mesh whose every node friction stopped each substep would be
        // stepped as x += h² F / m, stable only to half the explicit limit (a jelly inside
        // a 236 m cylinder blew up after 3.7 s); it slides along the inside instead.
        if vn < 0.0 {
            let tangent = rel - vn * hit.normal;
            let speed = tangent.length();
            let slowed = if speed > 0.0 {
                tangent * ((speed + mu * vn).max(0.0) / speed)
            } else {
                tangent
            };
            n.v[i] = Vec3A::from(base + slowed);
        }
        contacts.push(ContactPlane {
            node: i as u32,
            normal: hit.normal,
            offset: hit.normal.dot(p) + push.h * hit.normal.dot(base),
        });
    }
}

/// A dynamic body: the normal impulses that close every overlap together (projected
/// Gauss–Seidel on the coupled response), then friction node by node.
fn push_dynamic(
    n: &mut Nodes,
    side: &mut RigidSide,
    hits: &[Hit],
    factor: Option<&SkylineCholesky>,
    mu: f32,
    push: Push,
) {
    let h = push.h;
    if hits.len() > MAX_COUPLED {
        push_many(n, side, hits, mu, push);
        return;
    }
    let rows: Vec<(usize, Vec3)> = hits.iter().map(|h| (h.node, h.normal)).collect();
    let at: Vec<(Vec3, Vec3)> = hits
        .iter()
        .map(|h| (Vec3::from(n.x[h.node]), h.normal))
        .collect();
    let g = soft_response(n, factor, &rows, h) + side.response(&at);
    // G λ ≥ C / h: each overlap closed over the substep (deep ones at the push speed).
    let target: Vec<f64> = hits
        .iter()
        .map(|hit| {
            let p = Vec3::from(n.x[hit.node]);
            let approach = -(Vec3::from(n.v[hit.node]) - side.point_velocity(p)).dot(hit.normal);
            f64::from(push.closed(hit.overlap, approach)) / f64::from(h)
        })
        .collect();
    let a = hits.len();
    let mut lambda = vec![0.0f64; a];
    for _ in 0..CONTACT_PASSES {
        for k in 0..a {
            let diag = g[(k, k)];
            if diag <= 0.0 {
                continue;
            }
            let reached: f64 = (0..a).map(|l| g[(k, l)] * lambda[l]).sum();
            lambda[k] = (lambda[k] + (target[k] - reached) / diag).max(0.0);
        }
    }
    let impulses: Vec<(usize, Vec3)> = hits
        .iter()
        .zip(&lambda)
        .filter(|(_, l)| **l > 0.0)
        .map(|(h, &l)| (h.node, h.normal * l as f32))
        .collect();
    move_soft(n, factor, &impulses, h);
    for &(i, j) in &impulses {
        side.take(Vec3::from(n.x[i]), -j);
    }
    // Friction node by node, capped by each node's normal impulse.
    for (hit, &l) in hits.iter().zip(&lambda) {
        if l <= 0.0 {
            continue;
        }
        let i = hit.node;
        let p = Vec3::from(n.x[i]);
        let rel = Vec3::from(n.v[i]) - side.point_velocity(p);
        let tangent = rel - rel.dot(hit.normal) * hit.normal;
        let speed = tangent.length();
        if speed == 0.0 {
            continue;
        }
        let dir = tangent / speed;
        let stop = speed / (n.inv_mass[i] + side.inverse_mass_along(p, dir));
        let j = -stop.min(mu * l as f32) * dir;
        n.v[i] += Vec3A::from(n.inv_mass[i] * j);
        side.take(p, -j);
    }
}

/// Many nodes on one dynamic body: the same impulses node by node, each node with its own
/// mass (no dense response), several passes so that no node's place in the order favours it.
fn push_many(n: &mut Nodes, side: &mut RigidSide, hits: &[Hit], mu: f32, push: Push) {
    let h = push.h;
    // The push-out each overlap may have, fixed by the approach before any impulse.
    let bias: Vec<f32> = hits
        .iter()
        .map(|hit| {
            let p = Vec3::from(n.x[hit.node]);
            let approach = -(Vec3::from(n.v[hit.node]) - side.point_velocity(p)).dot(hit.normal);
            push.closed(hit.overlap, approach) / h
        })
        .collect();
    let mut normal_impulse = vec![0.0f32; hits.len()];
    let mut friction_impulse = vec![Vec3::ZERO; hits.len()];
    for _ in 0..CONTACT_PASSES.min(8) {
        for (k, hit) in hits.iter().enumerate() {
            let i = hit.node;
            let inv_node = n.inv_mass[i];
            let p = Vec3::from(n.x[i]);
            let rel = Vec3::from(n.v[i]) - side.point_velocity(p);
            let vn = rel.dot(hit.normal);
            let total = (normal_impulse[k]
                + (bias[k] - vn) / (inv_node + side.inverse_mass_along(p, hit.normal)))
            .max(0.0);
            let mut j = (total - normal_impulse[k]) * hit.normal;
            normal_impulse[k] = total;
            let tangent = rel - vn * hit.normal;
            let speed = tangent.length();
            let mut friction = friction_impulse[k];
            if speed > 0.0 {
                let dir = tangent / speed;
                friction -= speed / (inv_node + side.inverse_mass_along(p, dir)) * dir;
            }
            let cap = mu * total;
            if friction.length() > cap {
                friction *= cap / friction.length();
            }
            j += friction - friction_impulse[k];
            friction_impulse[k] = friction;
            n.v[i] += Vec3A::from(inv_node * j);
            side.take(p, -j);
        }
    }
    // The velocities carry the nodes out over the next substep; move them now as well, as the
    // coupled path does (Δx = h Δv), by the normal part.
    for (hit, &l) in hits.iter().zip(&normal_impulse) {
        n.x[hit.node] += Vec3A::from(h * n.inv_mass[hit.node] * l * hit.normal);
    }
}
