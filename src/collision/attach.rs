//! Colliders attached to bodies: a body's mass from its colliders, and colliders on child
//! entities.
//!
//! **Mass from colliders.** A [`RigidBody::Dynamic`] body spawned without a [`Mass`] gets its
//! mass, centre of mass and inertia from its colliders: m = Σ ρᵢ Vᵢ, with each collider's
//! [`ColliderDensity`] ρᵢ (default [`ColliderDensity::DEFAULT`] = 1000 kg/m³, water; a
//! 1 m cube weighs a tonne), the parts combined about their common centre of mass by the
//! parallel-axis theorem. Mass properties you give (a [`Mass`] or a
//! [`crate::rigid::RigidBodyBundle`]) are never overwritten.
//!
//! **Child colliders.** A [`Collider`] on an entity whose parent (`ChildOf`, at any depth)
//! is a body is part of that body: it sits at its [`ColliderOffset`] in the parent's frame
//! (with the `bevy` feature, its `Transform` sets the offset), adds to the body's mass,
//! and moves with it. hooke marks it [`ColliderOf`] and keeps its [`Position`] and
//! [`Rotation`] at its world pose after every step. The body's own [`Collider`] then holds
//! all the parts as one parry compound; contacts, contact messages and spatial queries name
//! the body. A part that is itself composite (a compound, trimesh or heightfield) cannot be
//! nested in a compound: that child is quarantined with [`Error::CompositePart`].
//!
//! A part's own [`crate::collision::Friction`], [`crate::collision::Restitution`], [`crate::collision::CollisionLayers`] and
//! [`crate::collision::Sensor`] are not read: the body's apply to all its parts.
//!
//! Changes are seen when they are inserted: a new collider, density or offset, a despawned
//! or re-parented child, a new [`RigidBody`] kind. The work is done by a command queued from
//! the component hooks, so it is complete before the next step.

use bevy_ecs::hierarchy::{ChildOf, Children};
use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Quat, Vec3, Vec3A};
use parry3d::mass_properties::MassProperties as ParryMass;
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, TypedShape};

use super::Collider;
use crate::core::error::{Error, Result, finite_vec, positive};
use crate::core::quarantine::{QuarantineReason, Quarantined, Validate, validate_on_insert};
use crate::particles::{Mass, Position};
use crate::rigid::{CenterOfMass, ComputedMass, Inertia, RigidBody, Rotation};

/// Density of a collider (kg/m³), used when hooke computes a body's mass from its colliders.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = density_changed)]
pub struct ColliderDensity(pub f32);

impl ColliderDensity {
    /// 1000 kg/m³ (water): a 1 m cube weighs 1000 kg, a 0.5 m ball 65.4 kg.
    pub const DEFAULT: ColliderDensity = ColliderDensity(1000.0);

    /// A validated density (kg/m³).
    ///
    /// # Errors
    /// [`Error::NotPositive`] or [`Error::NonFinite`] unless positive and finite.
    pub fn try_new(kg_per_m3: f32) -> Result<Self> {
        positive("collider density", kg_per_m3).map(Self)
    }
}

impl Default for ColliderDensity {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl Validate for ColliderDensity {
    fn validate(&self) -> Result<()> {
        positive("collider density", self.0).map(|_| ())
    }
}

fn density_changed(mut world: DeferredWorld, ctx: HookContext) {
    validate_on_insert::<ColliderDensity>(world.reborrow(), ctx);
    queue_refresh_owner(&mut world, ctx.entity);
}

/// Where a child collider sits in its parent's frame (m and a unit quaternion). With the
/// `bevy` feature hooke writes it from the child's `Transform`.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = offset_changed)]
pub struct ColliderOffset {
    /// Translation in the parent's frame (m).
    pub translation: Vec3,
    /// Rotation relative to the parent.
    pub rotation: Quat,
}

impl Default for ColliderOffset {
    fn default() -> Self {
        Self {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        }
    }
}

impl ColliderOffset {
    /// A validated offset (the rotation is normalised).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite translation or a bad rotation.
    pub fn try_new(translation: Vec3, rotation: Quat) -> Result<Self> {
        Ok(Self {
            translation: finite_vec("collider offset", translation)?,
            rotation: Rotation::try_new(rotation)?.0,
        })
    }

