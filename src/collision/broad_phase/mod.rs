//! Broad phase: an incremental sort-and-sweep over moving colliders, and a bounding volume
//! hierarchy over fixed ones.
//!
//! - **Moving** colliders (anything with a velocity) keep their order from the last step;
//!   each step their boxes are updated in place and re-sorted by insertion sort, which for
//!   coherent motion is close to O(n). The set is rebuilt (O(n log n)) only when colliders
//!   are added or removed. The sort key is (cell, min along the sweep axis): cells are
//!   slabs across a second axis, twice as thick as the largest box is along it, so a box
//!   can only overlap boxes of its own slab or the next. Sweeping slab by slab keeps a
//!   regular grid of boxes (a 10×10×10 stack) from testing every box of a whole row. A few
//!   boxes far thicker than the rest (a container around its contents) are set apart and
//!   tested against every box.
//!   The boxes are held grown a little (see the collision plugin's `run_broad_phase`), and
//!   while none of them changed the last pairs still hold and the sweep does not run.
//! - **Fixed** colliders sit in parry's BVH, rebuilt only when one of them is added, moved,
//!   reshaped or removed. Each awake moving box queries it: O(log n_fixed) per box. A fixed
//!   collider costs nothing per step while nothing about it changes.

pub(crate) mod plugin;
use bevy_ecs::prelude::*;
use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};

use crate::core::quarantine::Quarantined;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::Rotation;

use super::CollisionLayers;
use crate::collision::lanes::F4;

/// One collider's box as the broad phase sees it.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub(crate) struct Entry {
    pub entity: Entity,
    pub min: Vec3,
    pub max: Vec3,
    /// False for sleeping bodies: they pair with awake bodies only.
    pub awake: bool,
    pub layers: CollisionLayers,
    /// Slab index across the cell axis, set by the sweep.
    pub cell: i32,
}

/// The broad phase's working set and its output, kept from step to step.
#[derive(Resource)]
pub(crate) struct BroadPhase {
    /// Moving colliders, sorted along `axis`.
    pub moving: Vec<Entry>,
    /// Fixed colliders, in the order of the BVH's leaves.
    pub fixed: Vec<Entry>,
    pub fixed_tree: Bvh,
    /// Set when a fixed collider changed: the tree is rebuilt before the next query.
    pub fixed_dirty: bool,
    /// Set when moving colliders were added or removed: their list is rebuilt.
    pub moving_dirty: bool,
    pub axis: usize,
    /// The axis across which the slabs are cut.
    pub cell_axis: usize,
    /// Candidate pairs (lower entity first), sorted.
    pub pairs: Vec<(Entity, Entity)>,
    /// This step's and the last step's pairs as the sweep found them (unsorted): when they
    /// are the same, as in a scene at rest, `pairs` is too and is not sorted again.
    found: Vec<(Entity, Entity)>,
    found_before: Vec<(Entity, Entity)>,
    /// `pairs` is `found_before` sorted (false after a restore).
    pairs_from_found: bool,
    /// The pairs before the last time they were sorted again (kept for its memory).
    pairs_before: Vec<(Entity, Entity)>,
    /// The version of `pairs`: new whenever they change.
    pairs_stamp: crate::collision::slots::Stamp,
    /// The moving boxes in sweep order as six coordinate arrays, padded with empty boxes to
    /// whole lanes: the sweep tests four candidates at once.
    sweep: Sweep,
    /// The boxes' thicknesses across the slabs, reused each step to find their median.
    sizes: Vec<f32>,
}

/// Structure-of-arrays copy of the sorted moving boxes.
#[derive(Debug, Default)]
struct Sweep {
    min: [Vec<f32>; 3],
    max: [Vec<f32>; 3],
}

impl Sweep {
    fn fill(&mut self, entries: &[Entry]) {
        for k in 0..3 {
            let (min, max) = (&mut self.min[k], &mut self.max[k]);
            min.clear();
            max.clear();
            min.extend(entries.iter().map(|e| e.min[k]));
            max.extend(entries.iter().map(|e| e.max[k]));
            // An empty box (min > max) past the end: never overlaps, ends every sweep.
            min.extend([f32::INFINITY; 4]);
            max.extend([f32::NEG_INFINITY; 4]);
        }
    }

