//! A large group of joints solved as one system in time linear in its size: the joints that
//! form a tree over the bodies (a chain, a ragdoll, a bridge) exactly, the joints that close
//! a loop after it, each as one block.
//!
//! The system is the joints' KKT matrix rather than their effective mass A = J M⁻¹ Jᵀ:
//!
//! ```text
//! ⎡ M   Jᵀ ⎤ ⎡ x ⎤   ⎡  0 ⎤
//! ⎣ J  −E  ⎦ ⎣ λ ⎦ = ⎣ −b ⎦      gives (A + E) λ = b,
//! ```
//!
//! which is sparse in the shape of the tree: a body is a node (its velocity change, with the
//! impulses of its joints to the world or to immovable bodies folded in), a joint between two
//! moving bodies a node between them. Eliminated from the leaves to the root, each node
//! touches only its parent, so nothing fills in (Baraff, "Linear-time dynamics using Lagrange
//! multipliers", 1996). E is a regularisation of 1e-10 of the largest diagonal of A: it
//! makes the matrix quasi-definite, so every pivot block factors without pivoting, and
//! redundant rows do not stop it.

use glam::Vec3A;

use super::block::{self, Row};
use super::solve::{Accumulated, Mode, Side};

/// A node of the tree: a body, or a joint between two bodies.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// Unknowns: 6 (velocity change) plus its world joints' rows for a body; a joint's rows.
    dim: usize,
    /// The node nearer the root.
    parent: Option<usize>,
    /// A body's side index, or a joint's first row.
    item: usize,
    body: bool,
    /// Offsets in the arena: the pivot block (dim²), the coupling to the parent
    /// (dim × parent's dim, row-major) and then D⁻¹ times it, and the right-hand side.
    pivot: usize,
    coupling: usize,
    reduced: usize,
    rhs: usize,
    /// Offset in `floors`.
    floor: usize,
}

/// Working memory kept between passes.
#[derive(Debug, Default)]
pub(super) struct TreeScratch {
    nodes: Vec<Node>,
    arena: Vec<f64>,
    /// Per side: its body node, or `usize::MAX`.
    node_of: Vec<usize>,
    /// Per side: the first and one-past-last of its rows' runs in `attached`.
    runs: Vec<(usize, usize)>,
    /// Joint runs (first row, end) in `rows`: world runs per body, then links.
    world_runs: Vec<(usize, usize, usize)>,
    links: Vec<(usize, usize, usize, usize)>,
    /// Per side: the links touching it (indices into `links`).
    adjacency: Vec<Vec<usize>>,
    used: Vec<bool>,
    /// Per row: the node holding its λ and the place within the node.
    place: Vec<(usize, usize)>,
    solution: Vec<f64>,
    /// Per unknown of each node (at its `pivot`'s node order): the smallest pivot a λ row
    /// may leave and still count as independent of the rows before it (0 for a body's).
    floors: Vec<f64>,
    queue: Vec<usize>,
    single: block::Dense,
    /// The rows still held while the limits' active set is found.
    live: Vec<Row>,
    /// The sides whose adjacency `build` filled, and the bodies in row order.
    touched: Vec<usize>,
    roots: Vec<usize>,
    /// The world joints left out of the tree (a second tie to the ground closes a loop).
    grounding: Vec<(usize, usize)>,
}

const NONE: usize = usize::MAX;

/// Solves `rows` (whole joints, each joint's rows together) against `bodies` in `mode` and
/// applies the impulses, as [`block::solve`] does but in time linear in the rows when they
/// form a tree; a joint that closes a loop is solved after the tree, on its own. The limits'
/// one-sided rows are found by the same active set as there: any whose total would pull is
/// let go and the tree solved again, each round in linear time.
pub(super) fn solve(
    rows: &[Row],
    bodies: &mut [Side],
    acc: &mut [Accumulated],
    mode: Mode,
    s: &mut TreeScratch,
) {
    if rows.is_empty() {
        return;
    }
    let mut live = std::mem::take(&mut s.live);
    live.clear();
    live.extend_from_slice(rows);
    // Each round lets go of at least one row, so this ends.
    let loops = loop {
        let loops = build(&live, bodies, s);
        factor_and_solve(&live, bodies, mode, s);
        if !block::let_go_pulling(&mut live, &s.solution, acc, mode) {
            break loops;
        }
        block::release(rows, &live, bodies, acc);
    };
    block::apply(&live, &s.solution, bodies, acc, mode);
    // Joints closing a loop, each on its own against what the tree left.
    for (first, end) in loops {
        block::solve(&live[first..end], bodies, acc, mode, &mut s.single);
    }
    s.live = live;
}

