//! Entity order where a query's order would change the rounding.
//!
//! A query walks tables in the order its system first saw them: at its first run, every
//! table that exists then, in the order of an internal hash map; later ones as they appear.
//! A world restored from a snapshot, or one whose systems first ran at another moment, walks
//! the same tables in another order. Within a table, rows keep their order (a snapshot
//! restores them). So a system that sums several entities into one (spring forces on a
//! shared end) gives bit-identical results across such worlds only if it takes the entities
//! of different tables in an order of their own: entity order, which a restore keeps.

use bevy_ecs::archetype::Archetypes;
use bevy_ecs::component::ComponentId;
use bevy_ecs::entity::Entity;
use bevy_ecs::query::{QueryData, QueryFilter, ROQueryItem};
use bevy_ecs::system::Query;

/// Whether the entities with component `id` sit in more than one non-empty table.
#[must_use]
fn in_several_tables(archetypes: &Archetypes, id: ComponentId) -> bool {
    let Some(index) = archetypes.component_index().get(&id) else {
        return false;
    };
    let mut first = None;
    for archetype in index.keys().map(|&a| &archetypes[a]) {
        if archetype.is_empty() {
            continue;
        }
        match first {
            None => first = Some(archetype.table_id()),
            Some(t) if t != archetype.table_id() => return true,
            Some(_) => {}
        }
    }
    false
}

/// The items of `query` in table order while its entities with component `id` sit in one
/// table, in entity order otherwise (`order` is the system's scratch for it; `entity_of`
/// reads an item's entity).
pub(crate) fn stable<'a, 's, D, F>(
    query: &'a Query<'_, 's, D, F>,
    archetypes: &Archetypes,
    id: ComponentId,
    order: &'a mut Vec<Entity>,
    entity_of: impl Fn(&ROQueryItem<'a, 's, D>) -> Entity,
) -> Box<dyn Iterator<Item = ROQueryItem<'a, 's, D>> + 'a>
where
    D: QueryData,
    F: QueryFilter,
{
    if !in_several_tables(archetypes, id) {
        return Box::new(query.iter());
    }
    order.clear();
    order.extend(query.iter().map(|item| entity_of(&item)));
    order.sort_unstable();
    Box::new(order.iter().filter_map(|&e| query.get(e).ok()))
}
