//! Narrow phase: persistent contact manifolds per pair, and the contact query API.

pub(crate) mod ccd;
pub(crate) mod decisions;
pub(crate) mod fetch;
pub(crate) mod pairs;
pub(crate) mod plugin;
pub(crate) mod points;

use bevy_ecs::prelude::*;
use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{ContactManifold, ContactManifoldsWorkspace};

use crate::collision::narrow_phase::pairs::PairTable;
use crate::collision::narrow_phase::points::{MAX_POINTS, kept_normal_impulse};

/// What each contact point carries from step to step: its accumulated normal impulse, for
/// warm starting. parry moves it to the matching point of the next step's manifold.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ContactImpulse {
    /// Normal impulse (N·s).
    pub normal: f32,
}

/// What a manifold carries from step to step: its friction impulses, for warm starting, and
/// which of its points the solver takes (chosen when its points are found, see
/// [`choose_points`](crate::collision::narrow_phase::points::choose_points)).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ManifoldData {
    /// Friction impulse at the manifold's centre (N·s, world frame).
    pub tangent: Vec3,
    /// Twist impulse about the normal (N·m·s).
    pub twist: f32,
    /// Indices of the points solved, the first `kept_len`.
    pub kept: [u8; MAX_POINTS],
    pub kept_len: u8,
    /// The solver's geometry of the manifold, taken when its points were found.
    #[serde(default)]
    pub frozen: FrozenGeometry,
}

/// A manifold's normal and lever arms as the solver takes them, fixed in the world frame
/// when the manifold's points are found and kept while it is reused (rapier 0.36 does the
/// same and calls it anchor freezing).
///
/// Why: with lever arms that turned with each body, a leaning box's contact points swung
/// against the lean and the soft contacts' tilt stiffness lost to the weight above. A column
/// of 20 unit boxes fell over in 5 s and the 50-row one-deep pyramid leaned out of its plane
/// and fell by 15 s. With the arms fixed, the separation is still measured at the turned
/// points (only the directions the impulses act along are held), and both stand (see
/// `tests/it/collision/tall_stacks.rs`). Each arm rides with its body's centre of mass.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
pub(crate) struct FrozenGeometry {
    /// Normal from the first shape to the second (world frame).
    pub n: Vec3,
    /// Per kept point, the lever arms from each body's centre of mass (m, world frame).
    pub arms: [[Vec3; 2]; MAX_POINTS],
    /// Lever arms from each centre of mass to the kept points' centre, where friction acts.
    pub centre: [Vec3; 2],
    /// Mean distance of the kept points from their centre (m): the twist friction's arm.
    pub radius: f32,
    /// How many points the arms are for (none until the solver first reads the manifold).
    pub count: u8,
    /// The manifold's points were found since: the solver takes the new geometry unless it
    /// is within [`FrozenGeometry::TOLERANCE`] of this one.
    pub stale: bool,
}

impl Default for FrozenGeometry {
    /// Nothing frozen yet, so the solver takes the manifold's geometry when it first reads it.
    fn default() -> Self {
        Self {
            n: Vec3::ZERO,
            arms: [[Vec3::ZERO; 2]; MAX_POINTS],
            centre: [Vec3::ZERO; 2],
            radius: 0.0,
            count: 0,
            stale: true,
        }
    }
}

impl FrozenGeometry {
    /// How far (m) a manifold's geometry may have moved across the normal (and how far its
    /// normal may have turned, in radians) when its points are found again before the
    /// solver takes the new one. Taking it at every full update (every 5 mm of relative
    /// motion at the defaults) turned the arms with a leaning body in steps, and a column of
    /// 50 boxes fell.
    pub const TOLERANCE: f32 = 0.02;

    /// How far (m) a point may have moved along the normal, against its bodies' centres,
    /// before the solver takes the new geometry: the soft contacts' compression. The joints
    /// of a 100-box column at the defaults compress by up to 5 cm (their points' middles
    /// move half that against each centre) as the column settles; taken anew at 2 cm, each
    /// joint at its own step, the arms of the lower joints turned the column, and it fell.
    /// Across the normal the tolerance stays 2 cm: at 5 cm every way, a box rocking on an
    /// edge pushed on arms up to 5 cm from where it touched, and kept rocking (the top
    /// three crates of a knocked-out tower, for seconds).
    pub const COMPRESSION_TOLERANCE: f32 = 0.05;