/// Lays out the tree's nodes in breadth-first order from each body not yet reached; returns
/// the row runs of the joints that close a loop (left out of the tree, rows zero).
fn build(rows: &[Row], bodies: &[Side], s: &mut TreeScratch) -> Vec<(usize, usize)> {
    s.node_of.clear();
    s.node_of.resize(bodies.len(), NONE);
    s.adjacency.resize_with(bodies.len(), Vec::new);
    s.world_runs.clear();
    s.links.clear();
    // Joint runs: consecutive rows of one joint.
    let mut first = 0;
    let mut touched = std::mem::take(&mut s.touched);
    touched.clear();
    while first < rows.len() {
        let j = rows[first].joint;
        let end = first + rows[first..].iter().take_while(|r| r.joint == j).count();
        match (rows[first].a, rows[first].b) {
            (Some(a), Some(b)) if a != b => {
                for side in [a, b] {
                    if s.adjacency[side].is_empty() {
                        touched.push(side);
                    }
                    s.adjacency[side].push(s.links.len());
                }
                s.links.push((first, end, a, b));
            }
            (Some(body), _) | (None, Some(body)) => s.world_runs.push((body, first, end)),
            (None, None) => {}
        }
        first = end;
    }
    s.world_runs.sort_by_key(|&(body, first, _)| (body, first));
    s.runs.clear();
    s.runs.resize(bodies.len(), (0, 0));
    for (k, &(body, _, _)) in s.world_runs.iter().enumerate() {
        if s.runs[body].1 == 0 {
            s.runs[body].0 = k;
        }
        s.runs[body].1 = k + 1;
    }
    s.used.clear();
    s.used.resize(s.links.len(), false);
    s.grounding.clear();
    s.nodes.clear();
    s.place.clear();
    s.place.resize(rows.len(), (NONE, 0));
    // Bodies in row order, so that the roots (and the layout) follow the joints' order.
    let mut roots = std::mem::take(&mut s.roots);
    roots.clear();
    roots.extend(rows.iter().flat_map(|r| [r.a, r.b]).flatten());
    roots.dedup();
    // A body tied to the ground is its tree's root: eliminated last, its world rows see the
    // whole tree's mass. Below the root, a tie to the ground would leave the joint above it
    // only the turns that tie allows, its other rows with pivots of about E (a redundant
    // row's size), and the elimination would need 1 / E to carry them up.
    let grounded = |b: &usize| s.runs[*b].1 > s.runs[*b].0;
    let ties = roots.iter().filter(|b| grounded(b)).count();
    if ties > 0 {
        roots.sort_by_key(|b| !grounded(b));
    }
    for &root in &roots {
        if s.node_of[root] != NONE {
            continue;
        }
        // One tie to the ground per tree: a second one (a bridge hinged at both ends)
        // closes a loop through the ground, solved after the tree like any other. Inside
        // the tree it would lock some motions twice (hinges with parallel axes lock the
        // bridge's out-of-plane motion at both ends), and the bodies' reduced masses along
        // those motions grow to 1 / E, past what the elimination can carry in f64.
        let mut grounded = push_body(s, root, None, true);
        s.queue.clear();
        s.queue.push(root);
        let mut head = 0;
        while head < s.queue.len() {
            let body = s.queue[head];
            head += 1;
            for k in 0..s.adjacency[body].len() {
                let link = s.adjacency[body][k];
                let (first, end, a, b) = s.links[link];
                let other = if a == body { b } else { a };
                if s.used[link] || s.node_of[other] != NONE {
                    continue;
                }
                s.used[link] = true;
                let joint = s.nodes.len();
                s.nodes.push(Node {
                    dim: end - first,
                    parent: Some(s.node_of[body]),
                    item: first,
                    body: false,
                    pivot: 0,
                    coupling: 0,
                    reduced: 0,
                    rhs: 0,
                    floor: 0,
                });
                for (k, place) in s.place[first..end].iter_mut().enumerate() {
                    *place = (joint, k);
                }
                grounded |= push_body(s, other, Some(joint), !grounded);
                s.queue.push(other);
            }
        }
    }
    let loops = (0..s.links.len())
        .filter(|&k| !s.used[k])
        .map(|k| (s.links[k].0, s.links[k].1))
        .chain(s.grounding.drain(..))
        .collect();
    for &side in &touched {
        s.adjacency[side].clear();
    }
    (s.touched, s.roots) = (touched, roots);
    loops
}

