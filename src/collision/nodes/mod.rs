//! Meshes (soft bodies, cloth) against colliders: their nodes and the triangles between them
//! kept a thickness out of every collider, with Coulomb friction, after the positions are
//! integrated. Each effect whose meshes collide implements [`NodeLayer`] for its component
//! (and hands its surface's triangles to it) and registers [`collide_nodes`] for it. What
//! counts as a contact, a node's or a point inside a triangle's, is in `hits`; how each is
//! pushed out is in `push`. A point inside a triangle is moved as its corners are, each by
//! its barycentric weight over its mass.
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
//! Gauss–Seidel on that small system, then Coulomb friction per contact capped at μ λ; the
//! body takes −λ at each node, or at its own surface point facing a triangle. No plane holds a node to a dynamic body inside the solve: such a
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
mod hits;
mod push;

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::collision::nodes::coupling::{NodeImpulse, RigidSide};
use crate::collision::{Collider, ColliderAabb, ColliderOf, ContactSettings, Friction};
use crate::core::quarantine::Quarantined;
use crate::core::time::SubstepTime;
use crate::integrator::implicit::ContactPlane;
use crate::integrator::{ImplicitEuler, ImplicitState};
use crate::particles::{LinearVelocity, Mass, Nodes, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Inertia, Rotation};

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
    /// The surface's triangles (node indices), for contacts between nodes; none by default.
    fn triangles(&self) -> &[[u32; 3]] {
        &[]
    }
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
    manifolds: hits::FaceManifolds,
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
    let NodeScratch {
        meshes,
        near,
        manifolds,
    } = &mut *scratch;
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
            let motion = match &rigid {
                Some(side) => hits::Motion::new(
                    pose,
                    side.x,
                    side.v,
                    side.w,
                    crate::collision::radius(c, com),
                    h,
                ),
                None => hits::Motion::new(pose, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0.0, h),
            };
            let triangles = body.triangles();
            let found = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let shape = &**c.shape();
                let mut hits = hits::node_hits(n, shape, &motion, aabb, thickness, h);
                share_the_way_out(&mut hits, n, rigid.as_ref(), push, Vec3::from(x.0));
                let mut faces = Vec::new();
                hits::face_hits(
                    n, triangles, shape, &motion, aabb, thickness, h, &hits, manifolds, &mut faces,
                );
                hits.extend(faces);
                hits
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
            match rigid.as_mut() {
                Some(side) if side.dynamic => {
                    push::push_dynamic(n, side, &hits, factor, friction.0, push);
                    body.touched_a_body();
                }
                other => {
                    let side = other.map(|s| &*s);
                    push::push_immovable(n, body.contacts_mut(), side, &hits, friction.0, push);
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

/// How far overlaps are closed in one substep.
#[derive(Clone, Copy)]
pub(super) struct Push {
    /// The substep (s).
    pub(super) h: f32,
    /// The fastest an overlap older than this substep is closed (m/s).
    max_push: f32,
}

impl Push {
    /// The part of `overlap` (m) closed this substep for a node approaching the surface at
    /// `approach` (m/s, relative to it; negative leaving): all its approach brought in, and
    /// older overlap at `max_push`. Bounds the speed a mesh spawned deep inside a collider
    /// comes out at, as the rigid contacts do.
    #[must_use]
    pub(super) fn closed(self, overlap: f32, approach: f32) -> f32 {
        overlap.min((approach.max(0.0) + self.max_push) * self.h)
    }

    /// As [`Push::closed`], but older overlap only a fifth at a time: for a point between
    /// nodes, which its pinned or stiff neighbours can make as hard as a wall, and whose body
    /// takes its share one substep late. Closing all of the older overlap at once would hand
    /// the body back the approach it had, as a bounce.
    #[must_use]
    pub(super) fn closed_gently(self, overlap: f32, approach: f32) -> f32 {
        let new = (approach.max(0.0) * self.h).min(overlap);
        new + (0.2 * (overlap - new)).min(self.max_push * self.h)
    }
}

/// Deep hits (more overlap than one substep's push closes) of one mesh in one collider
/// leave the same way: along the mean of their normals, or, when those cancel (a mesh
/// centred in a box), from the collider's centre through theirs. Each node's own nearest
/// surface would tear a mesh that straddles the shape's medial axis apart at the push speed
/// (a jelly inside a box was pulled to all six faces and went non-finite in three steps).
/// Shallow hits, every contact of a mesh that did not start inside, keep their own normals.
fn share_the_way_out(
    hits: &mut [hits::Hit],
    n: &Nodes,
    side: Option<&RigidSide>,
    push: Push,
    center: Vec3,
) {
    let deep: Vec<bool> = hits
        .iter()
        .map(|hit| {
            let p = hit.point(n);
            let base = side.map_or(Vec3::ZERO, |s| s.point_velocity(p));
            let approach = -(hit.velocity(n) - base).dot(hit.normal);
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
        centroid += hit.point(n);
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
