//! Broad phase: an incremental sort-and-sweep over moving colliders, and a bounding volume
//! hierarchy over fixed ones.
//!
//! - **Moving** colliders (anything with a velocity) keep their order from the last step;
//!   each step their boxes are updated in place and re-sorted by insertion sort along the
//!   sweep axis, which for coherent motion is close to O(n). The set is rebuilt (O(n log n))
//!   only when colliders are added or removed.
//! - **Fixed** colliders sit in parry's BVH, rebuilt only when one of them is added, moved,
//!   reshaped or removed. Each awake moving box queries it: O(log n_fixed) per box. A fixed
//!   collider costs nothing per step while nothing about it changes.

use bevy_ecs::prelude::*;
use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};

use super::CollisionLayers;
use super::lanes::F4;

/// One collider's box as the broad phase sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Entry {
    pub entity: Entity,
    pub min: Vec3,
    pub max: Vec3,
    /// False for sleeping bodies: they pair with awake bodies only.
    pub awake: bool,
    pub layers: CollisionLayers,
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
    /// Candidate pairs (lower entity first), sorted.
    pub pairs: Vec<(Entity, Entity)>,
    /// The moving boxes in sweep order as six coordinate arrays, padded with empty boxes to
    /// whole lanes: the sweep tests four candidates at once.
    sweep: Sweep,
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
            pairs: Vec::new(),
            sweep: Sweep::default(),
        }
    }
}

/// Marks both lists out of date. Called from the component hooks of [`super::Collider`], of
/// every validated component (insert: a new pose or velocity; remove: a velocity taken away
/// makes a collider static) and of [`crate::Quarantined`]: inserts and removals are how the
/// broad phase learns about changes without scanning every collider each step.
pub(crate) fn mark_dirty(world: &mut bevy_ecs::world::DeferredWorld, entity: Entity) {
    if world.get::<super::Collider>(entity).is_none() {
        return;
    }
    if let Some(mut bp) = world.get_resource_mut::<BroadPhase>() {
        bp.fixed_dirty = true;
        bp.moving_dirty = true;
    }
}

/// The axis along which box centres spread most: sweeping it leaves the fewest overlaps.
pub(crate) fn sweep_axis(entries: &[Entry]) -> usize {
    let n = entries.len().max(1) as f32;
    let mean = entries.iter().map(|e| e.min + e.max).sum::<Vec3>() / (2.0 * n);
    let var = entries
        .iter()
        .map(|e| {
            let d = 0.5 * (e.min + e.max) - mean;
            d * d
        })
        .sum::<Vec3>();
    if var.x >= var.y && var.x >= var.z {
        0
    } else if var.y >= var.z {
        1
    } else {
        2
    }
}

fn key(a: Entity, b: Entity) -> (Entity, Entity) {
    if a < b { (a, b) } else { (b, a) }
}

impl BroadPhase {
    /// Rebuilds the fixed tree from `self.fixed` if it is out of date.
    pub fn refresh_fixed(&mut self) {
        if self.fixed_dirty {
            let leaves: Vec<Aabb> = self.fixed.iter().map(|e| Aabb::new(e.min, e.max)).collect();
            self.fixed_tree = Bvh::from_leaves(BvhBuildStrategy::default(), &leaves);
            self.fixed_dirty = false;
        }
    }

    /// Sorts the moving boxes (insertion sort: cheap when they were nearly sorted) and
    /// collects every overlapping pair that may interact.
    pub fn find_pairs(&mut self) {
        if self.moving_dirty {
            self.axis = sweep_axis(&self.moving);
            let axis = self.axis;
            self.moving.sort_unstable_by(|a, b| {
                a.min[axis]
                    .total_cmp(&b.min[axis])
                    .then(a.entity.cmp(&b.entity))
            });
            self.moving_dirty = false;
        } else {
            let axis = self.axis;
            for i in 1..self.moving.len() {
                let mut j = i;
                while j > 0 && {
                    let (p, q) = (&self.moving[j - 1], &self.moving[j]);
                    p.min[axis]
                        .total_cmp(&q.min[axis])
                        .then(p.entity.cmp(&q.entity))
                        .is_gt()
                } {
                    self.moving.swap(j - 1, j);
                    j -= 1;
                }
            }
        }
        self.pairs.clear();
        let axis = self.axis;
        self.sweep.fill(&self.moving);
        let keys = &self.sweep.min[axis];
        for (i, a) in self.moving.iter().enumerate() {
            let end = a.max[axis];
            let mut j = i + 1;
            // The padding's infinite keys stop the loop within the arrays.
            while keys[j] <= end {
                let mut hits = self.sweep.overlaps(i, j);
                while hits != 0 {
                    let b = &self.moving[j + hits.trailing_zeros() as usize];
                    hits &= hits - 1;
                    if (a.awake || b.awake) && a.layers.interacts(b.layers) {
                        self.pairs.push(key(a.entity, b.entity));
                    }
                }
                j += 4;
            }
        }
        self.refresh_fixed();
        for a in self.moving.iter().filter(|a| a.awake) {
            let bounds = Aabb::new(a.min, a.max);
            for leaf in self.fixed_tree.intersect_aabb(&bounds) {
                if let Some(b) = self.fixed.get(leaf as usize)
                    && a.layers.interacts(b.layers)
                {
                    self.pairs.push(key(a.entity, b.entity));
                }
            }
        }
        self.pairs.sort_unstable();
        self.pairs.dedup();
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
        bp.moving[2].min = Vec3::new(0.6, 5.5, 0.6);
        bp.moving[2].max = Vec3::new(1.6, 6.5, 1.6);
        bp.find_pairs();
        assert_eq!(
            ids(&bp),
            vec![(1, 2), (1, 5), (1, 6), (2, 5), (3, 4), (3, 5), (4, 5)]
        );
        // Asleep with asleep: no pair; asleep with awake or fixed as before.
        bp.moving[2].awake = false;
        bp.moving[3].awake = false;
        bp.find_pairs();
        assert!(!ids(&bp).contains(&(3, 4)) && !ids(&bp).contains(&(3, 5)));
    }
}
