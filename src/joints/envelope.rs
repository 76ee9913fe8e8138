//! A group of joint rows solved as one system, A x = b with A = J M⁻¹ Jᵀ their coupled
//! effective mass, by a Cholesky factorisation that stores and touches only each row's
//! envelope: its entries from the first row it shares a body with up to its diagonal.
//!
//! Rows p and q couple only through a body they both act on, so A is as sparse as the joints'
//! graph, and the factor fills in only inside the envelope (George and Liu, "Computer
//! Solution of Large Sparse Positive Definite Systems", 1981). The joints are put in reverse
//! Cuthill–McKee order ([`super::graph::order_joints`]): breadth first from a joint tied to the ground (or
//! an end of the graph), then reversed. A chain's envelope is then a band of its two
//! neighbours' rows and a tree eliminates from its leaves to its root, so neither fills in
//! past its own couplings; a loop (a bridge, a ring) adds one long row per joint closing it.
//! Factoring costs Σ (row's envelope)², about 80 operations a row for a chain instead of the
//! n³ / 3 of a dense factor.
//!
//! The limits' one-sided rows come last. Their active set is found as the dense solve finds
//! it: any whose total impulse would pull is let go and the rest solved again; a round then
//! refactors only the limits' own columns.

use super::block::{self, Row};
use super::graph::{Grouping, group_by_side};
use super::solve::{Accumulated, Mode, Side};

/// The working memory of [`solve`] for one group of rows, kept between calls: the layout of
/// its envelopes while the rows keep their sides, and the factor.
#[derive(Debug, Default)]
pub(super) struct Envelope {
    /// What the layout was made for: per row as given, its moving sides and whether it is
    /// one-sided.
    signature: Vec<(Option<usize>, Option<usize>, bool)>,
    /// Rows in solve order (indices into the rows given): equalities, then one-sided ones.
    order: Vec<usize>,
    equalities: usize,
    /// Per position: the first column of its envelope, and where that entry is in `values`.
    first: Vec<usize>,
    offset: Vec<usize>,
    /// The envelopes, row after row: A's entries, then the factor L's.
    values: Vec<f64>,
    /// The one-sided rows' envelopes as assembled, to refactor them in each round.
    tail: Vec<f64>,
    /// Per position: L's diagonal; infinite for a row left out.
    diagonal: Vec<f64>,
    /// Per position: b, then the solution x.
    x: Vec<f64>,
    /// Per position: still held (a one-sided row let go is not).
    live: Vec<bool>,
    /// (side, position, whether the row's b side is that side), grouped by side, each side's
    /// in the order of their positions.
    incidence: Vec<(usize, usize, bool)>,
    unsorted: Vec<(usize, usize, bool)>,
    groups: Grouping,
}

impl Envelope {
    /// A's entry (p, q), q ≤ p, inside p's envelope.
    #[inline]
    fn at(&self, p: usize, q: usize) -> usize {
        self.offset[p] + q - self.first[p]
    }
}

/// Solves `rows` (each joint's rows together) as one system against `bodies` in `mode`,
/// applies the impulses and adds them to the joints' accumulators `acc`. A row that no mass
/// moves or that the rows before it already hold is left out (its λ zero, see
/// [`block::redundancy_floor`]). Nothing is applied when the system has no usable pivot.
///
/// The factor is made afresh in every call: one made before the bodies' last position
/// update (about ω h off) broke a wheel spun at 100 rad/s and a kicked plank bridge, whose
/// redundant rows then no longer cancel.
pub(super) fn solve(
    rows: &[Row],
    bodies: &mut [Side],
    acc: &mut [Accumulated],
    mode: Mode,
    s: &mut Envelope,
) {
    let n = rows.len();
    if n == 0 {
        return;
    }
    lay_out(rows, s);
    let Some(eps) = assemble(rows, bodies, s) else {
        return;
    };
    s.live.clear();
    s.live.resize(n, true);
    if s.equalities < n {
        return solve_with_limits(rows, bodies, acc, mode, s, eps);
    }
    factor(s, 0, eps, block::redundancy_floor(eps));
    for (p, &i) in s.order.iter().enumerate() {
        s.x[p] = block::target(&rows[i], bodies, mode);
    }
    substitute(s);
    if !s.x.iter().all(|x| x.is_finite()) {
        return;
    }
    for (p, &i) in s.order.iter().enumerate() {
        block::apply_one(&rows[i], s.x[p], bodies, acc, mode);
    }
}