/// Adds `side`'s body node under `parent`, with its joints to the world folded in when
/// `ground`, else set aside in `s.grounding`; returns whether it has any.
fn push_body(s: &mut TreeScratch, side: usize, parent: Option<usize>, ground: bool) -> bool {
    let node = s.nodes.len();
    s.node_of[side] = node;
    let (from, to) = s.runs[side];
    let mut dim = 6;
    for &(_, first, end) in &s.world_runs[from..to] {
        if !ground {
            s.grounding.push((first, end));
            continue;
        }
        for (k, place) in s.place[first..end].iter_mut().enumerate() {
            *place = (node, dim + k);
        }
        dim += end - first;
    }
    s.nodes.push(Node {
        dim,
        parent,
        item: side,
        body: true,
        pivot: 0,
        coupling: 0,
        reduced: 0,
        rhs: 0,
        floor: 0,
    });
    to > from
}

/// A row's Jacobian on `side` as six numbers (linear, then angular), zero if it does not
/// act on it.
fn jacobian(row: &Row, side: usize) -> [f64; 6] {
    let (lin, ang) = if row.a == Some(side) {
        (row.lin_a, row.ang_a)
    } else if row.b == Some(side) {
        (row.lin_b, row.ang_b)
    } else {
        (Vec3A::ZERO, Vec3A::ZERO)
    };
    let f = |v: Vec3A| v.to_array().map(f64::from);
    let (l, a) = (f(lin), f(ang));
    [l[0], l[1], l[2], a[0], a[1], a[2]]
}

/// The mass matrix of a side: m on the first three, the world inertia tensor on the last.
fn mass(side: &Side) -> [[f64; 6]; 6] {
    let mut m = [[0.0; 6]; 6];
    let linear = if side.inv_m > 0.0 {
        1.0 / f64::from(side.inv_m)
    } else {
        0.0
    };
    for (i, row) in m.iter_mut().take(3).enumerate() {
        row[i] = linear;
    }
    // A body whose turning is locked (inverse inertia singular) gets an inertia a 1e12 times
    // its mass about those axes, so that its block stays definite.
    let mut inv_i = side.inv_i;
    let det = inv_i.determinant();
    if !(det.is_finite() && det > 1e-30) {
        let delta = 1e-12 * (inv_i.x_axis.x + inv_i.y_axis.y + inv_i.z_axis.z + side.inv_m);
        inv_i += glam::Mat3A::from_diagonal(glam::Vec3::splat(delta.max(f32::MIN_POSITIVE)));
    }
    let det = inv_i.determinant();
    if det.is_finite() && det > 0.0 {
        let inertia = inv_i.inverse();
        for i in 0..3 {
            for j in 0..3 {
                m[3 + i][3 + j] = f64::from(inertia.col(j)[i]);
            }
        }
    }
    m
}