    fn pose(&self) -> Pose {
        Pose::from_parts(self.translation, self.rotation.normalize())
    }
}

impl Validate for ColliderOffset {
    fn validate(&self) -> Result<()> {
        finite_vec("collider offset", self.translation)?;
        Rotation(self.rotation).validate()
    }
}

fn offset_changed(mut world: DeferredWorld, ctx: HookContext) {
    validate_on_insert::<ColliderOffset>(world.reborrow(), ctx);
    queue_refresh_owner(&mut world, ctx.entity);
}

/// Set by hooke on a child collider that is part of the body `body`. The child's own
/// [`Position`] and [`Rotation`] follow the body; the collision systems see only the body.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = attachment_changed, on_remove = attachment_changed)]
pub struct ColliderOf {
    /// The body this collider is part of.
    pub body: Entity,
    /// The collider's pose in the body's shape frame.
    pose: [f32; 7],
}

impl ColliderOf {
    /// The collider's pose in the body's shape frame (origin x − R c): translation (m) and
    /// rotation.
    #[must_use]
    pub fn local_pose(&self) -> (Vec3, Quat) {
        let p = self.pose;
        (
            Vec3::new(p[0], p[1], p[2]),
            Quat::from_xyzw(p[3], p[4], p[5], p[6]),
        )
    }
}

fn attachment_changed(mut world: DeferredWorld, ctx: HookContext) {
    crate::collision::broad_phase::mark_dirty(&mut world, ctx.entity);
}

/// The body's own collider while its [`Collider`] holds the compound of all its parts.
#[derive(serde::Serialize, serde::Deserialize, Component, Clone)]
pub(crate) struct OwnShape(Collider);

/// The most levels a collider part may sit below its body (a child is one level). A part
/// deeper than this is quarantined with [`Error::TooMany`] rather than left out silently:
/// the walk up from a part must stop somewhere, since game code can link `ChildOf` in a
/// cycle.
pub const MAX_PART_DEPTH: usize = 256;

/// What is above a collider on an entity.
enum Owner {
    /// The nearest body at or above it.
    Body(Entity),
    /// No body up to the root.
    None,
    /// More than [`MAX_PART_DEPTH`] levels and still no body (or a cycle).
    TooDeep,
}

/// The body a collider on `entity` belongs to: `entity` itself if it is a body, else the
/// nearest ancestor that is.
fn find_owner(world: &World, entity: Entity) -> Owner {
    let mut e = entity;
    for _ in 0..=MAX_PART_DEPTH {
        if world.get::<RigidBody>(e).is_some() {
            return Owner::Body(e);
        }
        match world.get::<ChildOf>(e) {
            Some(parent) => e = parent.parent(),
            None => return Owner::None,
        }
    }
    Owner::TooDeep
}

fn owner(world: &World, entity: Entity) -> Option<Entity> {
    match find_owner(world, entity) {
        Owner::Body(e) => Some(e),
        Owner::None | Owner::TooDeep => None,
    }
}

fn too_deep() -> Quarantined {
    Quarantined {
        reason: QuarantineReason::InvalidInput(Error::TooMany {
            what: "levels between a collider part and its body",
            max: MAX_PART_DEPTH as u64,
            got: MAX_PART_DEPTH as u64 + 1,
        }),
    }
}

/// Queues [`refresh_body`] for the body that owns a collider on `entity`, if any.
pub(crate) fn queue_refresh_owner(world: &mut DeferredWorld, entity: Entity) {
    let found = find_owner(world, entity);
    if matches!(found, Owner::TooDeep) && world.get::<Collider>(entity).is_some() {
        world.commands().entity(entity).try_insert(too_deep());
    }
    if let Owner::Body(body) = found {
        world
            .commands()
            .queue(move |world: &mut World| refresh_body(world, body));
    } else if let Some(body) = world.get::<ColliderOf>(entity).map(|c| c.body) {
        world
            .commands()
            .queue(move |world: &mut World| refresh_body(world, body));
    }
}

/// The body `entity`'s collider belongs to, refreshed (see [`queue_refresh_owner`]).
fn refresh_owner_of(world: &mut World, entity: Entity) {
    let body = owner(world, entity).or_else(|| world.get::<ColliderOf>(entity).map(|c| c.body));
    if let Some(body) = body {
        refresh_body(world, body);
    }
}

type WrittenPart<'a> = (
    Entity,
    Option<Ref<'a, ColliderDensity>>,
    Option<Ref<'a, ColliderOffset>>,
);

