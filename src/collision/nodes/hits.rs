//! Where a mesh touches a collider: its nodes in the collider's contact layer, and the
//! collider's surface inside the layer of a triangle between nodes.
//!
//! **Nodes.** A node closer than the thickness to the surface (or inside) is a hit with the
//! surface's outward normal. A node that moved more than the thickness relative to the
//! collider this substep is swept instead, from where it stood in the collider's frame at
//! the substep's start: a point test at its end could push it out of the far side of a thin
//! or fast shape.
//!
//! **Faces.** Nodes alone let anything smaller than the node spacing through: a 5 cm ball, a
//! thin bar or a crate's edge between the nodes of a 25 cm cloth. Each surface triangle near
//! the collider is tested against the shape as it stood at the substep's *start* (both moved
//! back by h v), with a reach of the thickness plus how far both could have moved since. That
//! query fixes the contact's features (the point on the triangle as barycentric weights, the
//! point on the shape in the shape's frame) and its normal, taken from the side the shape came
//! from; the overlap is measured between those two material points *now*. A fast or thin body
//! that crossed the triangle within the substep is therefore caught on the side it came from
//! (continuous, speculative in the manner of Box2D's speculative contacts), and one whose
//! features did not close the gap makes no contact.
//!
//! A triangle whose three nodes are all hits of the collider is skipped (a flat face under a
//! cloth: its nodes already hold it, and the face between them lies on the same plane), and so
//! is a face contact at a corner or on an edge whose nodes are hits: their own contacts hold
//! it. The faces keep half the nodes' layer (see [`FACE_LAYER`]).

