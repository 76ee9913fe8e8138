//! Collision hooks: the game's own code deciding, every step, whether two colliders
//! collide and how their contact behaves (one-way platforms, conveyor belts, a pair that
//! passes through under a condition only the game knows).
//!
//! A hook is a [`SystemParam`](bevy_ecs::system::SystemParam) that implements
//! [`CollisionHooks`]; [`CollisionHooksPlugin`] runs it for the pairs of colliders that carry
//! [`ActiveCollisionHooks`]. Pairs of colliders without that component never reach it, so a
//! world with hooks pays only for the colliders that asked.

use std::marker::PhantomData;

use bevy_ecs::prelude::*;
use bevy_ecs::system::{ReadOnlySystemParam, StaticSystemParam, SystemParamItem};
use glam::{Vec3, Vec3A};

use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::Contacts;
pub use crate::collision::narrow_phase::decisions::ActiveCollisionHooks;
use crate::collision::narrow_phase::decisions::{HookDecisions, PairEdit};
use crate::collision::{ContactSettings, Friction, Restitution, part_pose, shape_pose};
use crate::core::plugin::WorldPlugin;
use crate::core::schedule::PhysicsSchedule;
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// The game's collision rules, as a read-only system parameter (queries and resources of
/// the game's own components). Both methods have defaults that change nothing; implement
/// the ones you need and add [`CollisionHooksPlugin::<YourHooks>`].
///
/// The hooks are asked every step for the pairs of awake bodies. A sleeping body keeps the
/// contacts it fell asleep with and is not asked until it wakes: when a rule changes for a
/// body at rest (a drop-through key pressed), wake it by removing
/// [`crate::core::rest::Sleeping`].
///
/// ```
/// use bevy_ecs::prelude::*;
/// use bevy_ecs::system::SystemParam;
/// use hooke::prelude::*;
///
/// #[derive(Component)]
/// struct Ghost;
///
/// #[derive(SystemParam)]
/// struct GhostHooks<'w, 's> {
///     ghosts: Query<'w, 's, (), With<Ghost>>,
/// }
///
/// impl CollisionHooks for GhostHooks<'_, '_> {
///     fn filter_pair(&self, a: Entity, b: Entity, _: &mut Commands) -> bool {
///         // Ghosts pass through each other, and collide with everything else.
///         !(self.ghosts.contains(a) && self.ghosts.contains(b))
///     }
/// }
///
/// let mut world = World::new();
/// world.add_physics(PhysicsPlugins);
/// world.add_physics(CollisionHooksPlugin::<GhostHooks>::default());
/// ```
pub trait CollisionHooks: ReadOnlySystemParam + Send + Sync {
    /// Whether colliders `a` (the lower entity) and `b` collide this step. Runs before their
    /// contact is computed, for pairs whose bounding boxes overlap and where either collider
    /// has [`ActiveCollisionHooks::filter_pairs`]. A pair filtered out has no contact: no
    /// points, no impulses, and a [`crate::collision::ContactEnded`] if it was touching.
    fn filter_pair(&self, a: Entity, b: Entity, commands: &mut Commands) -> bool {
        let _ = (a, b, commands);
        true
    }

    /// Sees and edits the contact of a pair with points (touching, or about to within the
    /// contact margin) where either collider has [`ActiveCollisionHooks::modify_contacts`].
    /// Return false to leave the pair out of this step's solve: it stays touching, so no
    /// message is written for it, but it takes no impulse.
    fn modify_contacts(&self, contact: &mut ContactEdit, commands: &mut Commands) -> bool {
        let _ = (contact, commands);
        true
    }
}

/// One pair's contact as [`CollisionHooks::modify_contacts`] sees it, at the start of the
/// step, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEdit {
    /// The lower entity.
    pub a: Entity,
    /// The higher entity.
    pub b: Entity,
    /// Unit normal from `a` to `b` of the pair's deepest manifold.
    pub normal: Vec3,
    /// The contact points on `a`'s surface (m).
    pub points: Vec<Vec3>,
    /// Smallest separation of the points (m; negative when overlapping, positive for a
    /// contact that is still closing).
    pub separation: f32,
    /// The friction coefficient the pair will use (the colliders' combined; editable).
    pub friction: f32,
    /// The restitution the pair will use (editable).
    pub restitution: f32,
    /// The velocity of `b`'s surface relative to `a`'s that friction drives the contact
    /// to (m/s, world frame; its part along the normal is ignored). Zero: ordinary friction,
    /// which stops sliding. Set it with [`ContactEdit::set_surface_velocity`].
    pub relative_surface_velocity: Vec3,
}

impl ContactEdit {
    /// Makes the surface of `entity` (`a` or `b`) move at `velocity` along the contact
    /// (m/s, world frame), as a conveyor belt does: friction then carries the other
    /// collider along at that speed, up to μ times the normal force. Does nothing for an
    /// entity that is not in the pair.
    pub fn set_surface_velocity(&mut self, entity: Entity, velocity: Vec3) {
        // Friction drives b's surface relative to a's to this velocity: a belt on side a
        // carries b along with it, a belt on side b pushes a the other way.
        if entity == self.a {
            self.relative_surface_velocity = velocity;
        } else if entity == self.b {
            self.relative_surface_velocity = -velocity;
        }
    }

