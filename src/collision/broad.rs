//! Sort-and-sweep broad phase.

use bevy_ecs::prelude::*;
use glam::Vec3;

use super::CollisionLayers;

/// One collider's box as the broad phase sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Entry {
    pub entity: Entity,
    pub min: Vec3,
    pub max: Vec3,
    /// Whether the collider can move (dynamic or kinematic); two fixed colliders never pair.
    pub moving: bool,
    pub layers: CollisionLayers,
}

/// The broad phase's working set and its output, reused from step to step.
#[derive(Resource, Default)]
pub(crate) struct BroadPhase {
    pub entries: Vec<Entry>,
    /// Candidate pairs (lower entity first), sorted.
    pub pairs: Vec<(Entity, Entity)>,
}

/// The axis along which box centres spread most: sweeping it leaves the fewest overlaps.
fn sweep_axis(entries: &[Entry]) -> usize {
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

impl BroadPhase {
    /// Sorts the boxes along the sweep axis and collects every overlapping pair that may
    /// interact: O(n log n + overlaps along the axis).
    pub fn find_pairs(&mut self) {
        let axis = sweep_axis(&self.entries);
        // Ties broken by entity so the order, and so the solver's order, is deterministic.
        self.entries.sort_unstable_by(|a, b| {
            a.min[axis]
                .total_cmp(&b.min[axis])
                .then(a.entity.cmp(&b.entity))
        });
        self.pairs.clear();
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        for (i, a) in self.entries.iter().enumerate() {
            for b in &self.entries[i + 1..] {
                if b.min[axis] > a.max[axis] {
                    break;
                }
                if !(a.moving || b.moving)
                    || b.min[o1] > a.max[o1]
                    || a.min[o1] > b.max[o1]
                    || b.min[o2] > a.max[o2]
                    || a.min[o2] > b.max[o2]
                    || !a.layers.interacts(b.layers)
                {
                    continue;
                }
                self.pairs.push(if a.entity < b.entity {
                    (a.entity, b.entity)
                } else {
                    (b.entity, a.entity)
                });
            }
        }
        self.pairs.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(i: u32, min: Vec3, max: Vec3, moving: bool) -> Entry {
        Entry {
            entity: Entity::from_raw_u32(i).unwrap(),
            min,
            max,
            moving,
            layers: CollisionLayers::default(),
        }
    }

    #[test]
    fn finds_exactly_the_overlapping_moving_pairs() {
        let mut bp = BroadPhase {
            entries: vec![
                entry(1, Vec3::ZERO, Vec3::ONE, true),
                entry(2, Vec3::splat(0.5), Vec3::splat(1.5), true),
                entry(3, Vec3::splat(3.0), Vec3::splat(4.0), true),
                entry(4, Vec3::new(0.5, 5.0, 0.5), Vec3::new(0.9, 6.0, 0.9), true),
                entry(5, Vec3::splat(-10.0), Vec3::splat(10.0), false),
                entry(6, Vec3::splat(-1.0), Vec3::splat(0.2), false),
            ],
            pairs: Vec::new(),
        };
        bp.find_pairs();
        // Entity order is bevy's, not the index order: compare as sorted index pairs.
        let mut ids: Vec<(u32, u32)> = bp
            .pairs
            .iter()
            .map(|(a, b)| {
                let (a, b) = (a.index_u32(), b.index_u32());
                (a.min(b), a.max(b))
            })
            .collect();
        ids.sort_unstable();

        // 5 and 6 are fixed: they pair with every moving box they touch, never with each other.
        assert_eq!(ids, vec![(1, 2), (1, 5), (1, 6), (2, 5), (3, 5), (4, 5)]);
    }
}