    /// `fresh` if one of its arms moved more than [`FrozenGeometry::TOLERANCE`] across
    /// the normal or more than [`FrozenGeometry::COMPRESSION_TOLERANCE`] along it, its
    /// normal turned more than [`FrozenGeometry::TOLERANCE`], or it holds a different number
    /// of points (none when nothing was frozen yet); else `self`, no longer stale.
    #[must_use]
    pub fn refresh(&self, fresh: Self) -> Self {
        let (across, along) = (Self::TOLERANCE, Self::COMPRESSION_TOLERANCE);
        let n = fresh.n;
        let close = |a: Vec3, b: Vec3| {
            let d = a - b;
            let dn = d.dot(n);
            (d - dn * n).length_squared() <= across * across && dn.abs() <= along
        };
        let turned = (self.n - fresh.n).length_squared() > across * across;
        let keep = !turned
            && self.count == fresh.count
            && self
                .arms
                .iter()
                .flatten()
                .zip(fresh.arms.iter().flatten())
                .all(|(&a, &b)| close(a, b));
        if keep {
            Self {
                stale: false,
                ..*self
            }
        } else {
            fresh
        }
    }

    /// Whether every stored value is finite (a snapshot's may not be).
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.n.is_finite()
            && self.arms.iter().flatten().all(|a| a.is_finite())
            && self.centre.iter().all(|c| c.is_finite())
            && self.radius.is_finite()
    }
}

impl ManifoldData {
    /// The indices of the points the solver takes.
    #[must_use]
    pub fn kept(&self) -> &[u8] {
        &self.kept[..usize::from(self.kept_len)]
    }
}

pub(crate) type Manifold = ContactManifold<ManifoldData, ContactImpulse>;

/// One pair's state.
pub(crate) struct PairState {
    pub manifolds: Vec<Manifold>,
    pub workspace: Option<ContactManifoldsWorkspace>,
    pub touching: bool,
    pub sensor: bool,
    /// Where the last full update ran, while its manifolds may be reused.
    pub recycle: Option<Recycle>,
    /// This step's time-of-impact manifold for a fast pair (see the `ccd` module): solved
    /// after `manifolds`, found anew every step, never warm-started. Boxed: the pair map
    /// holds every pair inline, and few are ever cast.
    pub cast: Option<Box<Manifold>>,
}

/// The relative pose and reach of a pair's last full manifold update.
///
/// Reusing a manifold is exact in what it covers as long as the pair moved little since:
/// the update looked `prediction + window` deep, a feature it did not report was at least
/// that far away, and it is still farther than the current prediction if the drift plus any
/// growth of the prediction stays within `window`. The drift bounds how far any point of
/// the second shape moved in the first shape's frame: |Δt| + 2 |sin(Δθ/2)| r for a shape
/// within r of its origin.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy)]
pub(crate) struct Recycle {
    /// The second shape's pose in the first's frame.
    pub pos12: Pose,
    /// The prediction distance asked of parry, window included (m).
    pub reach: f32,
}

impl Recycle {
    /// True when manifolds found at `self` still hold at `pos12` for a prediction of
    /// `prediction`, the second shape lying within `extent` of its origin, and the pair moved
    /// at most `window` since.
    ///
    /// The drift must stay within the window even when the prediction shrank: parry's
    /// manifold holds the closest features and their neighbours, not every feature within
    /// its reach, so a fast body that slowed down (its reach metres deep) kept points from
    /// metres back, and a box stopped short of a thin wall then went through it.
    #[must_use]
    pub fn holds(&self, pos12: &Pose, extent: f32, prediction: f32, window: f32) -> bool {
        let turn = self.pos12.rotation.inverse() * pos12.rotation;
        let drift = (pos12.translation - self.pos12.translation).length()
            + 2.0 * turn.xyz().length() * extent;
        // A reach far past today's prediction (a fast pair that slowed, or two hulls now
        // moving together) kept speculative points that can no longer close: shed them.
        drift <= window
            && drift + prediction <= self.reach
            && self.reach <= 2.0 * (prediction + window)
    }
}

impl PairState {
    pub fn new() -> Self {
        Self {
            manifolds: Vec::new(),
            workspace: None,
            touching: false,
            sensor: false,
            recycle: None,
            cast: None,
        }
    }

    /// The manifolds the solver takes: parry's, then the time-of-impact one.
    pub fn solved(&self) -> impl Iterator<Item = &Manifold> {
        self.manifolds.iter().chain(self.cast.as_deref())
    }
}