type WrittenFilter = (
    Or<(Changed<ColliderDensity>, Changed<ColliderOffset>)>,
    Without<Quarantined>,
);

/// A density or offset written through `get_mut` (past the insert hook) is checked as an
/// insert would be, and its body's mass and compound are rebuilt: before, such a write was
/// silently ignored (the body kept its old mass) and a NaN one was never reported.
///
/// A value inserted since the last step counts too, although its hook already did the
/// work: a write through `get_mut` right after the spawn, before the first step, carries
/// the same change tick as the insert and cannot be told apart. The cost is one more
/// rebuild of such a body, once.
pub(crate) fn refresh_written_parts(
    mut commands: Commands,
    parts: Query<WrittenPart, WrittenFilter>,
) {
    for (e, density, offset) in &parts {
        let written = |r: Option<bool>| r.unwrap_or(false);
        let d = written(density.as_ref().map(DetectChanges::is_changed));
        let o = written(offset.as_ref().map(DetectChanges::is_changed));
        if !(d || o) {
            continue;
        }
        let bad = [
            density.filter(|_| d).and_then(|v| v.validate().err()),
            offset.filter(|_| o).and_then(|v| v.validate().err()),
        ]
        .into_iter()
        .flatten()
        .next();
        if let Some(err) = bad {
            commands.entity(e).try_insert(Quarantined {
                reason: QuarantineReason::InvalidInput(err),
            });
        } else {
            commands.queue(move |world: &mut World| refresh_owner_of(world, e));
        }
    }
}

/// Observer: a body was spawned or changed kind.
pub(crate) fn on_body_inserted(event: On<Insert<RigidBody>>, mut commands: Commands) {
    let body = event.event().entity;
    commands.queue(move |world: &mut World| refresh_body(world, body));
}

/// Observer: an entity is leaving its parent; if it was a part of a body, the body drops it.
pub(crate) fn on_child_of_discarded(
    event: On<Discard<ChildOf>>,
    parts: Query<&ColliderOf>,
    mut commands: Commands,
) {
    let child = event.event().entity;
    if let Ok(part) = parts.get(child) {
        let body = part.body;
        commands.queue(move |world: &mut World| {
            if let Ok(mut e) = world.get_entity_mut(child) {
                e.remove::<ColliderOf>();
            }
            refresh_body(world, body);
        });
    }
}

/// A collider, or an entity that may have collider descendants.
type ColliderOrParent = Or<(With<Collider>, With<Children>)>;

/// Observer: an entity got a parent; a collider in its subtree may now be part of a body.
pub(crate) fn on_child_of_inserted(
    event: On<Insert<ChildOf>>,
    candidates: Query<(), ColliderOrParent>,
    mut commands: Commands,
) {
    let child = event.event().entity;
    // Hierarchies of a game are mostly not colliders (visuals, UI): skip those at once.
    if !candidates.contains(child) {
        return;
    }
    commands.queue(move |world: &mut World| {
        if let Some(body) = owner(world, child) {
            refresh_body(world, body);
        }
    });
}

struct Part {
    entity: Entity,
    pose: Pose,
    shape: SharedShape,
    density: f32,
}

fn is_composite(shape: &SharedShape) -> bool {
    shape.as_composite_shape().is_some()
}

