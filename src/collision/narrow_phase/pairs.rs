//! The pair table: every broad-phase pair's [`PairState`] in a slot array, found by key
//! through a small index.
//!
//! Why not a map of states: a step reads every pair's state three times (the narrow phase,
//! the solver's preparation, the impulses written back). With the states inline in a hash
//! map, each of those was a probe into a table of 20,000 entries of ~100 bytes, and on
//! Box3D's convex pile a fifth of the step waited on those lines. Here the narrow phase
//! probes the index once and hands the later stages the slot, and the states sit in one
//! array that the end-of-step sweep reads as a dense list of step numbers.

use bevy_ecs::prelude::Entity;
use bevy_platform::collections::HashMap;

use crate::collision::narrow_phase::PairState;

/// How many pairs a pass over the table reads ahead of its work (see [`PairTable::warm`]).
pub(crate) const LOOK_AHEAD: usize = 32;

/// A pair's key: its lower entity, then its higher one.
pub(crate) type PairKey = (Entity, Entity);

/// The pair states, each in a slot that stays its own until the pair is removed.
#[derive(Default)]
pub(crate) struct PairTable {
    index: HashMap<PairKey, u32>,
    /// Per slot: the pair's key and state, `None` when free.
    slots: Vec<Option<(PairKey, PairState)>>,
    /// Per slot: the narrow-phase step that last saw the pair.
    seen: Vec<u64>,
    free: Vec<u32>,
    /// The version of the key-to-slot map: new whenever a pair gets or loses a slot.
    stamp: crate::collision::slots::Stamp,
}

impl PairTable {
    /// The number of pairs.
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// True when there is no pair.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    /// The slot of `key`, if it is a pair.
    #[inline]
    pub fn slot(&self, key: &PairKey) -> Option<u32> {
        self.index.get(key).copied()
    }

    /// The state of `key`.
    pub fn get(&self, key: &PairKey) -> Option<&PairState> {
        self.slot(key).and_then(|s| self.at(s))
    }

    /// The state in `slot` (`None` for a free or unknown slot).
    #[inline]
    pub fn at(&self, slot: u32) -> Option<&PairState> {
        self.slots.get(slot as usize)?.as_ref().map(|(_, s)| s)
    }

    /// The state in `slot`, to change.
    #[inline]
    pub fn at_mut(&mut self, slot: u32) -> Option<&mut PairState> {
        self.slots.get_mut(slot as usize)?.as_mut().map(|(_, s)| s)
    }

    /// Starts loading each of `slots`' states (see [`PairTable::prefetch`]), for a pass
    /// about to work through them.
    ///
    /// Why: a state is two pointers away from its slot (its manifolds, their points), each
    /// a cache miss when pairs are many. A pass that reads every state in turn waits on
    /// each; a short loop over a chunk of [`LOOK_AHEAD`] lets their loads overlap. On
    /// Box3D's pile that was a sixth of the step.
    #[inline]
    pub fn warm(&self, slots: impl Iterator<Item = u32>) {
        slots.for_each(|slot| self.prefetch(slot));
    }

    /// Starts loading the state in `slot` (its manifolds and their points) into the cache,
    /// without waiting for it.
    #[inline]
    pub fn prefetch(&self, slot: u32) {
        if let Some(state) = self.at(slot) {
            for m in &state.manifolds {
                crate::collision::prefetch::lines(m);
                crate::collision::prefetch::lines(m.points.as_slice());
            }
        }
    }

    /// The version of the key-to-slot map (see [`crate::collision::slots::Stamp`]): while it
    /// holds, every slot [`PairTable::slot`] gave still holds its pair.
    #[must_use]
    pub fn stamp(&self) -> crate::collision::slots::Stamp {
        self.stamp
    }

    /// Marks the pair in `slot` seen at `step`.
    #[inline]
    pub fn mark_seen(&mut self, slot: u32, step: u64) {
        if let Some(s) = self.seen.get_mut(slot as usize) {
            *s = step;
        }
    }

    /// The slot of `key`, a new pair's when it is not one yet, marked seen at `step`.
    pub fn see(&mut self, key: PairKey, step: u64) -> u32 {
        let slot = match self.index.get(&key) {
            Some(&s) => s,
            None => self.insert(key, PairState::new(), step),
        };
        self.seen[slot as usize] = step;
        slot
    }

    /// Adds `key` with `state`, last seen at `seen`; returns its slot. Replaces the state of
    /// a pair that is already there.
    pub fn insert(&mut self, key: PairKey, state: PairState, seen: u64) -> u32 {
        if let Some(&slot) = self.index.get(&key) {
            self.slots[slot as usize] = Some((key, state));
            self.seen[slot as usize] = seen;
            return slot;
        }
        let slot = match self.free.pop() {
            Some(s) => {
                self.slots[s as usize] = Some((key, state));
                self.seen[s as usize] = seen;
                s
            }
            None => {
                self.slots.push(Some((key, state)));
                self.seen.push(seen);
                (self.slots.len() - 1) as u32
            }
        };
        self.index.insert(key, slot);
        self.stamp = crate::collision::slots::Stamp::fresh();
        slot
    }

    /// Removes `key`; returns its state.
    pub fn remove(&mut self, key: &PairKey) -> Option<PairState> {
        let slot = self.index.remove(key)?;
        self.stamp = crate::collision::slots::Stamp::fresh();
        self.free.push(slot);
        self.slots[slot as usize].take().map(|(_, s)| s)
    }