/// Every pair of colliders whose boxes overlap, with their contact manifolds. A resource:
/// read it after a step to see what touches what.
#[derive(Resource, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct Contacts {
    #[cfg_attr(feature = "bevy", reflect(ignore))]
    pub(crate) pairs: PairTable,
    /// The pairs the narrow phase found points for this step (sensors left out), in the
    /// broad phase's order: the solver's preparation takes them from here.
    #[cfg_attr(feature = "bevy", reflect(ignore))]
    pub(crate) active: Vec<ActivePair>,
    pub(crate) step: u64,
    /// Touching pairs inside islands woken this step: the broad phase skipped them while
    /// they slept, but their manifolds still hold (nothing moved).
    pub(crate) woken: Vec<(Entity, Entity)>,
    /// Pairs whose manifolds parry computed again in the last step (the others were reused).
    pub(crate) updated: usize,
}

/// A pair with points to solve, as the narrow phase hands it to the solver.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ActivePair {
    /// Its slot in the pair table.
    pub slot: u32,
    /// Its lower entity.
    pub a: Entity,
    /// Its higher entity.
    pub b: Entity,
}

/// A touching pair, as reported by [`Contacts`].
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    /// The lower entity.
    pub a: Entity,
    /// The higher entity.
    pub b: Entity,
    /// Contact points on `a`'s surface (m): in `a`'s shape frame from [`Contacts::pair`],
    /// in the world from [`Contacts::pair_in_world`].
    pub points: Vec<Vec3>,

    /// Normal from `a` to `b` of the deepest manifold.
    pub normal: Vec3,
    /// Deepest penetration (m, positive when overlapping).
    pub depth: f32,
    /// Total normal impulse of the step's last substep (N·s): the contact force times the
    /// substep, [`crate::core::time::PhysicsTime::substep_dt`]. For the whole step's
    /// impulses, summed over its substeps, see [`crate::collision::ContactReport`].
    pub normal_impulse: f32,
    /// Whether one of the two is a sensor (no impulses then).
    pub sensor: bool,
}

fn key(a: Entity, b: Entity) -> (Entity, Entity) {
    if a < b { (a, b) } else { (b, a) }
}

impl Contacts {
    /// Pairs that touch now, sorted.
    #[must_use]
    pub fn touching(&self) -> Vec<(Entity, Entity)> {
        let mut v: Vec<_> = self
            .pairs
            .iter()
            .filter(|(_, s)| s.touching)
            .map(|(k, _)| *k)
            .collect();
        v.sort_unstable();
        v
    }

    /// True when `a` and `b` touch.
    #[must_use]
    pub fn are_touching(&self, a: Entity, b: Entity) -> bool {
        self.pairs.get(&key(a, b)).is_some_and(|s| s.touching)
    }

    /// Everything about the contact between `a` and `b`, if they touch. Points are given
    /// in the frame of the lower entity's shape, so pass world poses through
    /// [`Contacts::pair_in_world`] when positions matter.
    #[must_use]
    pub fn pair(&self, a: Entity, b: Entity) -> Option<ContactPair> {
        let (ka, kb) = key(a, b);
        let s = self.pairs.get(&(ka, kb)).filter(|s| s.touching)?;
        let mut out = ContactPair {
            a: ka,
            b: kb,
            points: Vec::new(),
            normal: Vec3::ZERO,
            depth: 0.0,
            normal_impulse: 0.0,
            sensor: s.sensor,
        };
        for m in &s.manifolds {
            // A compound's manifold is in its part's frame.
            let part = m.subshape_pos1().copied().unwrap_or_default();
            out.normal_impulse += kept_normal_impulse(m);
            for p in &m.points {
                out.points.push(part * p.local_p1);
                if -p.dist > out.depth || out.normal == Vec3::ZERO {
                    out.depth = out.depth.max(-p.dist);
                    out.normal = part.rotation * m.local_n1;
                }
            }
        }
        Some(out)
    }

    /// [`Contacts::pair`] with points and normal turned into world coordinates, given the
    /// lower entity's shape pose.
    #[must_use]
    pub fn pair_in_world(
        &self,
        a: Entity,
        b: Entity,
        pose_of_lower: parry3d::math::Pose,
    ) -> Option<ContactPair> {
        let mut p = self.pair(a, b)?;
        for x in &mut p.points {
            *x = pose_of_lower * *x;
        }
        p.normal = pose_of_lower.rotation * p.normal;
        Some(p)
    }

