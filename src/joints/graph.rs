//! The shape of a group of joints: which joints to solve together and in what order.
//!
//! A joint joins two sides; the moving ones are the graph's nodes. [`order_joints`] puts a
//! group in the order [`super::envelope`] factors cheaply; [`split_forest`] splits a net of
//! joints (too costly as one system) into trees, each cheap to factor, and the joints that
//! close its loops.

/// Whether a group whose factorisation costs `cost` ([`order_joints`]'s estimate) and has
/// `rows` rows is solved as one system: up to what a dense system of 128 rows costs
/// (128³ / 3, 0.7 M operations: a bridge of 24 planks fits) or 1,024 a row (a chain of any
/// length: about 80). A net of joints costs far more (Box3D's joint grid of 100 × 100 balls,
/// about 360,000 a row) and is solved joint after joint.
#[must_use]
pub(super) fn affordable(cost: f64, rows: usize) -> bool {
    cost <= (128.0_f64.powi(3) / 3.0).max(1024.0 * rows as f64)
}

/// What [`group_by_side`] reuses between calls.
#[derive(Debug, Default)]
pub(super) struct Grouping {
    /// Per side: its group (`usize::MAX` when none), reset after each call.
    slot: Vec<usize>,
    /// Per group: its count, then where it starts.
    start: Vec<usize>,
    /// Per item: its group.
    group: Vec<usize>,
}

/// Copies `items` into `out` so that those of one side are together, each side's in their
/// order, and the sides in the order they first appear: a counting sort in time linear in the
/// items.
pub(super) fn group_by_side<T: Copy>(
    items: &[T],
    side: impl Fn(&T) -> usize,
    g: &mut Grouping,
    out: &mut Vec<T>,
) {
    g.start.clear();
    g.group.clear();
    for item in items.iter() {
        let i = side(item);
        if i >= g.slot.len() {
            g.slot.resize(i + 1, usize::MAX);
        }
        if g.slot[i] == usize::MAX {
            g.slot[i] = g.start.len();
            g.start.push(0);
        }
        g.group.push(g.slot[i]);
        g.start[g.slot[i]] += 1;
    }
    let mut at = 0;
    for c in &mut g.start {
        (*c, at) = (at, at + *c);
    }
    out.clear();
    out.extend_from_slice(items);
    for (item, &group) in items.iter().zip(&g.group) {
        out[g.start[group]] = *item;
        g.start[group] += 1;
    }
    for item in items.iter() {
        g.slot[side(item)] = usize::MAX;
    }
}

/// The sides a list of joints touches: (moving side, joint's place in the list), grouped by
/// side, each side's in the list's order.
#[derive(Debug, Default)]
struct Touches {
    touches: Vec<(usize, usize)>,
    unsorted: Vec<(usize, usize)>,
    groups: Grouping,
}

impl Touches {
    /// Lists what `joints` touch, `ends(j)` naming joint j's moving sides.
    fn build(&mut self, joints: &[usize], ends: impl Fn(usize) -> (Option<usize>, Option<usize>)) {
        self.unsorted.clear();
        for (k, &j) in joints.iter().enumerate() {
            let (a, b) = ends(j);
            self.unsorted
                .extend([a, b].into_iter().flatten().map(|side| (side, k)));
        }
        group_by_side(&self.unsorted, |e| e.0, &mut self.groups, &mut self.touches);
    }

    /// Each side's run in `touches`: (side, first, end).
    fn runs(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        let mut t = 0;
        std::iter::from_fn(move || {
            let &(side, _) = self.touches.get(t)?;
            let from = t;
            t += self.touches[t..].iter().take_while(|e| e.0 == side).count();
            Some((side, from, t))
        })
    }
}

/// What [`order_joints`] reuses between calls.
#[derive(Debug, Default)]
pub(super) struct Ordering {
    touches: Touches,
    /// Per joint: its two runs in `touches` (or none).
    runs: Vec<[(usize, usize); 2]>,
    degree: Vec<usize>,
    seen: Vec<bool>,
    order: Vec<usize>,
    place: Vec<usize>,
    rows_before: Vec<usize>,
    next: Vec<usize>,
}