/// Gathers the collider parts of `body`'s subtree (stopping at nested bodies), depth first
/// in `Children` order so that the compound is the same from run to run.
/// Colliders deeper than [`MAX_PART_DEPTH`] go to `too_deep` instead.
fn collect_parts(
    world: &World,
    body: Entity,
    own: Option<&Collider>,
    too_deep: &mut Vec<Entity>,
) -> Vec<Part> {
    let density = |e: Entity| {
        world
            .get::<ColliderDensity>(e)
            .map_or(ColliderDensity::DEFAULT.0, |d| d.0)
    };
    let mut parts = Vec::new();
    if let Some(own) = own {
        parts.push(Part {
            entity: body,
            pose: Pose::IDENTITY,
            shape: own.shape.clone(),
            density: density(body),
        });
    }
    let mut stack: Vec<(Entity, Pose, usize)> = Vec::new();
    let push_children = |stack: &mut Vec<(Entity, Pose, usize)>, e: Entity, pose, depth| {
        if let Some(children) = world.get::<Children>(e) {
            for c in children.iter().rev() {
                stack.push((c, pose, depth + 1));
            }
        }
    };
    push_children(&mut stack, body, Pose::IDENTITY, 0);
    while let Some((e, parent_pose, depth)) = stack.pop() {
        if world.get::<RigidBody>(e).is_some() || world.get::<Quarantined>(e).is_some() {
            continue;
        }
        if depth > MAX_PART_DEPTH {
            // Left for the caller to quarantine, with everything below it.
            if world.get::<Collider>(e).is_some() {
                too_deep.push(e);
            }
            push_children(&mut stack, e, parent_pose, depth);
            continue;
        }
        let offset = world
            .get::<ColliderOffset>(e)
            .map_or(Pose::IDENTITY, ColliderOffset::pose);
        let pose = parent_pose * offset;
        if let Some(c) = world.get::<Collider>(e).filter(|c| !c.composed) {
            parts.push(Part {
                entity: e,
                pose,
                shape: c.shape.clone(),
                density: density(e),
            });
        }
        push_children(&mut stack, e, pose, depth);
    }
    parts
}

/// Brings `body`'s compound collider, its parts' [`ColliderOf`] marks and (for a dynamic
/// body with no mass of the user's) its mass properties up to date.
pub(crate) fn refresh_body(world: &mut World, body: Entity) {
    let Some(kind) = world.get::<RigidBody>(body).copied() else {
        return;
    };
    let own = match (world.get::<OwnShape>(body), world.get::<Collider>(body)) {
        (Some(own), Some(c)) if c.composed => Some(own.0.clone()),
        (_, Some(c)) if !c.composed => Some(c.clone()),
        _ => None,
    };
    let mut deep = Vec::new();
    let mut parts = collect_parts(world, body, own.as_ref(), &mut deep);
    for e in deep {
        world.entity_mut(e).insert(too_deep());
    }

    // Parts parry cannot nest are left out; their entities are quarantined.
    let has_children = parts.iter().any(|p| p.entity != body);
    if has_children {
        let mut bad = Vec::new();
        parts.retain(|p| {
            let nested = p.entity != body && is_composite(&p.shape);
            if nested {
                bad.push((p.entity, p.shape.shape_type()));
            }
            !nested
        });
        for (e, ty) in bad {
            world.entity_mut(e).insert(Quarantined {
                reason: QuarantineReason::InvalidInput(Error::CompositePart(format!("{ty:?}"))),
            });
        }
    }

    mark_parts(world, body, &parts);
    set_shape(world, body, own, &parts);
    if kind == RigidBody::Dynamic {
        set_mass(world, body, &parts);
    }
}

/// Marks each child part [`ColliderOf`] this body with its pose; unmarks children no longer
/// part of it.
fn mark_parts(world: &mut World, body: Entity, parts: &[Part]) {
    for p in parts.iter().filter(|p| p.entity != body) {
        let (t, q) = (p.pose.translation, p.pose.rotation);
        let mark = ColliderOf {
            body,
            pose: [t.x, t.y, t.z, q.x, q.y, q.z, q.w],
        };
        if world.get::<ColliderOf>(p.entity) != Some(&mark) {
            world.entity_mut(p.entity).insert(mark);
        }
    }
}

