//! Fetching the components of the many entities a pass needs.
//!
//! A lookup by entity costs a few hundred instructions on a query of ten components (it
//! finds the entity's table and each component's column every time), while a walk over the
//! query in storage order costs a few per entity. So a pass first lists the entities it
//! wants, each at a slot, and fetches them in one walk when they are at least a quarter of
//! the query; a few among many are still looked up, so that a handful of contacts among
//! thousands of static colliders does not pay for a walk over all of them.

use bevy_ecs::prelude::*;
use bevy_ecs::query::{QueryData, QueryFilter, ROQueryItem};

use crate::collision::slots::EntitySlots;

/// A walk pays while at least this share of the query's entities are wanted.
const WALK_SHARE: usize = 4;

/// The entities a pass wants, each at a slot (its position in the list).
#[derive(Debug, Default)]
pub(crate) struct Wanted {
    entities: Vec<Entity>,
    slots: EntitySlots,
}

impl Wanted {
    /// Forgets every entity.
    pub fn clear(&mut self) {
        self.slots.clear(self.entities.iter().copied());
        self.entities.clear();
    }

    /// The number of entities wanted.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// The slot of `e`, which is added if new.
    #[inline]
    pub fn slot(&mut self, e: Entity) -> usize {
        let entities = &self.entities;
        if let Some(i) = self.slots.find(e, |i| entities.get(i).copied()) {
            return i as usize;
        }
        self.slots.insert(e, self.entities.len() as u32);
        self.entities.push(e);
        self.entities.len() - 1
    }

    /// Calls `fill(slot, item)` for every wanted entity that `query` holds; `entity` tells
    /// an item's entity.
    pub fn fetch<'w, 's, D: QueryData, F: QueryFilter>(
        &self,
        query: &'w Query<'_, 's, D, F>,
        entity: impl Fn(&ROQueryItem<'w, 's, D>) -> Entity,
        mut fill: impl FnMut(usize, ROQueryItem<'w, 's, D>),
    ) {
        if self.entities.is_empty() {
            return;
        }
        // Cheap for archetype filters (a sum over tables), as the contact queries use.
        if WALK_SHARE * self.entities.len() >= query.count() {
            let entities = &self.entities;
            // `for_each` takes the query's table-at-a-time fold.
            query.iter().for_each(|item| {
                let e = entity(&item);
                if let Some(i) = self.slots.find(e, |i| entities.get(i).copied()) {
                    fill(i as usize, item);
                }
            });
        } else {
            for (i, &e) in self.entities.iter().enumerate() {
                if let Ok(item) = query.get(e) {
                    fill(i, item);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_ecs::system::SystemState;

    #[derive(Component, Debug, Clone, Copy, PartialEq)]
    struct Tag(u32);

    #[derive(Component)]
    struct Other;

    /// Fetches `want` from a world of `n` tagged entities (every third also with `Other`,
    /// so that they sit in two tables) and returns each slot's tag.
    fn fetched(n: u32, want: &[u32]) -> Vec<Option<u32>> {
        let mut world = World::new();
        let all: Vec<Entity> = (0..n)
            .map(|i| {
                let mut e = world.spawn(Tag(i));
                if i % 3 == 0 {
                    e.insert(Other);
                }
                e.id()
            })
            .collect();
        let mut state: SystemState<Query<(Entity, &Tag)>> = SystemState::new(&mut world);
        let query = state.get(&world).unwrap();
        let mut wanted = Wanted::default();
        for &k in want {
            wanted.slot(all[k as usize]);
        }
        let mut out = vec![None; wanted.len()];
        wanted.fetch(
            &query,
            |item: &(Entity, &Tag)| item.0,
            |i, item| out[i] = Some(item.1.0),
        );
        out
    }

    #[test]
    fn a_walk_and_lookups_fill_the_same_slots() {
        // Most of the world wanted: a walk. A repeated entity keeps its first slot.
        let want: Vec<u32> = (0..30).rev().chain([5]).collect();
        let walked = fetched(30, &want);
        assert_eq!(walked.len(), 30);
        assert_eq!(walked, (0..30).rev().map(Some).collect::<Vec<_>>());
        // Three among 300: lookups.
        assert_eq!(
            fetched(300, &[7, 250, 3]),
            vec![Some(7), Some(250), Some(3)]
        );
    }
}
