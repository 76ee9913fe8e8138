//! Names to entities: what an entry's name, or `name[i]`, selects at a moment of the run.

use std::collections::HashMap;

use bevy_ecs::prelude::*;

use super::Selector;

/// Names to entities.
pub(super) type Names = HashMap<String, Vec<Entity>>;

/// The entities a selector names now.
pub(super) fn members<'a>(names: &'a Names, sel: &Selector) -> &'a [Entity] {
    match (names.get(&sel.name), sel.index) {
        (Some(v), Some(i)) if i < v.len() => std::slice::from_ref(&v[i]),
        (Some(v), None) => v,
        _ => &[],
    }
}

/// The entities `name` or `name[i]` (negative from the end) names now, without allocating:
/// the checks call this for every expectation at every step.
pub(super) fn group<'a>(names: &'a Names, text: &str) -> &'a [Entity] {
    let (name, index) = super::split_selector(text);
    let index = index.ok().flatten();
    let Some(all) = names.get(name) else {
        return &[];
    };
    match index {
        None => all,
        Some(i) => {
            let k = if i < 0 { all.len() as i64 + i } else { i };
            usize::try_from(k)
                .ok()
                .and_then(|k| all.get(k))
                .map_or(&[], std::slice::from_ref)
        }
    }
}