/// The body's [`Collider`]: its own shape alone, or the compound of every part.
fn set_shape(world: &mut World, body: Entity, own: Option<Collider>, parts: &[Part]) {
    let children = parts.iter().any(|p| p.entity != body);
    if !children {
        // Back to the body's own shape (or none) if it had held a compound.
        if let Some(own_shape) = world.entity_mut(body).take::<OwnShape>() {
            world.entity_mut(body).insert(own_shape.0);
        } else if world.get::<Collider>(body).is_some_and(|c| c.composed) {
            world.entity_mut(body).remove::<Collider>();
        }
        return;
    }
    let mut shapes = Vec::with_capacity(parts.len());
    for p in parts {
        // The body's own compound contributes its parts (compounds do not nest).
        if let TypedShape::Compound(c) = p.shape.as_typed_shape() {
            shapes.extend(
                c.shapes()
                    .iter()
                    .map(|(pose, s)| (p.pose * *pose, s.clone())),
            );
        } else if !is_composite(&p.shape) {
            shapes.push((p.pose, p.shape.clone()));
        }
    }
    if shapes.is_empty() {
        return;
    }
    let Ok(mut compound) = Collider::new(SharedShape::compound(shapes)) else {
        return;
    };
    compound.composed = true;
    let mut e = world.entity_mut(body);
    if let Some(own) = own {
        e.insert(OwnShape(own));
    }
    e.insert(compound);
}

/// Mass, centre of mass and inertia of a dynamic body from its parts, unless the user gave
/// them. The body's frame origin stays where it is: x moves by R (c_new − c_old).
fn set_mass(world: &mut World, body: Entity, parts: &[Part]) {
    let user_mass = match (world.get::<Mass>(body), world.get::<ComputedMass>(body)) {
        (Some(m), Some(c)) => m.value() != c.mass,
        (Some(_), None) => true,
        _ => false,
    };
    if parts.is_empty() {
        return;
    }
    let total = parts
        .iter()
        .map(|p| p.shape.mass_properties(p.density).transform_by(&p.pose))
        .reduce(|a, b| a + b);
    let props = total
        .as_ref()
        .and_then(|t| mass_from_parry(t).ok())
        .unwrap_or_else(crate::rigid::default_mass);
    if !user_mass {
        crate::rigid::insert_computed_mass(world, body, props);
        return;
    }
    // The user's mass with the colliders' shape: their inertia scaled to that mass and their
    // centre of mass (as rapier and avian do), unless the user gave an inertia too. Without
    // it the body had no inertia at all and never turned.
    let Some(m) = world.get::<Mass>(body).map(Mass::value) else {
        return;
    };
    if world.get::<Inertia>(body).is_some() || !(m.is_finite() && m > 0.0) {
        return;
    }
    let inertia = props.inertia;
    let Ok(scaled) = Inertia::new(inertia.principal() * (m / props.mass), inertia.frame()) else {
        return;
    };
    if let Ok(scaled_props) = crate::rigid::MassProperties::new(m, props.center_of_mass, scaled) {
        crate::rigid::insert_computed_mass(world, body, scaled_props);
        // The mass is still the user's: a later collider change must not replace it.
        world.entity_mut(body).remove::<ComputedMass>();
    }
}

fn mass_from_parry(p: &ParryMass) -> Result<crate::rigid::MassProperties> {
    let mass = p.mass();
    if !(mass.is_finite() && mass > 0.0) {
        return Err(Error::InvalidMass(mass));
    }
    let inertia = Inertia::new(p.principal_inertia(), p.principal_inertia_local_frame)?;
    crate::rigid::MassProperties::new(mass, p.local_com, inertia)
}

type SoundBody<'a> = (&'a Position, &'a Rotation, Option<&'a CenterOfMass>);

/// After a step: every attached collider's [`Position`] and [`Rotation`] at its world pose.
/// The parts of a quarantined body stay where the body last was sound (its state may be
/// the non-finite one that quarantined it).
pub(crate) fn place_attached_colliders(
    bodies: Query<SoundBody, (Without<ColliderOf>, Without<Quarantined>)>,
    mut parts: Query<(&ColliderOf, &mut Position, &mut Rotation)>,
) {
    for (of, mut x, mut q) in &mut parts {
        let Ok((bx, bq, com)) = bodies.get(of.body) else {
            continue;
        };
        let c = com.map_or(Vec3::ZERO, |c| c.0);
        let (t, r) = of.local_pose();
        let origin = Vec3::from(bx.0) - bq.0 * c;
        let (nx, nq) = (Vec3A::from(origin + bq.0 * t), bq.0 * r);
        // Written without change ticks: hooke moves them, the user does not.
        if x.0 != nx {
            x.bypass_change_detection().0 = nx;
        }
        if q.0 != nq {
            q.bypass_change_detection().0 = nq;
        }
    }
}