    #[inline]
    fn lanes(v: &[f32], j: usize) -> F4 {
        // One bounds check and one unaligned load (the sweep never reads past the padding).
        let four: [f32; 4] = v[j..j + 4].try_into().unwrap_or([f32::NAN; 4]);
        F4::new(four)
    }

    /// Bit l set when box j + l overlaps box i.
    #[inline]
    fn overlaps(&self, i: usize, j: usize) -> u32 {
        let mut hit = F4::splat(0.0).simd_eq(F4::splat(0.0));
        for k in 0..3 {
            let (amin, amax) = (F4::splat(self.min[k][i]), F4::splat(self.max[k][i]));
            hit &= Self::lanes(&self.min[k], j).simd_le(amax)
                & Self::lanes(&self.max[k], j).simd_ge(amin);
        }
        hit.to_bitmask()
    }
}

impl Default for BroadPhase {
    /// Both lists start out of date, so colliders spawned before the plugin are picked up.
    fn default() -> Self {
        Self {
            moving: Vec::new(),
            fixed: Vec::new(),
            fixed_tree: Bvh::new(),
            fixed_dirty: true,
            moving_dirty: true,
            axis: 0,
            cell_axis: 2,
            pairs: Vec::new(),
            found: Vec::new(),
            found_before: Vec::new(),
            pairs_from_found: false,
            pairs_before: Vec::new(),
            pairs_stamp: crate::collision::slots::Stamp::fresh(),
            sweep: Sweep::default(),
            sizes: Vec::new(),
        }
    }
}

/// Marks both lists out of date. Called from the hooks of [`super::Collider`] and
/// [`super::ColliderOf`], and from the collision plugin's observers of poses, velocities and
/// quarantines (insert: a new pose or velocity; remove: a velocity taken away makes a
/// collider static): inserts and removals are how the broad phase learns about changes
/// without scanning every collider each step.
/// Observer: a pose, velocity or quarantine was inserted on a collider's entity.
pub(crate) fn on_body_inserted(
    event: On<Insert<(Position, Rotation, LinearVelocity, Quarantined)>>,
    colliders: Query<(), With<super::Collider>>,
    bp: Option<ResMut<BroadPhase>>,
) {
    flag(event.event().entity, &colliders, bp);
}

/// Observer: a velocity, pose or quarantine was removed from a collider's entity.
pub(crate) fn on_body_removed(
    event: On<Remove<(Position, LinearVelocity, Quarantined)>>,
    colliders: Query<(), With<super::Collider>>,
    bp: Option<ResMut<BroadPhase>>,
) {
    flag(event.event().entity, &colliders, bp);
}

fn flag(
    entity: Entity,
    colliders: &Query<(), With<super::Collider>>,
    bp: Option<ResMut<BroadPhase>>,
) {
    if let Some(mut bp) = bp.filter(|_| colliders.contains(entity)) {
        bp.fixed_dirty = true;
        bp.moving_dirty = true;
    }
}

pub(crate) fn mark_dirty(world: &mut bevy_ecs::world::DeferredWorld, entity: Entity) {
    if world.get::<super::Collider>(entity).is_none() {
        return;
    }
    if let Some(mut bp) = world.get_resource_mut::<BroadPhase>() {
        bp.fixed_dirty = true;
        bp.moving_dirty = true;
    }
}

/// The axes along which box centres spread most and next most: sweeping the first and
/// cutting slabs across the second leave the fewest overlaps to test.
pub(crate) fn sweep_axes(entries: &[Entry]) -> [usize; 2] {
    let n = entries.len().max(1) as f32;
    let mean = entries.iter().map(|e| e.min + e.max).sum::<Vec3>() / (2.0 * n);
    let var = entries
        .iter()
        .map(|e| {
            let d = 0.5 * (e.min + e.max) - mean;
            d * d
        })
        .sum::<Vec3>();
    let mut axes = [0, 1, 2];
    // A stable sort: ties keep x before y before z.
    axes.sort_by(|&a, &b| var[b].total_cmp(&var[a]));
    [axes[0], axes[1]]
}

/// The slab of a box far thicker than the others (see [`assign_cells`]).
const BIG: i32 = i32::MIN;