/// Puts `joints` in reverse Cuthill–McKee order for [`solve`], where `ends(j)` names joint
/// j's moving sides and `rows(j)` counts its rows; returns the factorisation's cost
/// estimate, Σ over rows of (its envelope)². Breadth first from a joint to something that
/// does not move (the ground), the one with the fewest neighbours (or any joint with the
/// fewest), neighbours by fewest neighbours of their own, each tie by place in the list;
/// then reversed, so that the search's last rows are eliminated first.
pub(super) fn order_joints(
    joints: &mut [usize],
    ends: impl Fn(usize) -> (Option<usize>, Option<usize>),
    rows: impl Fn(usize) -> usize,
    o: &mut Ordering,
) -> f64 {
    let m = joints.len();
    o.touches.build(joints, &ends);
    o.runs.clear();
    o.runs.resize(m, [(0, 0); 2]);
    for (_, from, to) in o.touches.runs() {
        for &(_, k) in &o.touches.touches[from..to] {
            let slot = usize::from(o.runs[k][0].1 > 0);
            o.runs[k][slot] = (from, to);
        }
    }
    o.degree.clear();
    o.degree.extend(o.runs.iter().map(|r| {
        r.iter()
            .map(|&(a, b)| (b - a).saturating_sub(1))
            .sum::<usize>()
    }));
    o.seen.clear();
    o.seen.resize(m, false);
    o.order.clear();
    let grounded = |k: usize| {
        let (a, b) = ends(joints[k]);
        a.is_none() || b.is_none()
    };
    while o.order.len() < m {
        let start = (0..m)
            .filter(|&k| !o.seen[k])
            .min_by_key(|&k| (!grounded(k), o.degree[k], k))
            .unwrap_or(0);
        o.seen[start] = true;
        let mut head = o.order.len();
        o.order.push(start);
        while head < o.order.len() {
            let k = o.order[head];
            head += 1;
            o.next.clear();
            for (from, to) in o.runs[k] {
                for &(_, other) in &o.touches.touches[from..to] {
                    if !o.seen[other] {
                        o.seen[other] = true;
                        o.next.push(other);
                    }
                }
            }
            let degree = &o.degree;
            o.next.sort_unstable_by_key(|&k| (degree[k], k));
            o.order.extend_from_slice(&o.next);
        }
    }
    o.order.reverse();
    // The cost: each row's envelope reaches back to the first row of its earliest neighbour.
    o.place.clear();
    o.place.resize(m, 0);
    o.rows_before.clear();
    let mut total = 0;
    for (place, &k) in o.order.iter().enumerate() {
        o.place[k] = place;
        o.rows_before.push(total);
        total += rows(joints[k]);
    }
    let mut cost = 0.0;
    for (place, &k) in o.order.iter().enumerate() {
        let earliest = o.runs[k]
            .iter()
            .flat_map(|&(from, to)| &o.touches.touches[from..to])
            .map(|&(_, other)| o.place[other])
            .fold(place, usize::min);
        let own = rows(joints[k]);
        let reach = o.rows_before[place] + own - o.rows_before[earliest];
        cost += (own * reach * reach) as f64;
    }
    o.next.clear();
    o.next.extend(o.order.iter().map(|&k| joints[k]));
    joints.copy_from_slice(&o.next);
    cost
}

/// What [`split_forest`] reuses between calls.
#[derive(Debug, Default)]
pub(super) struct Forest {
    touches: Touches,
    /// Per side: its run in `touches` (`usize::MAX` when none), reset after each call.
    slot: Vec<usize>,
    /// Per run: its span in `touches` and its tree.
    runs: Vec<(usize, usize, usize)>,
    /// Per joint's place: its tree, or `NONE` for a joint that closes a loop.
    tree: Vec<usize>,
    queue: Vec<usize>,
    /// Per tree (and the loops last): how many joints, then where they start.
    count: Vec<usize>,
    sorted: Vec<usize>,
}

const NONE: usize = usize::MAX;