/// [`solve`] for a system with one-sided rows, assembled: their active set is found round
/// by round, each refactoring only their columns.
fn solve_with_limits(
    rows: &[Row],
    bodies: &mut [Side],
    acc: &mut [Accumulated],
    mode: Mode,
    s: &mut Envelope,
    eps: f64,
) {
    let (n, equalities) = (rows.len(), s.equalities);
    let floor = block::redundancy_floor(eps);
    let tail_from = s.offset[equalities];
    s.tail.clear();
    s.tail.extend_from_slice(&s.values[tail_from..]);
    factor(s, 0, eps, floor);
    // Each round lets go of at least one row, so this ends.
    loop {
        for (p, &i) in s.order.iter().enumerate() {
            s.x[p] = if s.live[p] {
                block::target(&rows[i], bodies, mode)
            } else {
                0.0
            };
        }
        substitute(s);
        if !s.x.iter().all(|x| x.is_finite()) {
            return;
        }
        let mut let_go = false;
        for p in equalities..n {
            let row = &rows[s.order[p]];
            if s.live[p] && block::pulls(row, s.x[p], acc, mode) {
                s.live[p] = false;
                block::let_go(row, bodies, acc);
                let_go = true;
            }
        }
        if !let_go {
            break;
        }
        // Only the one-sided rows' columns change: restore them and factor them again.
        for p in equalities..n {
            let from = s.first[p].max(equalities);
            let (at, was) = (s.at(p, from), s.at(p, from) - tail_from);
            let len = p + 1 - from;
            s.values[at..at + len].copy_from_slice(&s.tail[was..was + len]);
        }
        factor(s, equalities, eps, floor);
    }
    for (p, &i) in s.order.iter().enumerate() {
        if s.live[p] {
            block::apply_one(&rows[i], s.x[p], bodies, acc, mode);
        }
    }
}

/// Lays out the envelopes of `rows` unless they are the rows (sides and kinds) the layout
/// was made for.
fn lay_out(rows: &[Row], s: &mut Envelope) {
    let key = |r: &Row| (r.a, r.b, r.held.one_sided());
    if s.signature.len() == rows.len() && rows.iter().map(key).eq(s.signature.iter().copied()) {
        return;
    }
    s.signature.clear();
    s.signature.extend(rows.iter().map(key));
    let n = rows.len();
    s.order.clear();
    s.order
        .extend((0..n).filter(|&i| !rows[i].held.one_sided()));
    s.equalities = s.order.len();
    s.order.extend((0..n).filter(|&i| rows[i].held.one_sided()));
    s.unsorted.clear();
    for (p, &i) in s.order.iter().enumerate() {
        let r = &rows[i];
        for (side, is_b) in [(r.a, false), (r.b, true)] {
            if let Some(side) = side {
                s.unsorted.push((side, p, is_b));
            }
        }
    }
    group_by_side(&s.unsorted, |e| e.0, &mut s.groups, &mut s.incidence);
    // A row's envelope starts at the first row of any body it acts on.
    s.first.clear();
    s.first.extend(0..n);
    let mut k = 0;
    while k < s.incidence.len() {
        let side = s.incidence[k].0;
        let end = k + s.incidence[k..].iter().take_while(|e| e.0 == side).count();
        let lowest = s.incidence[k].1;
        for e in &s.incidence[k..end] {
            s.first[e.1] = s.first[e.1].min(lowest);
        }
        k = end;
    }
    s.offset.clear();
    let mut size = 0;
    for p in 0..n {
        s.offset.push(size);
        size += p + 1 - s.first[p];
    }
    s.values.resize(size, 0.0);
    s.diagonal.resize(n, 0.0);
    s.x.resize(n, 0.0);
    s.live.resize(n, true);
}