/// Assembles, factors and solves the tree; leaves each row's λ in `s.solution`.
fn factor_and_solve(rows: &[Row], bodies: &[Side], mode: Mode, s: &mut TreeScratch) {
    // Each row's own effective mass J M⁻¹ Jᵀ; E: 1e-10 of the largest.
    let own = |r: &Row| {
        let part = |side: Option<usize>, lin: Vec3A, ang: Vec3A| {
            side.map_or(0.0, |i| {
                let (dv, dw) = block::response(&bodies[i], lin, ang);
                lin.dot(dv) + ang.dot(dw)
            })
        };
        f64::from(part(r.a, r.lin_a, r.ang_a) + part(r.b, r.lin_b, r.ang_b))
    };
    let scale = rows.iter().map(own).fold(0.0_f64, f64::max);
    let eps = 1e-10 * scale.max(f64::MIN_POSITIVE);
    // Arena layout.
    let (mut size, mut floors) = (0, 0);
    for i in 0..s.nodes.len() {
        let parent_dim = s.nodes[i].parent.map_or(0, |p| s.nodes[p].dim);
        let n = s.nodes[i].dim;
        let node = &mut s.nodes[i];
        node.pivot = size;
        node.coupling = node.pivot + n * n;
        node.reduced = node.coupling + n * parent_dim;
        node.rhs = node.reduced + n * parent_dim;
        size = node.rhs + n;
        node.floor = floors;
        floors += n;
    }
    s.arena.clear();
    s.arena.resize(size, 0.0);
    s.floors.clear();
    s.floors.resize(floors, 0.0);
    // The λ unknowns: −E on the diagonal, the right-hand side, and for a body's own rows
    // (its joints to immovable sides) their Jacobians on it.
    for (row, &(owner, at)) in rows.iter().zip(&s.place) {
        if owner == NONE {
            continue;
        }
        let node = s.nodes[owner];
        let n = node.dim;
        let arena = &mut s.arena;
        arena[node.pivot + at * n + at] = -eps;
        arena[node.rhs + at] = -block::target(row, bodies, mode);
        s.floors[node.floor + at] = block::redundancy_floor(eps);
        if node.body {
            for (c, &v) in jacobian(row, node.item).iter().enumerate() {
                arena[node.pivot + at * n + c] = v;
                arena[node.pivot + c * n + at] = v;
            }
        }
    }
    // The bodies' masses and the couplings to the parents.
    for i in 0..s.nodes.len() {
        let node = s.nodes[i];
        let n = node.dim;
        let arena = &mut s.arena;
        if node.body {
            let m = mass(&bodies[node.item]);
            for (r, row) in m.iter().enumerate() {
                arena[node.pivot + r * n..node.pivot + r * n + 6].copy_from_slice(row);
            }
        }
        let Some(p) = node.parent else { continue };
        let parent = s.nodes[p];
        let np = parent.dim;
        if node.body {
            // A body under a joint: the joint's Jacobian on it, transposed.
            for k in 0..np {
                let j = jacobian(&rows[parent.item + k], node.item);
                for (c, &v) in j.iter().enumerate() {
                    arena[node.coupling + c * np + k] = v;
                }
            }
        } else {
            // A joint under a body: its Jacobian on that body.
            for k in 0..n {
                let j = jacobian(&rows[node.item + k], parent.item);
                arena[node.coupling + k * np..node.coupling + k * np + 6].copy_from_slice(&j);
            }
        }
    }
    // Factor from the leaves up: D_i = H_ii − Σ children Cᵀ D_c⁻¹ C; R_i = D_i⁻¹ C_i.
    for i in (0..s.nodes.len()).rev() {
        let node = s.nodes[i];
        let n = node.dim;
        let (head, tail) = s.arena.split_at_mut(node.coupling);
        let pivot = &mut head[node.pivot..];
        ldl_factor(pivot, n, &s.floors[node.floor..node.floor + n]);
        let Some(p) = node.parent else { continue };
        let np = s.nodes[p].dim;
        let (coupling, rest) = tail.split_at_mut(n * np);
        let reduced = &mut rest[..n * np];
        reduced.copy_from_slice(coupling);
        for c in 0..np {
            ldl_solve_column(pivot, n, reduced, np, c);
        }
        // The parent's pivot block loses Cᵀ R, its right-hand side Rᵀ z_i (the parent comes
        // earlier in the arena).
        let (parent_pivot, parent_rhs) = (s.nodes[p].pivot, s.nodes[p].rhs);
        let (before, after) = s.arena.split_at_mut(node.coupling);
        let after = &after[..];
        let coupling = &after[..n * np];
        let reduced = &after[n * np..2 * n * np];
        let z = &after[2 * n * np..2 * n * np + n];
        let block = &mut before[parent_pivot..parent_pivot + np * np];
        for r in 0..np {
            for c in r..np {
                let mut sum = 0.0;
                for k in 0..n {
                    sum += coupling[k * np + r] * reduced[k * np + c];
                }
                block[r * np + c] -= sum;
                if c != r {
                    block[c * np + r] -= sum;
                }
            }
        }
        for r in 0..np {
            let mut sum = 0.0;
            for k in 0..n {
                sum += reduced[k * np + r] * z[k];
            }
            before[parent_rhs + r] -= sum;
        }
    }
    // Back substitution from the root: y_i = D_i⁻¹ z_i − R_i y_parent.
    for i in 0..s.nodes.len() {
        let node = s.nodes[i];
        let n = node.dim;
        let (head, tail) = s.arena.split_at_mut(node.rhs);
        let y = &mut tail[..n];
        ldl_solve_column(&head[node.pivot..node.pivot + n * n], n, y, 1, 0);
        if let Some(p) = node.parent {
            let parent = s.nodes[p];
            let np = parent.dim;
            for r in 0..n {
                let mut sum = 0.0;
                for k in 0..np {
                    sum += head[node.reduced + r * np + k] * head[parent.rhs + k];
                }
                y[r] -= sum;
            }
        }
    }
    s.solution.clear();
    s.solution.extend(s.place.iter().map(|&(node, at)| {
        // A loop's rows (no node) and a failed solve give NaN, which `apply` skips.
        if node == NONE {
            f64::NAN
        } else {
            s.arena[s.nodes[node].rhs + at]
        }
    }));
}

