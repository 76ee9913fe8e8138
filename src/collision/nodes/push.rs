//! Moving a mesh out of a collider by its hits: node by node against a static or kinematic
//! collider, by impulses found together against a dynamic body.

use glam::{Vec3, Vec3A};

use super::Push;
use super::hits::Hit;
use crate::collision::nodes::coupling::{RigidSide, Row, move_soft, soft_response_of};
use crate::integrator::implicit::ContactPlane;
use crate::integrator::skyline::SkylineCholesky;
use crate::particles::Nodes;

/// The most hits on one dynamic body whose impulses are found with the soft body's full
/// response (one factor solve each); past it, with the lumped masses.
const MAX_COUPLED: usize = 64;

/// Projected Gauss–Seidel passes over the hits on one dynamic body.
const CONTACT_PASSES: usize = 30;

/// A static or kinematic collider: each hit is moved out and stops on its own, relative to
/// the surface's velocity; a node's hit leaves a plane for the implicit solve.
pub(super) fn push_immovable(
    n: &mut Nodes,
    contacts: &mut Vec<ContactPlane>,
    side: Option<&RigidSide>,
    hits: &[Hit],
    mu: f32,
    push: Push,
) {
    for hit in hits {
        let Some(i) = hit.single() else {
            push_face(n, side, hit, mu, push);
            continue;
        };
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
            n.v[i] = Vec3A::from(base + slowed(rel, vn, hit.normal, mu));
        }
        contacts.push(ContactPlane {
            node: i as u32,
            normal: hit.normal,
            offset: hit.normal.dot(p) + push.h * hit.normal.dot(base),
        });
    }
}

/// The tangential part of `rel` after Coulomb friction with the normal approach `vn` < 0.
fn slowed(rel: Vec3, vn: f32, normal: Vec3, mu: f32) -> Vec3 {
    let tangent = rel - vn * normal;
    let speed = tangent.length();
    if speed > 0.0 {
        tangent * ((speed + mu * vn).max(0.0) / speed)
    } else {
        tangent
    }
}

/// A point between nodes against a static or kinematic collider: the triangle is moved out
/// as a node is, its corners in proportion to their weights over their masses, and the
/// point's approach and slip are taken by one impulse shared the same way.
fn push_face(n: &mut Nodes, side: Option<&RigidSide>, hit: &Hit, mu: f32, push: Push) {
    let w = hit.inverse_mass(n);
    if w <= 0.0 {
        return;
    }
    let at = hit.on_body(n);
    let base = side.map_or(Vec3::ZERO, |b| b.point_velocity(at));
    let approach = -(hit.velocity(n) - base).dot(hit.normal);
    hit.shift(n, hit.normal * push.closed_gently(hit.overlap, approach));
    let rel = hit.velocity(n) - base;
    let vn = rel.dot(hit.normal);
    if vn < 0.0 {
        let after = slowed(rel, vn, hit.normal, mu);
        hit.take(n, (after - rel) / w);
    }
}

/// A dynamic body: the normal impulses that close every overlap together (projected
/// Gauss–Seidel on the coupled response), then friction hit by hit.
pub(super) fn push_dynamic(
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
    let rows: Vec<Row> = hits.iter().map(row_of).collect();
    let at: Vec<(Vec3, Vec3)> = hits.iter().map(|h| (h.on_body(n), h.normal)).collect();
    let g = soft_response_of(n, factor, &rows, h) + side.response(&at);
    // G λ ≥ C / h: each overlap closed over the substep (deep ones at the push speed).
    let target: Vec<f64> = hits
        .iter()
        .zip(&at)
        .map(|(hit, &(p, _))| {
            let approach = -(hit.velocity(n) - side.point_velocity(p)).dot(hit.normal);
            let closed = match hit.single() {
                Some(_) => push.closed(hit.overlap, approach),
                None => push.closed_gently(hit.overlap, approach),
            };
            f64::from(closed) / f64::from(h)
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
    let mut impulses: Vec<(usize, Vec3)> = Vec::with_capacity(a);
    for (hit, &l) in hits.iter().zip(&lambda).filter(|(_, l)| **l > 0.0) {
        let j = hit.normal * l as f32;
        match hit.single() {
            Some(i) => impulses.push((i, j)),
            None => impulses.extend(hit.parts().map(|(i, w)| (i, w * j))),
        }
    }
    move_soft(n, factor, &impulses, h);
    // A node's contact acts where the node now is; a face's, at the body's surface point.
    for (hit, &l) in hits.iter().zip(&lambda).filter(|(_, l)| **l > 0.0) {
        side.take(hit.on_body(n), -hit.normal * l as f32);
    }
    // Friction hit by hit, capped by each one's normal impulse.
    for (hit, &l) in hits.iter().zip(&lambda) {
        if l <= 0.0 {
            continue;
        }
        let p = hit.on_body(n);
        let rel = hit.velocity(n) - side.point_velocity(p);
        let tangent = rel - rel.dot(hit.normal) * hit.normal;
        let speed = tangent.length();
        if speed == 0.0 {
            continue;
        }
        let dir = tangent / speed;
        let stop = speed / (hit.inverse_mass(n) + side.inverse_mass_along(p, dir));
        let j = -stop.min(mu * l as f32) * dir;
        hit.take(n, j);
        side.take(p, -j);
    }
}

fn row_of(hit: &Hit) -> Row {
    let mut parts = [(0, 0.0); 3];
    let mut count = 0;
    for (slot, part) in parts.iter_mut().zip(hit.parts()) {
        *slot = part;
        count += 1;
    }
    Row {
        parts,
        count,
        dir: hit.normal,
    }
}

/// Many hits on one dynamic body: the same impulses hit by hit, each with its own lumped
/// mass (no dense response), several passes so that no hit's place in the order favours it.
fn push_many(n: &mut Nodes, side: &mut RigidSide, hits: &[Hit], mu: f32, push: Push) {
    let h = push.h;
    // The push-out each overlap may have, fixed by the approach before any impulse.
    let bias: Vec<f32> = hits
        .iter()
        .map(|hit| {
            let p = hit.on_body(n);
            let approach = -(hit.velocity(n) - side.point_velocity(p)).dot(hit.normal);
            let closed = match hit.single() {
                Some(_) => push.closed(hit.overlap, approach),
                None => push.closed_gently(hit.overlap, approach),
            };
            closed / h
        })
        .collect();
    let mut normal_impulse = vec![0.0f32; hits.len()];
    let mut friction_impulse = vec![Vec3::ZERO; hits.len()];
    for _ in 0..CONTACT_PASSES.min(8) {
        for (k, hit) in hits.iter().enumerate() {
            let inv_node = hit.inverse_mass(n);
            let p = hit.on_body(n);
            let rel = hit.velocity(n) - side.point_velocity(p);
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
            hit.take(n, j);
            side.take(p, -j);
        }
    }
    // The velocities carry the hits out over the next substep; move them now as well, as the
    // coupled path does (Δx = h Δv), by the normal part.
    for (hit, &l) in hits.iter().zip(&normal_impulse) {
        for (i, w) in hit.parts() {
            n.x[i] += Vec3A::from(h * w * n.inv_mass[i] * l * hit.normal);
        }
    }
}
