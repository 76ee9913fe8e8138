//! Which of a manifold's points the solver takes, and in what order.

use glam::{Vec3, Vec3A};

use crate::collision::narrow_phase::{ContactImpulse, Manifold};

/// Most points a manifold keeps for the solver: four span any convex contact patch, and
/// parry's face–face clipping can give eight (a box resting squarely on another), which
/// doubles the work for no better support.
pub(crate) const MAX_POINTS: usize = 4;

/// Chooses the points of `m` the solver takes (see [`keep_points`]) and records them in its
/// data. Called when its points are found: a reused manifold keeps the choice.
pub(crate) fn choose_points(m: &mut Manifold, scratch: &mut Vec<(Vec3A, f32, bool)>) {
    scratch.clear();
    scratch.extend(m.points.iter().map(|p| {
        let warm = p.data != ContactImpulse::default();
        (Vec3A::from(p.local_p1), p.dist, warm)
    }));
    // The choice only measures distances in the contact plane, so it is made in the first
    // shape's (or part's) frame.
    let (mut keep, count) = keep_points(scratch, Vec3A::from(m.local_n1));
    solve_order(&mut keep[..count], m);
    for (k, &i) in m.data.kept.iter_mut().zip(&keep[..count]) {
        // parry's manifolds hold far fewer than 256 points.
        *k = i as u8;
    }
    m.data.kept_len = count as u8;
    m.data.frozen.stale = true;
}

/// What [`choose_points`] reads of a manifold of at most [`MAX_POINTS`] points: its
/// normal and its points, in the first shape's frame. A manifold that parry updated in
/// place (its points kept, only their separations refreshed) has the same key, and its
/// choice would come out the same: all its points, in the same order.
#[derive(Clone, Copy, PartialEq)]
pub(crate) struct PointsKey {
    n: Vec3,
    points: [Vec3; MAX_POINTS],
    count: usize,
}

impl PointsKey {
    /// The key of a single manifold of at most [`MAX_POINTS`] points; `None` for anything
    /// else, whose choice also depends on the points' depths.
    #[must_use]
    pub fn of(manifolds: &[Manifold]) -> Option<Self> {
        let [m] = manifolds else { return None };
        (m.points.len() <= MAX_POINTS).then(|| {
            let mut points = [Vec3::ZERO; MAX_POINTS];
            for (k, p) in points.iter_mut().zip(&m.points) {
                *k = p.local_p1;
            }
            Self {
                n: m.local_n1,
                points,
                count: m.points.len(),
            }
        })
    }
}

/// [`choose_points`] for each of `manifolds`, unless `before` (their key before parry's
/// update) shows the one manifold kept its points: the choice then stands, and only its
/// frozen geometry is marked for the solver to check.
pub(crate) fn choose_changed_points(
    manifolds: &mut [Manifold],
    before: Option<PointsKey>,
    scratch: &mut Vec<(Vec3A, f32, bool)>,
) {
    if before.is_some() && before == PointsKey::of(manifolds) {
        for m in manifolds {
            m.data.frozen.stale = true;
        }
        return;
    }
    for m in manifolds {
        choose_points(m, scratch);
    }
}

/// Puts the kept points of `m` in the order the solver visits them: around their centre,
/// counterclockwise in the contact plane, from the same direction of that plane every time.
///
/// Why: the order decides which way a pass leaves a face contact tilted (the corners solved
/// first take more of the impulse). parry lists a clipped face's corners around it, but
/// from a vertex that differs from one pair to the next, so each joint of a column tilted
/// its own way, and the tilts grew into buckling: a column of 100 unit boxes fell at the
/// defaults, and with every box moved up to 0.1 mm sideways none of 8 stood. Started from
/// the same direction, every joint tilts alike, the column leans a little as a whole and
/// stands (8 of 8 with those offsets, each top 0.16 m off the axis; 5 of 8 columns of 150;
/// with the compression tolerance of [`FrozenGeometry`]). Sorted along one axis and then
/// the other instead (as rapier 0.36 does), the corners were no longer taken around the
/// face: a cube landing flat slid and tipped, and the symmetric relax sweep (see the
/// solver) lost its point.
///
/// [`FrozenGeometry`]: crate::collision::narrow_phase::FrozenGeometry
fn solve_order(keep: &mut [usize], m: &Manifold) {
    if keep.len() < 2 {
        return;
    }
    let (u, v) = m.local_n1.any_orthonormal_pair();
    let n = keep.len() as f32;
    let centre = keep.iter().map(|&i| m.points[i].local_p1).sum::<Vec3>() / n;
    // One angle per point, not two per comparison.
    let mut by_angle = [(0.0f32, 0usize); MAX_POINTS];
    let by_angle = &mut by_angle[..keep.len()];
    for (slot, &i) in by_angle.iter_mut().zip(keep.iter()) {
        let d = m.points[i].local_p1 - centre;
        *slot = (d.dot(v).atan2(d.dot(u)), i);
    }
    by_angle.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    for (k, &(_, i)) in keep.iter_mut().zip(by_angle.iter()) {
        *k = i;
    }
}