/// Sets every entry's slab across `axis`: slabs twice as thick as the thickest box, so two
/// overlapping boxes are at most one slab apart even after rounding. Returns the widest
/// extent along `along` (the sweep axis). Far from the origin (more than a million slabs
/// out) or with no extent, everything shares one slab.
///
/// A few boxes more than eight times the median thickness (Box3D's washer drum, 20 m
/// around 8,000 cubes of 0.4 m) would make one slab of everything and a sweep in which each
/// cube meets hundreds: they go to a slab of their own, [`BIG`], sorted first, and are
/// tested against every box (a few times n). With many such boxes (more than n/32 + 8) the
/// scene has no outliers and none is set apart.
fn assign_cells(entries: &mut [Entry], sizes: &mut Vec<f32>, axis: usize, along: usize) -> f32 {
    let thickness = |e: &Entry| e.max[axis] - e.min[axis];
    sizes.clear();
    sizes.extend(entries.iter().map(thickness));
    let big = match sizes.len() {
        0 => f32::INFINITY,
        n => {
            let median = *sizes.select_nth_unstable_by(n / 2, f32::total_cmp).1;
            let cut = 8.0 * median;
            let count = sizes.iter().filter(|&&t| t > cut).count();
            if median > 0.0 && count <= n / 32 + 8 {
                cut
            } else {
                f32::INFINITY
            }
        }
    };
    let is_big = |e: &Entry| thickness(e) > big;
    let (mut thick, mut wide) = (0.0f32, 0.0f32);
    for e in entries.iter().filter(|e| !is_big(e)) {
        thick = thick.max(thickness(e));
        wide = wide.max(e.max[along] - e.min[along]);
    }
    let size = 2.0 * thick;
    // With no extent every slab index is infinite or NaN: one slab.
    let mut far = false;
    for e in entries.iter_mut() {
        let slab = e.min[axis] / size;
        far |= !slab.is_finite() || slab.abs() > 1e6;
        e.cell = if is_big(e) { BIG } else { slab.floor() as i32 };
    }
    if far {
        entries.iter_mut().for_each(|e| e.cell = 0);
        wide = entries
            .iter()
            .map(|e| e.max[along] - e.min[along])
            .fold(0.0, f32::max);
    }
    wide
}

/// The sweep order: slab, then the box's start along the sweep axis, then the entity.
fn sweep_order(a: &Entry, b: &Entry, axis: usize) -> std::cmp::Ordering {
    a.cell
        .cmp(&b.cell)
        .then(a.min[axis].total_cmp(&b.min[axis]))
        .then(a.entity.cmp(&b.entity))
}

fn key(a: Entity, b: Entity) -> (Entity, Entity) {
    if a < b { (a, b) } else { (b, a) }
}

impl BroadPhase {
    /// Pairs box `i` with the boxes `from..to` (sorted by start along the sweep axis) that
    /// start no later than `end`, four at a time.
    #[inline]
    fn sweep_run(&mut self, i: usize, from: usize, to: usize, end: f32) {
        let keys = &self.sweep.min[self.axis];
        let a = &self.moving[i];
        let mut j = from;
        while j < to && keys[j] <= end {
            let live = (1u32 << (to - j).min(4)) - 1;
            let mut hits = self.sweep.overlaps(i, j) & live;
            while hits != 0 {
                let b = &self.moving[j + hits.trailing_zeros() as usize];
                hits &= hits - 1;
                if (a.awake || b.awake) && a.layers.interacts(b.layers) {
                    self.found.push(key(a.entity, b.entity));
                }
            }
            j += 4;
        }
    }

    /// Rebuilds the fixed tree from `self.fixed` if it is out of date.
    pub fn refresh_fixed(&mut self) {
        if self.fixed_dirty {
            let leaves: Vec<Aabb> = self.fixed.iter().map(|e| Aabb::new(e.min, e.max)).collect();
            self.fixed_tree = Bvh::from_leaves(BvhBuildStrategy::default(), &leaves);
            self.fixed_dirty = false;
        }
    }

    /// The version of [`BroadPhase::pairs`]: the same as long as they did not change.
    #[must_use]
    pub fn pairs_stamp(&self) -> crate::collision::slots::Stamp {
        self.pairs_stamp
    }

    /// [`Self::find_pairs_except`] with no pair excluded.
    #[cfg(test)]
    pub fn find_pairs(&mut self) {
        self.find_pairs_except(&crate::collision::PairExclusions::default());
    }

