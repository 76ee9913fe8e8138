//! Dominance: in a contact between two dynamic bodies, the one of the higher group moves the
//! other and is not moved by it.

use bevy_ecs::prelude::*;

/// A body's dominance group (default 0). In a contact between two dynamic bodies of
/// different groups, the higher group's body acts as if its mass were infinite: it pushes the
/// other and takes no impulse from it (a player's body that no crate can shove, a boss that
/// walks through a pile). Bodies of the same group collide as usual. Static and kinematic
/// bodies already take no impulse from anything, whatever their group. Joints ignore it.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Dominance(pub i8);

/// Which side of a contact takes no impulse for dominance: bit 0 the first, bit 1 the second.
#[must_use]
#[inline]
pub(crate) fn held_sides(a: i8, b: i8) -> u8 {
    match a.cmp(&b) {
        std::cmp::Ordering::Greater => 1,
        std::cmp::Ordering::Less => 2,
        std::cmp::Ordering::Equal => 0,
    }
}