    /// The slot and state of the pair `(a, b)` (lower entity first) if the solver has points
    /// of it to take: not a sensor pair, and some manifold with points.
    pub(crate) fn solvable(&self, a: Entity, b: Entity) -> Option<(u32, &PairState)> {
        let slot = self.pairs.slot(&(a, b))?;
        let state = self.pairs.at(slot)?;
        (!state.sensor && state.solved().any(|m| !m.points.is_empty())).then_some((slot, state))
    }

    /// Pairs whose boxes overlap (touching or not).
    #[must_use]
    pub fn pairs_len(&self) -> usize {
        self.pairs.len()
    }

    /// Manifolds and contact points (touching or speculative) over all pairs.
    #[must_use]
    pub fn manifold_stats(&self) -> (usize, usize) {
        let m = self.pairs.values().map(|s| s.manifolds.len()).sum();
        let p = self
            .pairs
            .values()
            .flat_map(|s| &s.manifolds)
            .map(|m| m.points.len())
            .sum();
        (m, p)
    }

    /// Pairs whose manifolds were computed again in the last step; the other pairs moved
    /// less than [`crate::collision::ContactSettings::recycle_distance`] and kept theirs.
    #[must_use]
    pub fn updated_last_step(&self) -> usize {
        self.updated
    }

    /// Number of touching pairs.
    #[must_use]
    pub fn touching_count(&self) -> usize {
        self.pairs.values().filter(|s| s.touching).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drift_bound_covers_every_point_of_the_moved_shape_and_no_more() {
        let half = Vec3::new(0.5, 0.3, 0.2);
        let extent = half.length();
        let then = Pose::from_parts(Vec3::new(0.0, 1.0, 0.0), glam::Quat::IDENTITY);
        let now = Pose::from_parts(
            Vec3::new(0.001, 1.0, -0.002),
            glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.004),
        );
        // The farthest any corner of the box moved, measured.
        let mut moved = 0.0f32;
        for i in 0..8 {
            let c = half
                * Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
            moved = moved.max((now * c - then * c).length());
        }
        let bound = (now.translation - then.translation).length() + 2.0 * (0.002f32).sin() * extent;
        assert!(
            moved <= bound + 1e-6 && bound < 1.2 * moved,
            "{moved} vs {bound}"
        );
        let prediction = 0.02;
        let reach = |slack: f32| Recycle {
            pos12: then,
            reach: prediction + bound + slack,
        };
        let window = bound + 1e-5;
        assert!(reach(1e-5).holds(&now, extent, prediction, window));
        assert!(!reach(-1e-5).holds(&now, extent, prediction, window));
        // A faster pair asks for a deeper prediction, which the old search may not cover.
        assert!(!reach(1e-5).holds(&now, extent, prediction + 2e-5, window));
        // A pair that slowed down has a reach deeper than it needs now, but its manifold
        // holds the closest features of then, not every feature within that reach: past
        // the window it is found again.
        assert!(!reach(10.0).holds(&now, extent, prediction, bound - 1e-5));
    }

    fn geometry(shift: f32, count: u8) -> FrozenGeometry {
        let mut g = FrozenGeometry {
            n: Vec3::Y,
            count,
            stale: false,
            ..FrozenGeometry::default()
        };
        for (i, arms) in g.arms.iter_mut().take(usize::from(count)).enumerate() {
            let x = if i % 2 == 0 { -0.5 } else { 0.5 } + shift;
            *arms = [Vec3::new(x, 0.5, 0.5), Vec3::new(x, -0.5, 0.5)];
        }
        g
    }

    #[test]
    fn frozen_geometry_is_kept_through_small_moves_and_retaken_past_the_tolerance() {
        let old = FrozenGeometry {
            stale: true,
            ..geometry(0.0, 4)
        };
        let tol = FrozenGeometry::TOLERANCE;
        let kept = old.refresh(geometry(0.75 * tol, 4));
        assert_eq!(kept.arms, old.arms);
        assert!(!kept.stale && kept.count == 4);
        let moved = geometry(1.25 * tol, 4);
        assert_eq!(old.refresh(moved), moved);
        // A point more or fewer, a turned normal, or nothing frozen yet: the new geometry.
        assert_eq!(old.refresh(geometry(0.0, 3)), geometry(0.0, 3));
        let turned = FrozenGeometry {
            n: Vec3::new(1.5 * tol, 1.0, 0.0).normalize(),
            ..geometry(0.0, 4)
        };
        assert_eq!(old.refresh(turned), turned);
        assert_eq!(FrozenGeometry::default().refresh(moved), moved);
    }

