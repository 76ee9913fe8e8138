//! An index of per-step items by entity, shared by the narrow phase and the solver.

use bevy_ecs::entity::Entity;

/// A per-step index of items by entity, kept in an array by the entity's index: a lookup is
/// a load and a check against the entity the item holds, not a hash.
#[derive(Debug, Default)]
pub(crate) struct EntitySlots {
    slots: Vec<u32>,
}

impl EntitySlots {
    /// The index of `e`'s item, if it has one; `entity_of(i)` is the entity item i holds.
    #[inline]
    pub fn find(&self, e: Entity, entity_of: impl Fn(usize) -> Option<Entity>) -> Option<u32> {
        let i = *self.slots.get(e.index_u32() as usize)?;
        (entity_of(i as usize) == Some(e)).then_some(i)
    }

    pub fn insert(&mut self, e: Entity, i: u32) {
        let k = e.index_u32() as usize;
        if k >= self.slots.len() {
            self.slots.resize(k + 1, u32::MAX);
        }
        self.slots[k] = i;
    }

    /// Forgets the given entities' items.
    pub fn clear(&mut self, entities: impl Iterator<Item = Entity>) {
        for e in entities {
            if let Some(slot) = self.slots.get_mut(e.index_u32() as usize) {
                *slot = u32::MAX;
            }
        }
    }
}

/// A version of a list: a number no other version in this process has, so that a cache
/// built from one version is never taken for another's, not even across a snapshot restore.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Stamp(u64);

impl Stamp {
    /// A version no other has.
    #[must_use]
    pub fn fresh() -> Self {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        Self(NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
    }
}

impl Default for Stamp {
    fn default() -> Self {
        Self::fresh()
    }
}