use glam::{Quat, Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::shape::{Shape, Triangle};

use crate::collision::ColliderAabb;
use crate::particles::Nodes;

/// A contact between a mesh and a collider: one node, or a point inside a triangle (its
/// corners and barycentric weights). The normal is the collider's outward normal (world, the
/// way the mesh is pushed) and the overlap is how deep the point is in the contact layer (m,
/// positive inside).
#[derive(Debug, Clone, Copy)]
pub(super) struct Hit {
    corners: [u32; 3],
    weights: [f32; 3],
    /// 1 for a node, 3 for a point on a triangle.
    count: u8,
    /// Where the contact acts on the collider's body, for a point on a triangle (its surface
    /// point; a node's contact acts at the node).
    on_body: Option<Vec3>,
    /// A point held by pinned corners: the nodes do not move for it, the body alone answers.
    held: bool,
    pub(super) normal: Vec3,
    pub(super) overlap: f32,
}

impl Hit {
    fn node(i: usize, normal: Vec3, overlap: f32) -> Self {
        Self {
            corners: [i as u32; 3],
            weights: [1.0, 0.0, 0.0],
            count: 1,
            on_body: None,
            held: false,
            normal,
            overlap,
        }
    }

    /// Where the contact acts on the collider's body (m): the shape's surface point facing
    /// a triangle, or the node. A thin bar's contact taken a layer's thickness below its
    /// surface would have twice its radius as lever arm, and friction would spin it up.
    pub(super) fn on_body(&self, n: &Nodes) -> Vec3 {
        self.on_body.unwrap_or_else(|| self.point(n))
    }

    /// The node, for a node's hit.
    pub(super) fn single(&self) -> Option<usize> {
        (self.count == 1).then_some(self.corners[0] as usize)
    }

    /// The nodes that move for it and their weights (one node of weight 1, or a triangle's
    /// three corners; none for a point its pinned corners hold).
    pub(super) fn parts(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.corners
            .iter()
            .zip(&self.weights)
            .take(if self.held { 0 } else { self.count as usize })
            .map(|(&c, &w)| (c as usize, w))
    }

    /// The corners and their weights, whether they move or not.
    fn corners(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.corners
            .iter()
            .zip(&self.weights)
            .take(self.count as usize)
            .map(|(&c, &w)| (c as usize, w))
    }

    /// The contact point on the mesh (m).
    pub(super) fn point(&self, n: &Nodes) -> Vec3 {
        match self.single() {
            Some(i) => Vec3::from(n.x[i]),
            None => self.corners().map(|(i, w)| w * Vec3::from(n.x[i])).sum(),
        }
    }

    /// The contact point's velocity (m/s).
    pub(super) fn velocity(&self, n: &Nodes) -> Vec3 {
        match self.single() {
            Some(i) => Vec3::from(n.v[i]),
            None => self.corners().map(|(i, w)| w * Vec3::from(n.v[i])).sum(),
        }
    }

    /// The point's inverse mass in the lumped masses, Σ wₐ² / mₐ (1/kg).
    pub(super) fn inverse_mass(&self, n: &Nodes) -> f32 {
        match self.single() {
            Some(i) => n.inv_mass[i],
            None => self.parts().map(|(i, w)| w * w * n.inv_mass[i]).sum(),
        }
    }

    /// Gives the point the impulse `j` (N·s) in the lumped masses: node a takes wₐ j.
    pub(super) fn take(&self, n: &mut Nodes, j: Vec3) {
        match self.single() {
            Some(i) => n.v[i] += Vec3A::from(n.inv_mass[i] * j),
            None => {
                for (i, w) in self.parts() {
                    n.v[i] += Vec3A::from(w * n.inv_mass[i] * j);
                }
            }
        }
    }

    /// Moves the point by `dx` (m) in the lumped masses, each node in proportion to wₐ / mₐ
    /// (the least-mass-weighted move that moves the point by `dx`).
    pub(super) fn shift(&self, n: &mut Nodes, dx: Vec3) {
        match self.single() {
            Some(i) => n.x[i] += Vec3A::from(dx),
            None => {
                let w = self.inverse_mass(n);
                if w <= 0.0 {
                    return;
                }
                for (i, wi) in self.parts() {
                    n.x[i] += Vec3A::from(dx * (wi * n.inv_mass[i] / w));
                }
            }
        }
    }
}

/// Where the collider's shape stands now and stood at the substep's start.
pub(super) struct Motion {
    /// The shape's pose now.
    pub(super) end: Pose,
    /// At the substep's start, when it moved.
    pub(super) start: Option<Pose>,
    /// How far any point of the shape moved this substep, at most (m).
    pub(super) reach: f32,
}

impl Motion {
    /// A collider whose body moves at `v` (m/s) and `w` (rad/s), its shape at `end` now, its
    /// centre of mass at `x` and its points within `radius` (m) of it.
    pub(super) fn new(end: Pose, x: Vec3, v: Vec3, w: Vec3, radius: f32, h: f32) -> Self {
        if v == Vec3::ZERO && w == Vec3::ZERO {
            return Self {
                end,
                start: None,
                reach: 0.0,
            };
        }
        let back = Quat::from_scaled_axis(-h * w);
        let rotation = (back * end.rotation).normalize();
        // The shape frame turns about the centre of mass: its origin's offset turns with it.
        let translation = x - h * v + back * (end.translation - x);
        Self {
            end,
            start: Some(Pose::from_parts(translation, rotation)),
            reach: h * (v.length() + w.length() * radius),
        }
    }
}

/// The surface a fast node crossed within the substep: its sweep from `start` to `end` (in
/// the collider's frame, `start` outside the shape) enters the shape. The hit's outward
/// normal and the overlap that puts the node back `thickness` outside the entry point.
fn crossed(shape: &dyn Shape, start: Vec3, end: Vec3, thickness: f32) -> Option<(Vec3, f32)> {
    if shape.contains_local_point(start) {
        return None;
    }
    let ray = parry3d::query::Ray::new(start, end - start);
    let hit = shape.cast_local_ray_and_get_normal(&ray, 1.0, true)?;
    let n = hit.normal;
    let entry = ray.point_at(hit.time_of_impact);
    (n.is_finite() && n != Vec3::ZERO).then(|| (n, thickness + (entry - end).dot(n)))
}

/// The nodes in the collider's contact layer, in index order.
pub(super) fn node_hits(
    n: &Nodes,
    shape: &dyn Shape,
    motion: &Motion,
    aabb: &ColliderAabb,
    thickness: f32,
    h: f32,
) -> Vec<Hit> {
    let pose = &motion.end;
    let rotation = pose.rotation;
    let inverse = pose.inverse();
    let start_inverse = motion.start.map(|s| s.inverse());
    let mut hits = Vec::new();
    for i in 0..n.x.len() {
        if n.inv_mass[i] == 0.0 {
            continue;
        }
        let p = Vec3::from(n.x[i]);
        let step = Vec3::from(n.v[i]) * h;
        let back = p - step;
        // Where the node stood at the substep's start, in the collider's frame then (and, for
        // the bounds test, in the world as if the collider had stood where it stands now).
        let (back_local, back_seen) = match &start_inverse {
            Some(s) => {
                let local = *s * back;
                (local, *pose * local)
            }
            None => (inverse * back, back),
        };
        let (lo, hi) = (p.min(back_seen), p.max(back_seen));
        if (hi + Vec3::splat(thickness)).cmplt(aabb.min).any()
            || (lo - Vec3::splat(thickness)).cmpgt(aabb.max).any()
        {
            continue;
        }
        let local = inverse * p;
        if !local.is_finite() || !back_local.is_finite() {
            // A node gone non-finite is caught by its own check; projecting it would trip
            // parry's asserts (NaN against a capsule of half height 0).
            continue;
        }
        // A node that moved more than the contact distance relative to the collider this
        // substep may have crossed the surface, or a thin shape whole: the sweep's entry
        // decides, since a point test at its end would push it out of the far side (a soft
        // cube at 300 m/s under implicit integration went through the ground).
        let moved = match start_inverse {
            Some(_) => (local - back_local).length_squared(),
            None => step.length_squared(),
        };
        if moved > thickness * thickness
            && let Some((normal_local, overlap)) = crossed(shape, back_local, local, thickness)
        {
            hits.push(Hit::node(i, rotation * normal_local, overlap));
            continue;
        }
        let Some((normal_local, depth)) = nearest_surface(shape, local, thickness) else {
            continue;
        };
        hits.push(Hit::node(i, rotation * normal_local, thickness - depth));
    }
    hits
}

/// The share of the contact layer the surface between the nodes keeps. Less than the nodes':
/// a cloth resting on a sphere bulges into the layer between its nodes (by the sagitta, 1.6 mm
/// for 5 cm cells on a 0.5 m ball), and its nodes step in and out of theirs; had the faces
/// the full layer, they would push the cloth out between nodes its implicit solve pulls back
/// in, and it would never rest (it shook at 1.3 m/s).
const FACE_LAYER: f32 = 0.5;

/// The least share of a point's weights on nodes that can move for the nodes to move for it.
const MIN_FREE_WEIGHT: f32 = 0.25;

/// The collider's surface inside the contact layer of the triangles between nodes (see the
/// module docs), for the triangles near `aabb`. `node_hits` are the same collider's node
/// hits, in node order.
#[allow(clippy::too_many_arguments)]
pub(super) fn face_hits(
    n: &Nodes,
    triangles: &[[u32; 3]],
    shape: &dyn Shape,
    motion: &Motion,
    aabb: &ColliderAabb,
    thickness: f32,
    h: f32,
    node_hits: &[Hit],
    manifolds: &mut FaceManifolds,
    out: &mut Vec<Hit>,
) {
    let mut points = Vec::new();
    let hit_node = |i: u32| {
        node_hits
            .binary_search_by_key(&(i as usize), |hit| hit.single().unwrap_or(usize::MAX))
            .is_ok()
    };
    let start_pose = motion.start.unwrap_or(motion.end);
    let len = n.x.len();
    for &corners in triangles {
        if corners.iter().any(|&c| c as usize >= len)
            || corners.iter().all(|&c| n.inv_mass[c as usize] == 0.0)
        {
            continue;
        }
        let touching = corners.map(hit_node);
        if touching.iter().all(|t| *t) {
            continue;
        }
        let now = corners.map(|c| Vec3::from(n.x[c as usize]));
        let before = corners.map(|c| Vec3::from(n.x[c as usize] - n.v[c as usize] * h));
        let own = corners
            .iter()
            .map(|&c| h * n.v[c as usize].length())
            .fold(0.0f32, f32::max);
        let reach = thickness + motion.reach + own;
        let lo = now[0]
            .min(now[1])
            .min(now[2])
            .min(before[0].min(before[1]).min(before[2]));
        let hi = now[0]
            .max(now[1])
            .max(now[2])
            .max(before[0].max(before[1]).max(before[2]));
        if (hi + Vec3::splat(reach)).cmplt(aabb.min).any()
            || (lo - Vec3::splat(reach)).cmpgt(aabb.max).any()
            || !(lo.is_finite() && hi.is_finite())
        {
            continue;
        }
        let Some(weights) = Barycentric::of(before) else {
            continue;
        };
        let triangle = Triangle::new(before[0], before[1], before[2]);
        points.clear();
        contact_points(&triangle, shape, &start_pose, reach, manifolds, &mut points);
        for &(normal, on_triangle, on_shape_local) in &points {
            if !(normal.is_finite() && on_triangle.is_finite() && on_shape_local.is_finite()) {
                continue;
            }
            let w = weights.at(on_triangle);
            // A point at a corner, or on an edge, whose nodes are in the layer themselves is
            // theirs to hold.
            if (0..3).all(|k| w[k] < 1e-2 || touching[k]) {
                continue;
            }
            // A point held mostly by pinned corners is held: moving it by its free corners
            // alone would fling them by 1/w (a bridge pinned along a ledge's edge blew up), so
            // the body alone answers it, as it would a static surface.
            let free: f32 = (0..3)
                .filter(|&k| n.inv_mass[corners[k] as usize] > 0.0)
                .map(|k| w[k])
                .sum();
            let held = free < MIN_FREE_WEIGHT;
            let on_shape = motion.end * on_shape_local;
            let on_mesh: Vec3 = (0..3).map(|k| w[k] * now[k]).sum();
            let overlap = FACE_LAYER * thickness - (on_mesh - on_shape).dot(normal);
            if overlap > 0.0 && overlap.is_finite() {
                out.push(Hit {
                    corners,
                    weights: w,
                    count: 3,
                    on_body: Some(on_shape),
                    held,
                    normal,
                    overlap,
                });
            }
        }
    }
}

/// parry's contact manifolds, kept between calls.
pub(super) type FaceManifolds = Vec<parry3d::query::ContactManifold<(), ()>>;

/// The contact points of a triangle and a shape as they stood at the substep's start, within
/// `reach`: (the collider's outward normal, the point on the triangle, the shape's point in
/// its frame). A manifold, not one point: a crate's face on a triangle is held at each of
/// its corners, where one point would let the triangle see-saw into the face.
fn contact_points(
    triangle: &Triangle,
    shape: &dyn Shape,
    pose: &Pose,
    reach: f32,
    manifolds: &mut FaceManifolds,
    out: &mut Vec<(Vec3, Vec3, Vec3)>,
) {
    use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};
    manifolds.clear();
    let mut workspace = None;
    if DefaultQueryDispatcher
        .contact_manifolds(pose, triangle, shape, reach, manifolds, &mut workspace)
        .is_err()
    {
        return;
    }
    for m in manifolds.iter() {
        // A manifold on a part of a compound or mesh gives its points in the part's frame.
        let part = m.subshape_pos2().copied().unwrap_or(Pose::IDENTITY);
        let deepest = m
            .points
            .iter()
            .map(|p| p.dist)
            .fold(f32::INFINITY, f32::min);
        if deepest < 0.0
            && let Some(way) = overlapping(triangle, shape, pose)
            && way.0.dot(-m.local_n1) < 0.0
        {
            out.push(way);
            continue;
        }
        out.extend(
            m.points
                .iter()
                .map(|p| (-m.local_n1, p.local_p1, part * p.local_p2)),
        );
    }
}