/// Assembles A into the envelopes; returns the regularisation ε (1e-10 of A's largest
/// diagonal entry), or `None` when no row has mass behind it.
fn assemble(rows: &[Row], bodies: &[Side], s: &mut Envelope) -> Option<f64> {
    let n = rows.len();
    s.values.fill(0.0);
    let jacobian = |&(_, p, is_b): &(usize, usize, bool)| {
        let r = &rows[s.order[p]];
        if is_b {
            (p, r.lin_b, r.ang_b)
        } else {
            (p, r.lin_a, r.ang_a)
        }
    };
    let mut k = 0;
    while k < s.incidence.len() {
        let side = &bodies[s.incidence[k].0];
        let end = k + s.incidence[k..]
            .iter()
            .take_while(|e| e.0 == s.incidence[k].0)
            .count();
        for u in k..end {
            let (p, lin, ang) = jacobian(&s.incidence[u]);
            let (dv, dw) = block::response(side, lin, ang);
            let (fp, op) = (s.first[p], s.offset[p]);
            for w in k..=u {
                let (q, lq, aq) = jacobian(&s.incidence[w]);
                s.values[op + q - fp] += f64::from(lq.dot(dv) + aq.dot(dw));
            }
        }
        k = end;
    }
    let scale = (0..n).map(|p| s.values[s.at(p, p)]).fold(0.0_f64, f64::max);
    (scale > 0.0 && scale.is_finite()).then_some(1e-10 * scale)
}

/// Factors A = L Lᵀ in place for the rows from `from` on, the columns before `from` of those
/// rows already factored: row by row, each entry the dot product of two envelopes. A row let
/// go, one with no mass behind it or one the rows before it already hold (its pivot at or
/// below `floor`) is left out: its diagonal infinite, so it takes no part in the rows after
/// it and its x is zero.
fn factor(s: &mut Envelope, from: usize, eps: f64, floor: f64) {
    let n = s.first.len();
    for p in from..n {
        let (fp, op) = (s.first[p], s.offset[p]);
        let len = p + 1 - fp;
        if !s.live[p] {
            s.values[op..op + len].fill(0.0);
            s.diagonal[p] = f64::INFINITY;
            continue;
        }
        let (before, row) = s.values.split_at_mut(op);
        let row = &mut row[..len];
        let (first, offset) = (&s.first[..p], &s.offset[..p]);
        for q in fp.max(from)..p {
            let (fq, oq) = (first[q], offset[q]);
            let k0 = fp.max(fq);
            let (mine, rest) = row.split_at_mut(q - fp);
            let mine = &mine[k0 - fp..];
            let theirs = &before[oq + k0 - fq..][..mine.len()];
            // Summed in order from −0.0, as `Iterator::sum` does: the bits of the factor do
            // not depend on how this loop is written.
            let mut dot = -0.0_f64;
            for (a, b) in mine.iter().zip(theirs) {
                dot += a * b;
            }
            rest[0] = (rest[0] - dot) / s.diagonal[q];
        }
        let mut own = -0.0_f64;
        for a in &row[..len - 1] {
            own += a * a;
        }
        let d = row[len - 1] + eps - own;
        s.diagonal[p] = if d.is_nan() || d <= floor {
            f64::INFINITY
        } else {
            d.sqrt()
        };
        row[len - 1] = s.diagonal[p];
    }
}

/// Solves L Lᵀ x = b in place in `s.x`.
fn substitute(s: &mut Envelope) {
    let n = s.first.len();
    for p in 0..n {
        let (fp, op) = (s.first[p], s.offset[p]);
        let row = &s.values[op..op + p - fp];
        let dot: f64 = row.iter().zip(&s.x[fp..p]).map(|(a, b)| a * b).sum();
        s.x[p] = (s.x[p] - dot) / s.diagonal[p];
    }
    for p in (0..n).rev() {
        let (fp, op) = (s.first[p], s.offset[p]);
        let x = s.x[p] / s.diagonal[p];
        s.x[p] = x;
        if x != 0.0 {
            for (k, &l) in s.values[op..op + p - fp].iter().enumerate() {
                s.x[fp + k] -= l * x;
            }
        }
    }
}
#[cfg(test)]
mod tests {
    use glam::{Mat3A, Quat, Vec3, Vec3A};