/// Factors the symmetric n × n block `a` (row-major) in place as L D Lᵀ without pivoting:
/// D on the diagonal, L below it. Quasi-definite blocks always factor this way.
///
/// A λ row whose pivot is within its `floor` of zero depends on the rows before it (a loop
/// of hinges with parallel axes locks its out-of-plane motion twice): it is left out, its
/// λ zero. Kept, its pivot would be −E, and any mismatch between the rows it repeats
/// (rounding) would come back as an impulse 1 / E = 10¹⁰ times larger that moves nothing
/// but builds up in the warm start until the rounding of it moves everything.
fn ldl_factor(a: &mut [f64], n: usize, floor: &[f64]) {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            if a[k * n + k].is_finite() {
                d -= a[j * n + k] * a[j * n + k] * a[k * n + k];
            }
        }
        if floor[j] > 0.0 && (d.is_nan() || d.abs() <= floor[j]) {
            a[j * n + j] = f64::NEG_INFINITY;
            for i in j + 1..n {
                a[i * n + j] = 0.0;
            }
            continue;
        }
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for k in 0..j {
                if a[k * n + k].is_finite() {
                    v -= a[i * n + k] * a[j * n + k] * a[k * n + k];
                }
            }
            a[i * n + j] = v / d;
        }
    }
}