    #[test]
    fn frozen_geometry_is_kept_through_a_compression_deeper_than_the_tolerance_across() {
        let old = geometry(0.0, 4);
        // Along the normal (y), as a settling column's contacts compress.
        let along = |d: f32| {
            let mut g = geometry(0.0, 4);
            for arms in &mut g.arms {
                arms[0].y -= d;
                arms[1].y += d;
            }
            g
        };
        let (tol, deep) = (
            FrozenGeometry::TOLERANCE,
            FrozenGeometry::COMPRESSION_TOLERANCE,
        );
        assert!(deep > 2.0 * tol);
        assert_eq!(old.refresh(along(2.0 * tol)).arms, old.arms);
        let pressed = along(1.25 * deep);
        assert_eq!(old.refresh(pressed), pressed);
    }
}

/// One pair's state as a snapshot holds it (see [`crate::snapshot`]).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct PairRecord {
    a: Entity,
    b: Entity,
    manifolds: Vec<Manifold>,
    workspace: Option<ContactManifoldsWorkspace>,
    touching: bool,
    sensor: bool,
    seen: u64,
    recycle: Option<Recycle>,
    cast: Option<Manifold>,
}

/// [`Contacts`] as a snapshot holds it: the pairs in key order, so that the same contacts
/// always write the same bytes.
#[derive(Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct ContactsRecord {
    pairs: Vec<PairRecord>,
    step: u64,
    woken: Vec<(Entity, Entity)>,
}

impl ContactsRecord {
    /// Renames every entity through `f` and puts the pairs back in key order (for a digest
    /// that does not depend on entity ids).
    pub(crate) fn rename(&mut self, f: impl Fn(Entity) -> Entity) {
        for p in &mut self.pairs {
            (p.a, p.b) = (f(p.a), f(p.b));
        }
        for w in &mut self.woken {
            *w = (f(w.0), f(w.1));
        }
        self.pairs.sort_by_key(|p| (p.a, p.b));
        self.woken.sort_unstable();
    }
}

/// Whether every point a manifold's data names is one of its points (the solver indexes by
/// them).
fn kept_in_range(m: &Manifold) -> bool {
    usize::from(m.data.kept_len) <= MAX_POINTS
        && m.data
            .kept()
            .iter()
            .all(|&k| usize::from(k) < m.points.len())
}

impl Contacts {
    /// The pairs and their warm-start impulses, for a snapshot.
    pub(crate) fn to_record(&self) -> ContactsRecord {
        let mut pairs: Vec<PairRecord> = self
            .pairs
            .iter_seen()
            .map(|(&(a, b), s, seen)| PairRecord {
                a,
                b,
                seen,
                manifolds: s.manifolds.clone(),
                workspace: s.workspace.clone(),
                touching: s.touching,
                sensor: s.sensor,
                recycle: s.recycle,
                cast: s.cast.as_deref().cloned(),
            })
            .collect();
        pairs.sort_unstable_by_key(|p| (p.a, p.b));
        ContactsRecord {
            pairs,
            step: self.step,
            woken: self.woken.clone(),
        }
    }

    /// Contacts from a snapshot, their entities mapped by `map`. `Err` names an entity the
    /// map does not know, or (`None`) a manifold whose data points past its points.
    pub(crate) fn from_record(
        record: ContactsRecord,
        map: impl Fn(Entity) -> Option<Entity>,
    ) -> Result<Self, Option<Entity>> {
        let both = |(a, b): (Entity, Entity)| {
            Ok::<_, Option<Entity>>(key(map(a).ok_or(Some(a))?, map(b).ok_or(Some(b))?))
        };
        let mut pairs = PairTable::default();
        for mut p in record.pairs {
            if !p.manifolds.iter().chain(&p.cast).all(kept_in_range) {
                return Err(None);
            }
            // Geometry a snapshot holds that is not finite is taken again from the poses.
            for m in p.manifolds.iter_mut().chain(p.cast.as_mut()) {
                if !m.data.frozen.is_finite() {
                    m.data.frozen = FrozenGeometry::default();
                }
            }
            let k = both((p.a, p.b))?;
            pairs.insert(
                k,
                PairState {
                    manifolds: p.manifolds,
                    workspace: p.workspace,
                    touching: p.touching,
                    sensor: p.sensor,
                    recycle: p.recycle,
                    cast: p.cast.map(Box::new),
                },
                p.seen,
            );
        }
        let woken = record
            .woken
            .into_iter()
            .map(both)
            .collect::<Result<_, _>>()?;
        Ok(Self {
            pairs,
            active: Vec::new(),
            step: record.step,
            woken,
            updated: 0,
        })
    }
}