    /// Sorts the moving boxes (insertion sort: cheap when they were nearly sorted) and
    /// collects every overlapping pair that may interact and is not in `excluded`.
    pub fn find_pairs_except(&mut self, excluded: &crate::collision::PairExclusions) {
        if self.moving_dirty {
            [self.axis, self.cell_axis] = sweep_axes(&self.moving);
        }
        let axis = self.axis;
        let wide = assign_cells(&mut self.moving, &mut self.sizes, self.cell_axis, axis);
        if self.moving_dirty {
            self.moving.sort_unstable_by(|a, b| sweep_order(a, b, axis));
            self.moving_dirty = false;
        } else {
            for i in 1..self.moving.len() {
                let mut j = i;
                while j > 0 && sweep_order(&self.moving[j - 1], &self.moving[j], axis).is_gt() {
                    self.moving.swap(j - 1, j);
                    j -= 1;
                }
            }
        }
        self.found.clear();
        self.sweep.fill(&self.moving);
        let n = self.moving.len();
        let slab_end = |moving: &[Entry], i: usize| {
            let cell = moving[i].cell;
            moving[i..]
                .iter()
                .position(|b| b.cell != cell)
                .map_or(n, |k| i + k)
        };
        // The current slab ends at `next`; `after` ends the slab after it when that one is
        // adjacent (else `after == next`).
        let (mut next, mut after) = (0, 0);
        // Where the scan of the next slab starts: the boxes of a slab come in increasing
        // start along the axis, so this only moves forward.
        let mut from = 0;
        for i in 0..n {
            let cell = self.moving[i].cell;
            if i == next {
                next = slab_end(&self.moving, i);
                after = match self.moving.get(next) {
                    Some(b) if b.cell == cell.wrapping_add(1) => slab_end(&self.moving, next),
                    _ => next,
                };
                from = next;
            }
            let (lo, hi) = (self.moving[i].min[axis], self.moving[i].max[axis]);
            // Its own slab: the boxes after it that start before it ends.
            self.sweep_run(i, i + 1, next, hi);
            // The next slab: boxes that start at most `wide` before it starts (any box
            // starting earlier also ends before it starts).
            let keys = &self.sweep.min[axis];
            while from < after && keys[from] < lo - wide {
                from += 1;
            }
            self.sweep_run(i, from, after, hi);
        }
        // The boxes set apart as far thicker than the rest, against every other box.
        let big = self.moving.iter().take_while(|e| e.cell == BIG).count();
        for a in &self.moving[..big] {
            for b in &self.moving[big..] {
                let overlap = a.min.cmple(b.max).all() && b.min.cmple(a.max).all();
                if overlap && (a.awake || b.awake) && a.layers.interacts(b.layers) {
                    self.found.push(key(a.entity, b.entity));
                }
            }
        }
        self.refresh_fixed();
        for a in self.moving.iter().filter(|a| a.awake) {
            let bounds = Aabb::new(a.min, a.max);
            for leaf in self.fixed_tree.intersect_aabb(&bounds) {
                if let Some(b) = self.fixed.get(leaf as usize)
                    && a.layers.interacts(b.layers)
                {
                    self.found.push(key(a.entity, b.entity));
                }
            }
        }
        if !excluded.is_empty() {
            self.found.retain(|p| !excluded.contains(p.0, p.1));
        }
        // Sorting took a third of the broad phase of a 50-row pyramid at rest, whose pairs
        // come out of the sweep in the same order every step.
        if !(self.pairs_from_found && self.found == self.found_before) {
            std::mem::swap(&mut self.pairs, &mut self.pairs_before);
            self.pairs.clone_from(&self.found);
            // The order of `(Entity, Entity)`, as one integer: cheaper to compare.
            self.pairs.sort_unstable_by_key(|&(a, b)| {
                (u128::from(a.to_bits()) << 64) | u128::from(b.to_bits())
            });
            self.pairs.dedup();
            self.pairs_from_found = true;
            // The sweep finds the same pairs in another order when boxes pass each other
            // along its axis (in a resting pyramid, every step): the same list keeps its
            // version.
            if self.pairs != self.pairs_before {
                self.pairs_stamp = crate::collision::slots::Stamp::fresh();
            }
        }
        std::mem::swap(&mut self.found, &mut self.found_before);
    }
}