/// Splits a group of `joints` into trees and the joints that close loops: each tree grows
/// breadth first from the bodies tied to something that does not move (the ground), all at
/// once, taking every joint that reaches a body no tree has yet; the joints left close
/// loops. Reorders `joints` tree after tree (each in its joints' order), then the loops;
/// `ends` holds where each tree ends. `ends_of(j)` names joint j's moving sides.
///
/// A hanging net (Box3D's joint grid, its top row static) splits into its columns, each a
/// chain that carries its load exactly, and the joints across them.
pub(super) fn split_forest(
    joints: &mut [usize],
    ends_of: impl Fn(usize) -> (Option<usize>, Option<usize>),
    f: &mut Forest,
    ends: &mut Vec<usize>,
) {
    let m = joints.len();
    f.touches.build(joints, &ends_of);
    f.runs.clear();
    for (side, from, to) in f.touches.runs() {
        if side >= f.slot.len() {
            f.slot.resize(side + 1, NONE);
        }
        f.slot[side] = f.runs.len();
        f.runs.push((from, to, NONE));
    }
    f.tree.clear();
    f.tree.resize(m, NONE);
    let mut trees = 0;
    // The roots: every body tied to the ground, each its own tree.
    f.queue.clear();
    for (k, &j) in joints.iter().enumerate() {
        if let (Some(side), None) | (None, Some(side)) = ends_of(j) {
            let run = f.slot[side];
            if f.runs[run].2 == NONE {
                f.runs[run].2 = trees;
                trees += 1;
                f.queue.push(run);
            }
            f.tree[k] = f.runs[run].2;
        }
    }
    let mut head = 0;
    let mut seed = 0;
    loop {
        while head < f.queue.len() {
            let run = f.queue[head];
            head += 1;
            let (from, to, tree) = f.runs[run];
            for t in from..to {
                let k = f.touches.touches[t].1;
                if f.tree[k] != NONE {
                    continue;
                }
                let (a, b) = ends_of(joints[k]);
                let other = if a == Some(f.touches.touches[t].0) {
                    b
                } else {
                    a
                };
                let Some(other) = other else { continue };
                let next = f.slot[other];
                if f.runs[next].2 == NONE {
                    f.runs[next].2 = tree;
                    f.tree[k] = tree;
                    f.queue.push(next);
                }
            }
        }
        // A part of the group with no tie to the ground grows from its first body.
        while seed < f.runs.len() && f.runs[seed].2 != NONE {
            seed += 1;
        }
        if seed == f.runs.len() {
            break;
        }
        f.runs[seed].2 = trees;
        trees += 1;
        f.queue.push(seed);
    }
    for &(side, _) in &f.touches.touches {
        f.slot[side] = NONE;
    }
    // Tree after tree, the loops last, each in the list's order.
    f.count.clear();
    f.count.resize(trees + 1, 0);
    let bucket = |tree: usize| tree.min(trees);
    for &tree in &f.tree {
        f.count[bucket(tree)] += 1;
    }
    ends.clear();
    let mut at = 0;
    for c in &mut f.count {
        (*c, at) = (at, at + *c);
        ends.push(at);
    }
    ends.pop();
    f.sorted.clear();
    f.sorted.resize(m, 0);
    for (k, &tree) in f.tree.iter().enumerate() {
        let b = bucket(tree);
        f.sorted[f.count[b]] = joints[k];
        f.count[b] += 1;
    }
    joints.copy_from_slice(&f.sorted);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A net of `n` × `n` bodies hung from a static top row, as Box3D's joint grid: joint
    /// (side a, side b), moving sides only, `None` for the static row. Bodies are numbered
    /// column after column (`k * n + i`, row i from the top); joints to the body above, then
    /// to the one in the column before.
    fn net(n: usize) -> Vec<(Option<usize>, Option<usize>)> {
        let moving = |k: usize, i: usize| (i > 0).then_some(k * n + i);
        let mut joints = Vec::new();
        for k in 0..n {
            for i in 0..n {
                if i > 0 {
                    joints.push((moving(k, i - 1), moving(k, i)));
                }
                if k > 0 && i > 0 {
                    joints.push((moving(k - 1, i), moving(k, i)));
                }
            }
        }
        joints
    }

    #[test]
    fn a_chain_listed_in_any_order_is_ordered_into_a_band() {
        // 100 ball joints of a chain hung from the world, listed scrambled: the order found
        // has each joint's rows reach back only to its neighbour's, about 60 a row.
        let ends = |j: usize| ((j > 0).then(|| j - 1), Some(j));
        let mut joints: Vec<usize> = (0..100).map(|k| (k * 37) % 100).collect();
        let cost = order_joints(&mut joints, ends, |_| 3, &mut Ordering::default());
        assert!(cost < 100.0 * 300.0, "cost {cost}");
        assert!(affordable(cost, 300));
        for pair in joints.windows(2) {
            assert_eq!(pair[0].abs_diff(pair[1]), 1, "{joints:?}");
        }
        // The tie to the world is the search's start, so it is eliminated last.
        assert_eq!(joints.last(), Some(&0));
    }

    #[test]
    fn a_hanging_net_is_too_costly_whole_and_splits_into_its_columns() {
        let n = 30;
        let all = net(n);
        let ends = |j: usize| all[j];
        let mut joints: Vec<usize> = (0..all.len()).collect();
        let rows = 3 * all.len();
        let cost = order_joints(&mut joints, ends, |_| 3, &mut Ordering::default());
        assert!(!affordable(cost, rows), "cost {cost} for {rows} rows");
        let mut joints: Vec<usize> = (0..all.len()).collect();
        let mut tree_ends = Vec::new();
        split_forest(&mut joints, ends, &mut Forest::default(), &mut tree_ends);
        // A tree per column, each the column's n − 1 joints; the joints across are loops.
        assert_eq!(tree_ends.len(), n);
        let mut from = 0;
        for &to in &tree_ends {
            assert_eq!(to - from, n - 1);
            let column = |j: usize| all[j].1.unwrap() / n;
            assert!(
                joints[from..to]
                    .iter()
                    .all(|&j| column(j) == column(joints[from]))
            );
            let mut span = joints[from..to].to_vec();
            let cost = order_joints(&mut span, ends, |_| 3, &mut Ordering::default());
            assert!(affordable(cost, 3 * (n - 1)));
            from = to;
        }
        assert_eq!(joints.len() - from, (n - 1) * (n - 1));
    }
}