/// The normal impulse of the points of `m` the solver took (N·s). The others hold what
/// parry carried over to them by feature, which may be from a step long ago.
#[must_use]
pub(crate) fn kept_normal_impulse(m: &Manifold) -> f32 {
    m.data
        .kept()
        .iter()
        .filter_map(|&k| m.points.get(usize::from(k)))
        .map(|p| p.data.normal)
        .sum()
}

/// Which of a manifold's points to solve when it has more than [`MAX_POINTS`]: the deepest,
/// the one farthest from it, the one making the largest triangle with those two, and the one
/// farthest out on the other side of their line (else the one farthest from the three).
/// `points` are (position, separation, warm); distances are measured in the contact plane
/// of normal `n`.
///
/// Face–face clipping gives each corner twice (once from each shape's features), at nearly
/// the same spot and depth, so a plain choice would flip between the copies from step to
/// step and lose the warm-start impulse each time (measured: a settled 1,000-box heap kept
/// 4 cm/s of jitter). Points that were solved last step (`warm`) win near-ties: a millimetre
/// of depth, a percent of spread. Returns the indices kept and their count.
#[must_use]
pub(crate) fn keep_points(points: &[(Vec3A, f32, bool)], n: Vec3A) -> ([usize; MAX_POINTS], usize) {
    let mut keep = [0; MAX_POINTS];
    if points.len() <= MAX_POINTS {
        for (i, k) in keep.iter_mut().enumerate().take(points.len()) {
            *k = i;
        }
        return (keep, points.len());
    }
    let pos = |i: usize| points[i].0;
    let argmax = |score: &dyn Fn(Vec3A, f32, bool) -> f32| {
        let mut best = (0, f32::NEG_INFINITY);
        for (i, &(p, d, warm)) in points.iter().enumerate() {
            let s = score(p, d, warm);
            if s > best.1 {
                best = (i, s);
            }
        }
        best
    };
    let spread = |s: f32, warm: bool| if warm { s * 1.01 } else { s };
    let (i0, _) = argmax(&|_, d, warm| if warm { 1e-3 - d } else { -d });
    let p0 = pos(i0);
    // In-plane distances: the component along n is the separation, not the spread.
    let (i1, _) = argmax(&|p, _, warm| spread((p - p0).reject_from_normalized(n).length(), warm));
    // n · ((p1 − p0) × (p − p0)) = m · (p − p0): which side of the line p0p1, and how far.
    let m = n.cross(pos(i1) - p0);
    let side = |p: Vec3A| m.dot(p - p0);
    let (i2, _) = argmax(&|p, _, warm| spread(side(p).abs(), warm));
    let sign = side(pos(i2)).signum();
    let (i3, s3) = argmax(&|p, _, warm| spread(-side(p) * sign, warm));
    let i3 = if s3 > 0.0 {
        i3
    } else {
        let chosen = [i0, i1, i2].map(pos);
        argmax(&|p, _, warm| {
            let d = chosen.map(|c| (p - c).reject_from_normalized(n).length());
            spread(d[0].min(d[1]).min(d[2]), warm)
        })
        .0
    };
    keep = [i0, i1, i2, i3];
    keep.sort_unstable();
    // Degenerate patches (all points on a line or one spot) can pick an index twice.
    let mut count = 0;
    for k in 0..MAX_POINTS {
        if k == 0 || keep[k] != keep[count - 1] {
            keep[count] = keep[k];
            count += 1;
        }
    }
    (keep, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_clipped_points_of_a_square_face_reduce_to_its_four_corners() {
        // Two coincident unit squares clipped against each other: every corner twice, the
        // second copy 1 mm less deep.
        let corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)];
        let points: Vec<(Vec3A, f32, bool)> = corners
            .iter()
            .chain(&corners)
            .enumerate()
            .map(|(i, &(x, z))| {
                (
                    Vec3A::new(x, 1.0, z),
                    if i < 4 { -0.002 } else { -0.001 },
                    false,
                )
            })
            .collect();
        let (keep, count) = keep_points(&points, Vec3A::Y);
        assert_eq!(count, 4);
        let mut kept: Vec<(i32, i32)> = keep[..count]
            .iter()
            .map(|&i| {
                let p = points[i].0 * 2.0;
                (p.x as i32, p.z as i32)
            })
            .collect();
        kept.sort_unstable();
        assert_eq!(kept, vec![(-1, -1), (-1, 1), (1, -1), (1, 1)]);
        // The deepest copies are the ones kept.
        assert!(keep[..count].iter().all(|&i| i < 4), "{keep:?}");
    }

    #[test]
    fn few_points_are_kept_as_they_are_and_a_degenerate_patch_does_not_repeat_one() {
        let p = |x: f32| (Vec3A::new(x, 0.0, 0.0), 0.0, false);
        assert_eq!(keep_points(&[p(0.0), p(1.0)], Vec3A::Y), ([0, 1, 0, 0], 2));
        // Six points on one line: both ends, no index twice.
        let line: Vec<_> = (0..6).map(|i| p(i as f32)).collect();
        let (keep, count) = keep_points(&line, Vec3A::Y);
        let kept = &keep[..count];
        assert!(kept.contains(&0) && kept.contains(&5), "{kept:?}");
        let mut unique = kept.to_vec();
        unique.dedup();
        assert_eq!(unique.len(), count);
    }

    /// A unit box face on another, clipped as parry clips it: each corner twice, once as a
    /// vertex of either box, listed around the face.
    fn clipped_face() -> Manifold {
        use parry3d::query::TrackedContact;
        use parry3d::shape::PackedFeatureId;
        let mut m = Manifold::new();
        m.local_n1 = Vec3::Y;
        let corners = [(0.5, 0.5), (-0.5, 0.5), (-0.5, -0.5), (0.5, -0.5)];
        for copy in 0..2u32 {
            for (i, &(x, z)) in corners.iter().enumerate() {
                let p = Vec3::new(x, 0.5, z);
                let fid = PackedFeatureId::vertex(copy * 4 + i as u32);
                m.points
                    .push(TrackedContact::new(p, p - Vec3::Y, fid, fid, -0.01));
            }
        }
        m
    }

    #[test]
    fn the_solver_takes_a_face_around_it_from_the_same_side_whatever_parry_listed_first() {
        let mut orders = Vec::new();
        // parry's list, and the same list started from each other corner.
        for start in 0..4 {
            let mut m = clipped_face();
            m.points.rotate_left(start);
            choose_points(&mut m, &mut Vec::new());
            let corners: Vec<Vec3> = m
                .data
                .kept()
                .iter()
                .map(|&k| m.points[usize::from(k)].local_p1)
                .collect();
            assert_eq!(corners.len(), 4);
            // Around the face: each corner shares an edge with the next.
            for (a, b) in corners.iter().zip(corners.iter().cycle().skip(1)) {
                let d = (*a - *b).abs();
                assert!(d.x < 1e-6 || d.z < 1e-6, "{corners:?}");
            }
            orders.push(corners);
        }
        assert!(orders.windows(2).all(|w| w[0] == w[1]), "{orders:?}");
    }

    #[test]
    fn a_manifold_impulse_counts_only_the_points_solved() {
        let mut m = clipped_face();
        choose_points(&mut m, &mut Vec::new());
        let kept: Vec<usize> = m.data.kept().iter().map(|&k| usize::from(k)).collect();
        // The solver wrote this step's impulses into the points it took; the others hold
        // what parry carried over from a step when they were taken.
        for (i, p) in m.points.iter_mut().enumerate() {
            p.data.normal = if kept.contains(&i) { 10.0 } else { 99.0 };
        }
        assert_eq!(kept_normal_impulse(&m), 40.0);
    }

    fn corners_kept(m: &Manifold) -> Vec<Vec3> {
        m.data
            .kept()
            .iter()
            .map(|&k| m.points[usize::from(k)].local_p1)
            .collect()
    }

    #[test]
    fn a_choice_stands_while_parry_keeps_the_points_and_is_made_again_when_they_change() {
        let mut m = clipped_face();
        m.points.truncate(4);
        m.points.rotate_left(1);
        choose_points(&mut m, &mut Vec::new());
        let chosen = corners_kept(&m);
        // parry updated the manifold in place: the same points, deeper.
        m.data.frozen.stale = false;
        let before = PointsKey::of(std::slice::from_ref(&m));
        assert!(before.is_some());
        for p in &mut m.points {
            p.dist -= 0.002;
        }
        let mut ms = [m.clone()];
        choose_changed_points(&mut ms, before, &mut Vec::new());
        let mut again = m.clone();
        choose_points(&mut again, &mut Vec::new());
        assert_eq!(ms[0].data.kept(), again.data.kept());
        assert!(
            ms[0].data.frozen.stale,
            "the solver must still check the geometry"
        );
        // parry found the points again and lists them from another corner: the old indices
        // would name other corners, so the choice is made again.
        let mut ms = [m.clone()];
        ms[0].points.rotate_left(1);
        choose_changed_points(&mut ms, before, &mut Vec::new());
        assert_eq!(corners_kept(&ms[0]), chosen);
        assert_ne!(ms[0].data.kept(), m.data.kept());
        // More points than the solver takes: their depths decide, so there is no key.
        assert!(PointsKey::of(&[clipped_face()]).is_none());
        assert!(PointsKey::of(&[]).is_none());
    }
}