/// Solves L D Lᵀ x = b for column `c` of the n × `width` row-major `b`, in place.
fn ldl_solve_column(a: &[f64], n: usize, b: &mut [f64], width: usize, c: usize) {
    for i in 0..n {
        let mut v = b[i * width + c];
        for k in 0..i {
            v -= a[i * n + k] * b[k * width + c];
        }
        b[i * width + c] = v;
    }
    for i in 0..n {
        b[i * width + c] /= a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i * width + c];
        for k in i + 1..n {
            v -= a[k * n + i] * b[k * width + c];
        }
        b[i * width + c] = v;
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat3A, Quat, Vec3};

    use super::super::solve::{Angular, Rows};
    use super::*;

    fn body(x: Vec3A, inv_m: f32, spin: Vec3A) -> Side {
        Side {
            x,
            q: Quat::from_rotation_y(0.3 * x.x),
            inv_m,
            inv_i: Mat3A::from_diagonal(Vec3::new(6.0, 4.0, 9.0) * inv_m),
            w: spin,
            v: Vec3A::new(0.1 * x.y, -x.x, 0.5),
            moves: true,
            ..Side::WORLD
        }
    }

    /// A torso (0) with a head welded on (1), two arms on ball joints (2, 3), a forearm on a
    /// hinge (4) and the torso hung from the world: a tree of 5 joints to moving bodies and
    /// one to the world, 26 rows. Optionally a sixth joint from the forearm back to the
    /// torso, which closes a loop.
    fn ragdoll(with_loop: bool) -> (Vec<Side>, Vec<Row>) {
        ragdoll_with(with_loop, None)
    }

    /// [`ragdoll`], its left arm's ball joint twisting 0.1..0.2 rad about x (past its lower
    /// stop) and its forearm's hinge turning ±0.3 rad, their limits' rows included with
    /// `limits`' impulses.
    fn ragdoll_with(with_loop: bool, limits: Option<&[Accumulated]>) -> (Vec<Side>, Vec<Row>) {
        let sides = vec![
            Side::WORLD,
            body(Vec3A::ZERO, 0.1, Vec3A::new(0.2, 0.0, 0.1)),
            body(Vec3A::new(0.0, 0.6, 0.0), 0.5, Vec3A::new(3.0, 1.0, 0.0)),
            body(Vec3A::new(0.5, 0.2, 0.0), 1.0, Vec3A::new(0.0, 0.0, -2.0)),
            body(Vec3A::new(-0.5, 0.2, 0.0), 1.0, Vec3A::ZERO),
            body(Vec3A::new(0.9, 0.2, 0.0), 2.0, Vec3A::new(0.0, 5.0, 1.0)),
        ];
        let ball = |a: Vec3A, b: Vec3A| Rows::ball(a, b);
        let joints = [
            (
                0,
                1,
                ball(Vec3A::new(0.0, 1.0, 0.0), Vec3A::new(0.0, 0.3, 0.0)),
            ),
            (
                1,
                2,
                Rows {
                    angular: Angular::Weld {
                        relative: Quat::IDENTITY,
                    },
                    ..ball(Vec3A::new(0.0, 0.3, 0.0), Vec3A::new(0.0, -0.3, 0.0))
                },
            ),
            (
                1,
                3,
                ball(Vec3A::new(0.25, 0.2, 0.0), Vec3A::new(-0.25, 0.0, 0.0)),
            ),
            (
                1,
                4,
                ball(Vec3A::new(-0.25, 0.2, 0.0), Vec3A::new(0.25, 0.0, 0.0)),
            ),
            (
                3,
                5,
                Rows {
                    angular: Angular::Hinge {
                        axis_a: Vec3::Z,
                        axis_b: Vec3::Z,
                    },
                    ..ball(Vec3A::new(0.2, 0.0, 0.0), Vec3A::new(-0.2, 0.0, 0.0))
                },
            ),
            (
                5,
                1,
                ball(Vec3A::new(0.1, -0.2, 0.0), Vec3A::new(0.9, -0.1, 0.0)),
            ),
        ];
        let mut rows = Vec::new();
        let count = if with_loop {
            joints.len()
        } else {
            joints.len() - 1
        };
        for (j, (a, b, geometry)) in joints.iter().take(count).enumerate() {
            let side = |i: usize| ((i > 0).then_some(i), &sides[i]);
            let mut geometry = *geometry;
            if limits.is_some() && j == 2 {
                geometry.axial.axis = Some(super::super::solve::Axis::Twist {
                    axis_a: Vec3::X,
                    axis_b: Vec3::X,
                });
                geometry.axial.limits = Some((0.1, 0.2));
            }
            if limits.is_some() && j == 4 {
                geometry.axial.axis = Some(super::super::solve::Axis::Turn {
                    axis_a: Vec3::Z,
                    axis_b: Vec3::Z,
                });
                geometry.axial.limits = Some((-0.3, 0.3));
            }
            let held = limits.map(|acc| (1.0 / 240.0, &acc[j]));
            block::joint_rows(j, &geometry, side(*a), side(*b), held, &mut rows);
        }
        (sides, rows)
    }

    /// Solves `rows` densely (into `acc`) and as a tree (into a copy, returned), and checks
    /// that both leave the bodies with the same velocities.
    fn both_ways(
        rows: &[Row],
        sides: &[Side],
        acc: &mut [Accumulated],
        mode: Mode,
    ) -> Vec<Accumulated> {
        let (mut dense, mut sparse) = (sides.to_vec(), sides.to_vec());
        let mut acc_sparse = acc.to_vec();
        block::solve(rows, &mut dense, acc, mode, &mut block::Dense::default());
        solve(
            rows,
            &mut sparse,
            &mut acc_sparse,
            mode,
            &mut TreeScratch::default(),
        );
        for (d, s) in dense.iter().zip(&sparse) {
            assert!((d.v - s.v).length() < 1e-4, "{} against {}", s.v, d.v);
            assert!((d.w - s.w).length() < 1e-4, "{} against {}", s.w, d.w);
        }
        acc_sparse
    }

    #[test]
    fn a_tree_with_limits_finds_the_dense_systems_active_set() {
        // The twist past its stop keeps pushing; the hinge, far from its stop, lets go of
        // what it held: the tree finds the same active set as the dense system.
        for (lower, upper) in [(0.5, 0.0), (0.0, 0.0), (2.0, 0.0)] {
            let mut acc = vec![Accumulated::default(); 5];
            acc[2].lower = lower;
            acc[2].upper = upper;
            acc[4].upper = 0.3;
            let (sides, rows) = ragdoll_with(false, Some(&acc));
            assert!(rows.iter().filter(|r| r.held.one_sided()).count() == 2);
            let acc_sparse = both_ways(&rows, &sides, &mut acc, Mode::RIGID);
            for (d, s) in acc.iter().zip(&acc_sparse) {
                for (x, y) in [(d.lower, s.lower), (d.upper, s.upper)] {
                    assert!(
                        x >= 0.0 && (x - y).abs() < 1e-4 * (1.0 + x),
                        "{x} against {y}"
                    );
                }
            }
            assert!(acc[2].lower > 0.0 && acc[4].upper == 0.0, "{acc:?}");
        }
    }

    #[test]
    fn a_tree_is_solved_as_the_dense_system_solves_it() {
        let (sides, rows) = ragdoll(false);
        assert_eq!(rows.len(), 3 + 6 + 3 + 3 + 5);
        for mode in [
            Mode::RIGID,
            Mode {
                bias_rate: 30.0,
                mass_scale: 0.8,
                impulse_scale: 0.2,
            },
        ] {
            let mut acc = vec![
                Accumulated {
                    linear: Vec3A::X,
                    ..Default::default()
                };
                5
            ];
            let acc_sparse = both_ways(&rows, &sides, &mut acc, mode);
            for (d, s) in acc.iter().zip(&acc_sparse) {
                assert!((d.linear - s.linear).length() < 1e-4 * (1.0 + d.linear.length()));
                assert!((d.angular - s.angular).length() < 1e-4 * (1.0 + d.angular.length()));
            }
        }
    }

    #[test]
    fn a_loop_is_closed_after_the_tree_and_repeated_passes_converge() {
        let (mut sides, rows) = ragdoll(true);
        let mut acc = vec![Accumulated::default(); 6];
        let mut scratch = TreeScratch::default();
        let speed = |sides: &[Side]| {
            rows.iter()
                .map(|r| {
                    let part = |b: Option<usize>, l: Vec3A, a: Vec3A| {
                        b.map_or(0.0, |s| l.dot(sides[s].v) + a.dot(sides[s].w))
                    };
                    (part(r.a, r.lin_a, r.ang_a) + part(r.b, r.lin_b, r.ang_b)).abs()
                })
                .fold(0.0_f32, f32::max)
        };
        let before = speed(&sides);
        solve(&rows, &mut sides, &mut acc, Mode::RIGID, &mut scratch);
        let once = speed(&sides);
        for _ in 0..30 {
            solve(&rows, &mut sides, &mut acc, Mode::RIGID, &mut scratch);
        }
        let after = speed(&sides);
        // Block Gauss–Seidel between the tree and the loop's joint: measured 5 → 0.64 → 0.026.
        assert!(
            once < 0.2 * before && after < 0.01 * before,
            "{before} → {once} → {after}"
        );
    }
}
