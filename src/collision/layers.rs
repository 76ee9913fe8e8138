//! Collision layers: which colliders may touch, as bit masks or as a game's own enum.

use bevy_ecs::prelude::*;

use crate::core::error::{Error, Result};

/// A game's named collision layer: implement it for an enum, one line.
///
/// ```
/// use hooke::collision::{CollisionLayers, PhysicsLayer};
///
/// #[derive(Clone, Copy)]
/// enum Layer {
///     Ground,
///     Player,
///     Enemy,
///     Pickup,
/// }
///
/// impl PhysicsLayer for Layer {
///     fn index(self) -> u32 {
///         self as u32
///     }
/// }
///
/// // The player is on its layer and touches the ground and enemies, not pickups.
/// let player = CollisionLayers::from_layers([Layer::Player], [Layer::Ground, Layer::Enemy]).unwrap();
/// let pickup = CollisionLayers::from_layers([Layer::Pickup], [Layer::Player]).unwrap();
/// assert!(!player.interacts(pickup));
/// ```
pub trait PhysicsLayer: Copy {
    /// The layer's bit, 0 to 31.
    fn index(self) -> u32;
}

/// A set of layers as a bit mask (bit i is layer i).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LayerMask(pub u32);

impl LayerMask {
    /// Every layer.
    pub const ALL: LayerMask = LayerMask(u32::MAX);
    /// No layer.
    pub const NONE: LayerMask = LayerMask(0);

    /// The mask of `layers`.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a layer whose index is 32 or more.
    pub fn from_layers<L: PhysicsLayer>(layers: impl IntoIterator<Item = L>) -> Result<Self> {
        let mut bits = 0u32;
        for layer in layers {
            let i = layer.index();
            bits |= 1u32.checked_shl(i).ok_or(Error::OutOfRange {
                what: "collision layer index",
                value: i as f32,
                range: "0 to 31",
            })?;
        }
        Ok(Self(bits))
    }
}

impl From<u32> for LayerMask {
    fn from(bits: u32) -> Self {
        Self(bits)
    }
}

impl std::ops::BitOr for LayerMask {
    type Output = LayerMask;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl std::ops::BitAnd for LayerMask {
    type Output = LayerMask;
    fn bitand(self, rhs: Self) -> Self {
        Self(self.0 & rhs.0)
    }
}

impl std::ops::Not for LayerMask {
    type Output = LayerMask;
    fn not(self) -> Self {
        Self(!self.0)
    }
}

/// Which colliders may touch: a pair interacts when each one's `memberships` meets the
/// other's `filters`. Default: every layer, colliding with every layer.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct CollisionLayers {
    /// Layers this collider is on (bit mask).
    pub memberships: u32,
    /// Layers this collider collides with (bit mask).
    pub filters: u32,
}

impl Default for CollisionLayers {
    fn default() -> Self {
        Self {
            memberships: u32::MAX,
            filters: u32::MAX,
        }
    }
}

impl CollisionLayers {
    /// True when the two colliders may interact.
    #[must_use]
    pub fn interacts(self, other: Self) -> bool {
        self.memberships & other.filters != 0 && other.memberships & self.filters != 0
    }
}

impl CollisionLayers {
    /// Layers from masks: `CollisionLayers::new(0b01, 0b10)` or from [`LayerMask`]s.
    #[must_use]
    pub fn new(memberships: impl Into<LayerMask>, filters: impl Into<LayerMask>) -> Self {
        Self {
            memberships: memberships.into().0,
            filters: filters.into().0,
        }
    }

    /// Layers from a game's named layers ([`PhysicsLayer`]): on `memberships`, colliding
    /// with `filters`.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a layer whose index is 32 or more.
    pub fn from_layers<L: PhysicsLayer>(
        memberships: impl IntoIterator<Item = L>,
        filters: impl IntoIterator<Item = L>,
    ) -> Result<Self> {
        Ok(Self::new(
            LayerMask::from_layers(memberships)?,
            LayerMask::from_layers(filters)?,
        ))
    }
}