    /// The pairs not seen at `step`, with whether they touch.
    pub fn unseen(&self, step: u64) -> impl Iterator<Item = (PairKey, bool)> + '_ {
        self.seen
            .iter()
            .enumerate()
            .filter(move |&(_, &s)| s != step)
            .filter_map(|(i, _)| self.slots[i].as_ref().map(|(k, s)| (*k, s.touching)))
    }

    /// Moves the pairs of `order` (slots) to the front, in that order, with their manifolds
    /// copied to fresh memory, and renumbers `order` to their new slots; the other pairs
    /// follow. Why: the stages walk the pairs in the broad phase's order, and states and
    /// manifolds allocated over time in another order made each visit a cache miss.
    pub fn reorder<'a>(&mut self, order: impl Iterator<Item = &'a mut u32>) {
        let mut old = std::mem::take(&mut self.slots);
        let len = old.len() as u32;
        let old_seen = std::mem::take(&mut self.seen);
        self.free.clear();
        self.index.clear();
        self.stamp = crate::collision::slots::Stamp::fresh();
        let mut put = |this: &mut Self, slot: u32| -> Option<u32> {
            let (key, mut state) = old.get_mut(slot as usize)?.take()?;
            state.manifolds = state.manifolds.clone();
            let at = this.slots.len() as u32;
            this.slots.push(Some((key, state)));
            this.seen.push(old_seen[slot as usize]);
            this.index.insert(key, at);
            Some(at)
        };
        for o in order {
            *o = put(self, *o).unwrap_or(u32::MAX);
        }
        for slot in 0..len {
            put(self, slot);
        }
    }

    /// Every pair with its state, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (&PairKey, &PairState)> {
        self.slots.iter().flatten().map(|(k, s)| (k, s))
    }

    /// Every pair with its state and the step that last saw it, in slot order.
    pub fn iter_seen(&self) -> impl Iterator<Item = (&PairKey, &PairState, u64)> {
        self.slots
            .iter()
            .zip(&self.seen)
            .filter_map(|(e, &seen)| e.as_ref().map(|(k, s)| (k, s, seen)))
    }

    /// Every pair's state, in slot order.
    pub fn values(&self) -> impl Iterator<Item = &PairState> {
        self.iter().map(|(_, s)| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(a: u32, b: u32) -> PairKey {
        (
            Entity::from_raw_u32(a).unwrap(),
            Entity::from_raw_u32(b).unwrap(),
        )
    }

    #[test]
    fn slots_are_kept_until_removed_and_reused_after() {
        let mut t = PairTable::default();
        let a = t.see(key(1, 2), 1);
        let b = t.see(key(1, 3), 1);
        assert_ne!(a, b);
        assert_eq!(t.see(key(1, 2), 2), a);
        assert_eq!(t.unseen(2).collect::<Vec<_>>(), vec![(key(1, 3), false)]);
        assert!(t.remove(&key(1, 3)).is_some());
        assert!(t.get(&key(1, 3)).is_none() && t.at(b).is_none());
        assert_eq!(t.len(), 1);
        // The freed slot is the next pair's.
        assert_eq!(t.see(key(2, 3), 3), b);
        assert_eq!(t.iter().count(), 2);
        assert!(
            t.iter_seen()
                .any(|(k, _, seen)| *k == key(2, 3) && seen == 3)
        );
    }

    #[test]
    fn the_version_changes_exactly_when_a_pair_gets_or_loses_a_slot() {
        let mut t = PairTable::default();
        assert_ne!(
            t.stamp(),
            PairTable::default().stamp(),
            "two tables share a version"
        );
        let v0 = t.stamp();
        let a = t.see(key(1, 2), 1);
        let v1 = t.stamp();
        assert_ne!(v1, v0, "a new pair");
        // Seeing a known pair, marking it seen, or replacing its state keeps every slot.
        assert_eq!(t.see(key(1, 2), 2), a);
        t.mark_seen(a, 3);
        t.insert(key(1, 2), PairState::new(), 3);
        assert_eq!(t.stamp(), v1);
        assert!(t.unseen(3).next().is_none());
        t.see(key(1, 3), 3);
        let v2 = t.stamp();
        assert_ne!(v2, v1, "another new pair");
        t.remove(&key(1, 3));
        let v3 = t.stamp();
        assert_ne!(v3, v2, "a removal");
        let mut order = [a];
        t.reorder(order.iter_mut());
        assert_ne!(t.stamp(), v3, "a reorder");
    }

    #[test]
    fn reordering_moves_the_given_pairs_to_the_front_and_keeps_every_state() {
        let mut t = PairTable::default();
        for b in 2..8 {
            let slot = t.see(key(1, b), 1);
            t.at_mut(slot).unwrap().touching = b % 2 == 0;
        }
        t.remove(&key(1, 4));
        let mut order = vec![t.slot(&key(1, 7)).unwrap(), t.slot(&key(1, 3)).unwrap()];
        t.reorder(order.iter_mut());
        assert_eq!(order, vec![0, 1]);
        let front: Vec<PairKey> = t.iter().take(2).map(|(k, _)| *k).collect();
        assert_eq!(front, vec![key(1, 7), key(1, 3)]);
        assert_eq!(t.len(), 5);
        for b in [2, 3, 5, 6, 7] {
            assert_eq!(t.get(&key(1, b)).unwrap().touching, b % 2 == 0, "{b}");
        }
        assert!(t.get(&key(1, 4)).is_none());
        assert_eq!(t.unseen(1).count(), 0);
    }
}