/// The broad phase as a snapshot holds it: the moving boxes as kept (grown, possibly from
/// earlier steps: the pairs they give are a superset that depends on history) in their sweep
/// order, the sweep axes and the last pairs. The fixed list and its tree are rebuilt (their
/// pairs do not depend on history).
#[derive(Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct BroadPhaseRecord {
    moving: Vec<Entry>,
    moving_dirty: bool,
    axis: usize,
    cell_axis: usize,
    pairs: Vec<(Entity, Entity)>,
}

impl BroadPhaseRecord {
    /// Renames every entity through `f`; the pairs are put back in order, the sweep's
    /// entries keep theirs (for a digest that does not depend on entity ids).
    pub(crate) fn rename(&mut self, f: impl Fn(Entity) -> Entity) {
        for e in &mut self.moving {
            e.entity = f(e.entity);
        }
        for p in &mut self.pairs {
            *p = (f(p.0), f(p.1));
        }
        self.pairs.sort_unstable();
    }
}

impl BroadPhase {
    /// What a snapshot keeps (see [`BroadPhaseRecord`]).
    pub(crate) fn to_record(&self) -> BroadPhaseRecord {
        BroadPhaseRecord {
            moving: self.moving.clone(),
            moving_dirty: self.moving_dirty,
            axis: self.axis,
            cell_axis: self.cell_axis,
            pairs: self.pairs.clone(),
        }
    }