/// A shape that already overlaps a triangle at the substep's start (its push last substep
/// did not clear it: a heavy body moves on before the mesh pushes it back). The least
/// penetration's direction is then no guide to the side it belongs on (a crate pressed into
/// a cloth cell wrapped it and left sideways through it), so the side its centre stands on
/// decides: the triangle's normal toward that side, and the shape's point deepest toward the
/// triangle along it. The collider's outward normal, the point on the triangle and the
/// shape's point in its frame; `None` for a shape without a support map.
fn overlapping(triangle: &Triangle, shape: &dyn Shape, pose: &Pose) -> Option<(Vec3, Vec3, Vec3)> {
    let support = shape.as_support_map()?;
    let face = triangle.normal()?;
    let centre = *pose * shape.compute_local_aabb().center();
    let side = if (centre - triangle.a).dot(face) >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let normal = -side * face;
    let local = support.local_support_point(pose.rotation.inverse() * normal);
    let deepest = *pose * local;
    let on_triangle = deepest - (deepest - triangle.a).dot(face) * face;
    Some((normal, on_triangle, local))
}

/// Barycentric coordinates in a triangle.
struct Barycentric {
    a: Vec3,
    e1: Vec3,
    e2: Vec3,
    d11: f32,
    d12: f32,
    d22: f32,
    inv: f32,
}