    /// The other collider of the pair, if `entity` is in it.
    #[must_use]
    pub fn other(&self, entity: Entity) -> Option<Entity> {
        match entity {
            e if e == self.a => Some(self.b),
            e if e == self.b => Some(self.a),
            _ => None,
        }
    }

    /// The normal pointing away from `entity` (`a` or `b`) towards the other collider.
    #[must_use]
    pub fn normal_from(&self, entity: Entity) -> Vec3 {
        if entity == self.b {
            -self.normal
        } else {
            self.normal
        }
    }
}

/// Runs the hooks `H` for the pairs of colliders with [`ActiveCollisionHooks`]. Add it
/// beside `PhysicsPlugins` (to a `World` with `add_physics`, to an `App` with
/// `add_plugins`); one hooks type per world.
pub struct CollisionHooksPlugin<H: CollisionHooks>(PhantomData<fn() -> H>);

impl<H: CollisionHooks> Default for CollisionHooksPlugin<H> {
    fn default() -> Self {
        Self(PhantomData)
    }
}

impl<H: CollisionHooks> std::fmt::Debug for CollisionHooksPlugin<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("CollisionHooksPlugin")
    }
}

impl<H: CollisionHooks + 'static> WorldPlugin for CollisionHooksPlugin<H>
where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    fn build(&self, world: &mut World) {
        world.init_resource::<HookDecisions>();
        crate::core::schedule::add_own_systems(
            world,
            PhysicsSchedule,
            (
                filter_pairs::<H>.in_set(CollisionHookSystems::FilterPairs),
                modify_contacts::<H>.in_set(CollisionHookSystems::ModifyContacts),
            ),
        );
    }
}

/// Where the hooks run inside [`crate::core::schedule::CollisionSystems::Detect`]: pairs are
/// filtered between the broad and the narrow phase, contacts edited after the narrow phase.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CollisionHookSystems {
    /// [`CollisionHooks::filter_pair`].
    FilterPairs,
    /// [`CollisionHooks::modify_contacts`].
    ModifyContacts,
}

fn filter_pairs<H: CollisionHooks>(
    hooks: StaticSystemParam<H>,
    bp: Res<BroadPhase>,
    flagged: Query<(Entity, &ActiveCollisionHooks)>,
    mut decisions: ResMut<HookDecisions>,
    mut commands: Commands,
) where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    let decisions = &mut *decisions;
    decisions.rejected.clear();
    decisions.refresh(&bp, &flagged);
    for &((a, b), h) in &decisions.hooked {
        if h.filter_pairs && !hooks.filter_pair(a, b, &mut commands) {
            decisions.rejected.insert((a, b));
        }
    }
}

type EditedBody<'a> = (
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a Friction,
    &'a Restitution,
);

fn modify_contacts<H: CollisionHooks>(
    hooks: StaticSystemParam<H>,
    contacts: Res<Contacts>,
    settings: Res<ContactSettings>,
    bodies: Query<EditedBody>,
    mut decisions: ResMut<HookDecisions>,
    mut commands: Commands,
) where
    for<'w, 's> SystemParamItem<'w, 's, H>: CollisionHooks,
{
    let decisions = &mut *decisions;
    decisions.edits.clear();
    for &((a, b), h) in &decisions.hooked {
        if !h.modify_contacts {
            continue;
        }
        let Some((slot, state)) = contacts.solvable(a, b) else {
            continue;
        };
        let (Ok(ba), Ok(bb)) = (bodies.get(a), bodies.get(b)) else {
            continue;
        };
        let pose = shape_pose(ba.0.0, ba.1.0, ba.2);
        let friction = settings.friction_rule.combine(ba.3.0, bb.3.0);
        let restitution = settings.restitution_rule.combine(ba.4.0, bb.4.0);
        let mut edit = ContactEdit {
            a,
            b,
            normal: Vec3::ZERO,
            points: Vec::new(),
            separation: f32::INFINITY,
            friction,
            restitution,
            relative_surface_velocity: Vec3::ZERO,
        };
        for m in state.solved() {
            let part = part_pose(&pose, m.subshape_pos1());
            for &k in m.data.kept() {
                let Some(p) = m.points.get(usize::from(k)) else {
                    continue;
                };
                edit.points.push(part * p.local_p1);
                if p.dist < edit.separation {
                    edit.separation = p.dist;
                    edit.normal = part.rotation * m.local_n1;
                }
            }
        }
        let enabled = hooks.modify_contacts(&mut edit, &mut commands);
        let changed = |x: f32, y: f32| (x.to_bits() != y.to_bits()).then_some(x);
        let surface = edit.relative_surface_velocity;
        let out = PairEdit {
            enabled,
            friction: changed(edit.friction, friction).filter(|f| f.is_finite() && *f >= 0.0),
            restitution: changed(edit.restitution, restitution)
                .filter(|r| r.is_finite() && *r >= 0.0),
            surface: if surface.is_finite() {
                surface.into()
            } else {
                Vec3A::ZERO
            },
        };
        if !enabled
            || out.friction.is_some()
            || out.restitution.is_some()
            || out.surface != Vec3A::ZERO
        {
            decisions.edits.insert(slot, out);
        }
    }
}