    /// Restores a record, its entities mapped by `map` (an order-keeping map: the lists
    /// stay sorted). `Err` names an entity the map does not know.
    pub(crate) fn restore(
        &mut self,
        record: &BroadPhaseRecord,
        map: impl Fn(Entity) -> Option<Entity>,
    ) -> Result<(), Entity> {
        let mut moving = record.moving.clone();
        for e in &mut moving {
            e.entity = map(e.entity).ok_or(e.entity)?;
        }
        let pairs = record
            .pairs
            .iter()
            .map(|&(a, b)| Ok(key(map(a).ok_or(a)?, map(b).ok_or(b)?)))
            .collect::<Result<Vec<_>, Entity>>()?;
        self.moving = moving;
        self.moving_dirty = record.moving_dirty;
        self.axis = record.axis.min(2);
        self.cell_axis = record.cell_axis.min(2);
        self.pairs = pairs;
        self.pairs_from_found = false;
        self.pairs_stamp = crate::collision::slots::Stamp::fresh();
        self.fixed_dirty = true;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(i: u32, min: Vec3, max: Vec3) -> Entry {
        Entry {
            entity: Entity::from_raw_u32(i).unwrap(),
            min,
            max,
            awake: true,
            layers: CollisionLayers::default(),
            cell: 0,
        }
    }

    #[test]
    fn finds_exactly_the_overlapping_pairs_and_never_fixed_with_fixed() {
        let mut bp = BroadPhase {
            moving: vec![
                entry(1, Vec3::ZERO, Vec3::ONE),
                entry(2, Vec3::splat(0.5), Vec3::splat(1.5)),
                entry(3, Vec3::splat(3.0), Vec3::splat(4.0)),
                entry(4, Vec3::new(0.5, 5.0, 0.5), Vec3::new(0.9, 6.0, 0.9)),
            ],
            fixed: vec![
                entry(5, Vec3::splat(-10.0), Vec3::splat(10.0)),
                entry(6, Vec3::splat(-1.0), Vec3::splat(0.2)),
            ],
            fixed_dirty: true,
            moving_dirty: true,
            ..Default::default()
        };
        bp.find_pairs();
        // Entity order is bevy's, not the index order: compare as sorted index pairs.
        let ids = |bp: &BroadPhase| {
            let mut ids: Vec<(u32, u32)> = bp
                .pairs
                .iter()
                .map(|(a, b)| {
                    let (a, b) = (a.index_u32(), b.index_u32());
                    (a.min(b), a.max(b))
                })
                .collect();
            ids.sort_unstable();
            ids
        };
        assert_eq!(
            ids(&bp),
            vec![(1, 2), (1, 5), (1, 6), (2, 5), (3, 5), (4, 5)]
        );
        // Move box 3 onto box 4 (incremental path): the pairs follow.
        // The sweep reorders the list: find boxes by entity.
        let at = |bp: &BroadPhase, i: u32| {
            bp.moving
                .iter()
                .position(|e| e.entity.index_u32() == i)
                .unwrap()
        };
        let three = at(&bp, 3);
        bp.moving[three].min = Vec3::new(0.6, 5.5, 0.6);
        bp.moving[three].max = Vec3::new(1.6, 6.5, 1.6);
        bp.find_pairs();
        assert_eq!(
            ids(&bp),
            vec![(1, 2), (1, 5), (1, 6), (2, 5), (3, 4), (3, 5), (4, 5)]
        );
        // Asleep with asleep: no pair; asleep with awake or fixed as before.
        let (three, four) = (at(&bp, 3), at(&bp, 4));
        bp.moving[three].awake = false;
        bp.moving[four].awake = false;
        bp.find_pairs();
        assert!(!ids(&bp).contains(&(3, 4)) && !ids(&bp).contains(&(3, 5)));
    }
    /// A deterministic scatter of boxes of mixed sizes, some asleep.
    fn scatter(n: u32, seed: u32, spread: f32) -> Vec<Entry> {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3::new(next(), next(), next()) * spread;
                let half = Vec3::new(next(), next(), next()) * 0.8 + Vec3::splat(0.05);
                let mut e = entry(i + 1, c - half, c + half);
                e.awake = i % 7 != 0;
                e
            })
            .collect()
    }

    fn brute_force(entries: &[Entry]) -> Vec<(Entity, Entity)> {
        let mut out = Vec::new();
        for (i, a) in entries.iter().enumerate() {
            for b in &entries[i + 1..] {
                let overlap = a.min.cmple(b.max).all() && b.min.cmple(a.max).all();
                if overlap && (a.awake || b.awake) {
                    out.push(key(a.entity, b.entity));
                }
            }
        }
        out.sort_unstable();
        out
    }

    #[test]
    fn slab_sweep_finds_exactly_the_brute_force_pairs_as_boxes_move() {
        for (seed, spread) in [(1, 12.0), (2, 30.0), (3, 4.0), (4, 12.0)] {
            let mut moving = scatter(400, seed, spread);
            // One long box across everything: thick slabs, every pair still found.
            if seed == 2 {
                moving[5].max.z += 20.0;
            }
            // Three containers around everything: set apart from the sweep, each tested
            // against every box.
            if seed == 4 {
                for k in [5, 9, 13] {
                    moving[k].min -= Vec3::splat(20.0);
                    moving[k].max += Vec3::splat(20.0);
                }
            }
            let mut bp = BroadPhase {
                moving: moving.clone(),
                ..Default::default()
            };
            bp.refresh_fixed();
            bp.find_pairs();
            assert_eq!(bp.pairs, brute_force(&moving), "seed {seed}");
            let apart = bp.moving.iter().filter(|e| e.cell == BIG).count();
            assert_eq!(apart, if seed == 4 { 3 } else { 0 }, "seed {seed}");
            // Move every box a little (incremental re-sort) and a few a lot.
            for step in 0..3u32 {
                for (k, e) in bp.moving.iter_mut().enumerate() {
                    let d = if k % 50 == 0 { 3.0 } else { 0.2 };
                    let shift = Vec3::new(
                        ((k as u32 * 7 + step) % 5) as f32 - 2.0,
                        ((k as u32 * 3 + step) % 3) as f32 - 1.0,
                        ((k as u32 + step * 5) % 7) as f32 - 3.0,
                    ) * (d / 3.0);
                    e.min += shift;
                    e.max += shift;
                }
                let now = bp.moving.clone();
                let (before, stamp) = (bp.pairs.clone(), bp.pairs_stamp());
                bp.find_pairs();
                assert_eq!(bp.pairs, brute_force(&now), "seed {seed}, step {step}");
                // A new version exactly when the pairs changed.
                assert_eq!(bp.pairs_stamp() == stamp, bp.pairs == before, "seed {seed}");
            }
            // Nothing moved: the same pairs, the same version.
            let stamp = bp.pairs_stamp();
            bp.find_pairs();
            assert_eq!(bp.pairs_stamp(), stamp, "seed {seed}");
        }
    }
}