impl Barycentric {
    /// For the triangle `t`, or `None` when it has (almost) no area.
    fn of(t: [Vec3; 3]) -> Option<Self> {
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let det = d11 * d22 - d12 * d12;
        (det > 1e-12 * d11 * d22 && det.is_finite()).then(|| Self {
            a: t[0],
            e1,
            e2,
            d11,
            d12,
            d22,
            inv: 1.0 / det,
        })
    }

    /// The weights of the point of the triangle nearest `p` (clamped to the triangle).
    fn at(&self, p: Vec3) -> [f32; 3] {
        let d = p - self.a;
        let (d1, d2) = (d.dot(self.e1), d.dot(self.e2));
        let u = ((self.d22 * d1 - self.d12 * d2) * self.inv).max(0.0);
        let v = ((self.d11 * d2 - self.d12 * d1) * self.inv).max(0.0);
        let s = (1.0 - u - v).max(0.0);
        let total = s + u + v;
        [s / total, u / total, v / total]
    }
}

/// The outward normal at the surface nearest to `local` and its signed distance from it
/// (m, negative inside), if it is closer than `thickness` or inside.
///
/// Inside a convex hull the nearest face plane decides, exactly: parry's projection onto a
/// hull runs GJK with a tolerance that grows with the shape, and called a point 2.7 cm
/// below a 720 m hull inside, so a jelly falling out of it had nodes pulled back and
/// stopped (a 79 m/s jolt).
fn nearest_surface(shape: &dyn Shape, local: Vec3, thickness: f32) -> Option<(Vec3, f32)> {
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
