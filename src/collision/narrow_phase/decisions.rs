//! The collision hooks' decisions for this step, as the narrow phase and the solver's
//! preparation read them (the hooks themselves, above, write them: see
//! [`crate::collision::CollisionHooks`]).

use bevy_ecs::prelude::*;
use bevy_platform::collections::{HashMap, HashSet};
use glam::Vec3A;

use crate::collision::broad_phase::BroadPhase;

/// Which of the [`crate::collision::CollisionHooks`] run for the pairs of this collider. A pair runs a hook
/// when either of its colliders asks for it.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct ActiveCollisionHooks {
    /// [`crate::collision::CollisionHooks::filter_pair`] decides whether the pair collides at all.
    pub filter_pairs: bool,
    /// [`crate::collision::CollisionHooks::modify_contacts`] sees and edits the pair's contact.
    pub modify_contacts: bool,
}

impl ActiveCollisionHooks {
    /// Only [`crate::collision::CollisionHooks::filter_pair`].
    pub const FILTER_PAIRS: Self = Self {
        filter_pairs: true,
        modify_contacts: false,
    };
    /// Only [`crate::collision::CollisionHooks::modify_contacts`].
    pub const MODIFY_CONTACTS: Self = Self {
        filter_pairs: false,
        modify_contacts: true,
    };
    /// Both hooks.
    pub const ALL: Self = Self {
        filter_pairs: true,
        modify_contacts: true,
    };

    pub(crate) fn or(self, other: Self) -> Self {
        Self {
            filter_pairs: self.filter_pairs || other.filter_pairs,
            modify_contacts: self.modify_contacts || other.modify_contacts,
        }
    }
}

/// What a modify hook changed of one pair, as the solver's preparation applies it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairEdit {
    pub enabled: bool,
    pub friction: Option<f32>,
    pub restitution: Option<f32>,
    pub surface: Vec3A,
}

/// The hooks' decisions for this step, and the pairs they run for.
#[derive(Resource, Default)]
pub(crate) struct HookDecisions {
    /// Colliders with [`ActiveCollisionHooks`], sorted, as the pair list was made from.
    pub(crate) flagged: Vec<(Entity, ActiveCollisionHooks)>,
    /// The broad phase's pair list the hooked pairs were taken from.
    pub(crate) stamp: Option<crate::collision::slots::Stamp>,
    /// Pairs with a hooked collider, and the hooks they run.
    pub(crate) hooked: Vec<((Entity, Entity), ActiveCollisionHooks)>,
    /// The flagged colliders as read this step (kept to reuse its memory).
    seen: Vec<(Entity, ActiveCollisionHooks)>,
    /// Pairs a filter hook turned away this step.
    pub rejected: HashSet<(Entity, Entity)>,
    /// Edits by pair slot, for this step.
    pub edits: HashMap<u32, PairEdit>,
}

impl HookDecisions {
    /// True when `(a, b)` (lower entity first) was filtered out this step.
    #[inline]
    pub fn rejects(&self, a: Entity, b: Entity) -> bool {
        !self.rejected.is_empty() && self.rejected.contains(&(a, b))
    }

    /// The edit of the pair in `slot`, if a hook changed it.
    #[inline]
    pub fn edit(&self, slot: u32) -> Option<&PairEdit> {
        if self.edits.is_empty() {
            None
        } else {
            self.edits.get(&slot)
        }
    }

    /// Brings the hooked pairs up to date with the broad phase's pairs and the flagged
    /// colliders; a scan of every pair only when either changed.
    pub(crate) fn refresh(
        &mut self,
        bp: &BroadPhase,
        flagged: &Query<(Entity, &ActiveCollisionHooks)>,
    ) {
        let mut now = std::mem::take(&mut self.seen);
        now.clear();
        now.extend(flagged.iter().map(|(e, h)| (e, *h)));
        now.sort_unstable_by_key(|f| f.0);
        if now == self.flagged && self.stamp == Some(bp.pairs_stamp()) {
            self.seen = now;
            return;
        }
        let flags = |e: Entity| now.binary_search_by_key(&e, |f| f.0).ok().map(|i| now[i].1);
        self.hooked.clear();
        for &(a, b) in &bp.pairs {
            if let Some(h) = match (flags(a), flags(b)) {
                (Some(x), Some(y)) => Some(x.or(y)),
                (x, y) => x.or(y),
            } {
                self.hooked.push(((a, b), h));
            }
        }
        self.seen = std::mem::replace(&mut self.flagged, now);
        self.stamp = Some(bp.pairs_stamp());
    }
}