    use super::super::block::tests::relative_speed;
    use super::super::solve::{Angular, Rows};
    use super::*;

    fn body(x: Vec3A, inv_m: f32, spin: Vec3A) -> Side {
        Side {
            x,
            q: Quat::from_rotation_y(0.3 * x.x),
            inv_m: Vec3A::splat(inv_m),
            inv_i: Mat3A::from_diagonal(Vec3::new(6.0, 4.0, 9.0) * inv_m),
            w: spin,
            v: Vec3A::new(0.1 * x.y, -x.x, 0.5),
            moves: true,
            ..Side::WORLD
        }
    }

    /// A torso (0) with a head welded on (1), two arms on ball joints (2, 3), a forearm on a
    /// hinge (4) and the torso hung from the world: a tree of 5 joints to moving bodies and
    /// one to the world, 26 rows; with `with_loop` a sixth joint from the forearm back to the
    /// torso, which closes a loop. With `limits`, its left arm's ball joint twists 0.1..0.2
    /// rad about x (past its lower stop) and its forearm's hinge turns ±0.3 rad, their
    /// limits' rows included with `limits`' impulses. Its joints' rows are listed last joint
    /// first when `reversed`.
    fn ragdoll_with(
        with_loop: bool,
        limits: Option<&[Accumulated]>,
        reversed: bool,
    ) -> (Vec<Side>, Vec<Row>) {
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
        let mut listed: Vec<usize> = (0..count).collect();
        if reversed {
            listed.reverse();
        }
        for j in listed {
            let (a, b, geometry) = &joints[j];
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

    #[test]
    fn a_rigid_solve_leaves_no_relative_velocity_whatever_the_joints_order() {
        // A tree and a tree with a loop, listed in either order: one exact solve leaves every
        // anchor without relative velocity, and both orders leave the bodies alike.
        for with_loop in [false, true] {
            let mut after = Vec::new();
            for reversed in [false, true] {
                let (mut sides, rows) = ragdoll_with(with_loop, None, reversed);
                let before = relative_speed(&rows, &sides);
                let mut acc = vec![Accumulated::default(); 6];
                solve(
                    &rows,
                    &mut sides,
                    &mut acc,
                    Mode::RIGID,
                    &mut Envelope::default(),
                );
                let left = relative_speed(&rows, &sides);
                assert!(
                    before > 1.0 && left < 1e-5 * before,
                    "loop {with_loop}, reversed {reversed}: {before} -> {left}"
                );
                after.push(sides);
            }
            for (a, b) in after[0].iter().zip(&after[1]) {
                assert!((a.v - b.v).length() < 1e-4 && (a.w - b.w).length() < 1e-4);
            }
        }
    }

    #[test]
    fn limits_past_their_stop_push_and_the_others_let_go() {
        // The twist past its lower stop keeps pushing; the hinge, far from its stop, lets go
        // of what it held; every other row is held exactly, in the soft mode too.
        for (lower, upper) in [(0.5, 0.0), (0.0, 0.0), (2.0, 0.0)] {
            for mode in [
                Mode::RIGID,
                Mode {
                    bias_rate: 30.0,
                    mass_scale: 0.8,
                    impulse_scale: 0.2,
                },
            ] {
                let mut acc = vec![Accumulated::default(); 5];
                acc[2].lower = lower;
                acc[2].upper = upper;
                acc[4].upper = 0.3;
                let (mut sides, rows) = ragdoll_with(false, Some(&acc), false);
                assert_eq!(rows.iter().filter(|r| r.held.one_sided()).count(), 2);
                solve(&rows, &mut sides, &mut acc, mode, &mut Envelope::default());
                assert!(acc[2].lower > 0.0 && acc[4].upper == 0.0, "{acc:?}");
                if mode.bias_rate == 0.0 {
                    let held: Vec<Row> = rows
                        .iter()
                        .filter(|r| !(r.joint == 4 && r.held.one_sided()))
                        .copied()
                        .collect();
                    assert!(relative_speed(&held, &sides) < 1e-4);
                }
            }
        }
    }
}
