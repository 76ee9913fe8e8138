//! `Transform` ⇄ physics pose.
//!
//! hooke's state is the centre of mass x ([`Position`]) and the orientation q
//! ([`Rotation`]); a `Transform` places the entity's frame origin, which is x − R c for a
//! body with centre of mass c ([`CenterOfMass`], shape frame). Every body and collider
//! remembers the `Transform` hooke last wrote or read ([`SyncedTransform`]); a `Transform`
//! that differs was written by someone else, and becomes the physics pose before the next
//! step. That comparison of values, not of change ticks, is what makes a write through
//! `get_mut`, a `commands.insert` and an interpolated frame all behave the same.
//!
//! A kinematic body's written `Transform` is not a teleport but where it should be by the end
//! of the next step: hooke gives it a [`KinematicTarget`] for that step, so it moves there
//! with the velocity that takes it there and carries what rests on it (a platform moved by
//! its `Transform` every frame). After the step the target is taken off again and its
//! velocities zeroed: it stands still until the next write.
//!
//! On first sight a body's `Transform` wins, unless it is the identity while the physics
//! pose is not (a body spawned with `Position`): then the physics pose wins. Scale is left
//! alone and does not scale colliders: a body or collider whose `Transform` has a scale
//! other than one is reported once with a [`TransformScaleIgnored`] message.

use bevy_app::{App, Plugin};
use bevy_ecs::hierarchy::ChildOf;
use bevy_ecs::prelude::*;
use bevy_transform::components::{GlobalTransform, Transform};
use glam::{Quat, Vec3, Vec3A};

use super::SyncedTransform;
use super::interpolation::PoseHistory;
use super::{AppSchedule, PhysicsAppSystems};
use crate::collision::{Collider, ColliderOf, ColliderOffset};
use crate::core::quarantine::Quarantined;
use crate::particles::{LinearVelocity, Mass, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, KinematicTarget, RigidBody, Rotation};

/// Reads written `Transform`s before each step and writes poses back after it.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsTransformPlugin;

impl Plugin for PhysicsTransformPlugin {
    fn build(&self, app: &mut App) {
        let schedule = app
            .world()
            .get_resource::<AppSchedule>()
            .map_or_else(|| super::PhysicsSchedulePlugin::default().schedule, |s| s.0);
        app.add_systems(
            schedule,
            (
                (read_transforms, read_child_offsets, report_scales)
                    .in_set(PhysicsAppSystems::ReadTransforms),
                (write_transforms, release_transform_targets).in_set(PhysicsAppSystems::Writeback),
            ),
        );
        app.add_observer(place_on_spawn);
    }
}

/// A parent's world rotation.
fn pr_of(parent: Option<&ChildOf>, globals: &Query<&GlobalTransform>) -> Quat {
    parent_pose(parent, globals).1
}

/// A parent's world pose as (translation, rotation), ignoring scale.
fn parent_pose(parent: Option<&ChildOf>, globals: &Query<&GlobalTransform>) -> (Vec3, Quat) {
    parent
        .and_then(|p| globals.get(p.parent()).ok())
        .map_or((Vec3::ZERO, Quat::IDENTITY), |g| {
            let (_, r, t) = g.to_scale_rotation_translation();
            (t, r)
        })
}

type BodyPose<'a> = (
    Entity,
    &'a mut Transform,
    Option<&'a ChildOf>,
    Option<&'a SyncedTransform>,
    &'a Position,
    Option<&'a Rotation>,
    Option<&'a CenterOfMass>,
    Option<&'a mut PoseHistory>,
    Option<&'a RigidBody>,
);
type Posed = (
    Or<(With<RigidBody>, With<Collider>, With<Mass>)>,
    Without<ColliderOf>,
    Without<Quarantined>,
);

/// Written `Transform`s become [`Position`] and [`Rotation`] (inserted, so the broad phase,
/// the validating hooks and the sleep rules all hear of it).
fn read_transforms(
    mut commands: Commands,
    mut bodies: Query<BodyPose, Posed>,
    globals: Query<&GlobalTransform>,
) {
    for (e, mut t, parent, synced, x, q, com, history, body) in &mut bodies {
        if synced.is_some_and(|s| s.matches(&t)) {
            continue;
        }
        // A particle has no orientation of its own: its Transform keeps the one it has.
        let particle = q.is_none();
        let q = q
            .copied()
            .unwrap_or_else(|| Rotation(pr_of(parent, &globals) * t.rotation));
        let c = com.map_or(Vec3::ZERO, |c| c.0);
        let (pt, pr) = parent_pose(parent, &globals);
        if synced.is_none()
            && *t == Transform::IDENTITY
            && (x.0 != Vec3A::ZERO || q.0 != Quat::IDENTITY)
        {
            // Spawned through the physics API: the physics pose wins.
            let origin = Vec3::from(x.0) - q.0 * c;
            t.translation = pr.inverse() * (origin - pt);
            t.rotation = pr.inverse() * q.0;
            commands.entity(e).insert(SyncedTransform::of(&t));
            continue;
        }
        let rotation = (pr * t.rotation).normalize();
        let origin = pt + pr * t.translation;
        let centre = origin + rotation * c;
        if synced.is_some() && body == Some(&RigidBody::Kinematic) {
            // Moved, not teleported: reached by the end of the next step.
            commands.entity(e).insert((
                KinematicTarget {
                    position: centre,
                    rotation,
                },
                TargetFromTransform,
                SyncedTransform::of(&t),
            ));
            continue;
        }
        if let Some(mut h) = history {
            h.reset(t.translation, t.rotation);
        }
        let mut cmd = commands.entity(e);
        cmd.insert((Position(centre.into()), SyncedTransform::of(&t)));
        if !particle {
            cmd.insert(Rotation(rotation));
        }
    }
}

/// What [`place_on_spawn`] reads and writes.
type SpawnPose<'a> = (
    &'a Transform,
    &'a mut Position,
    Option<&'a mut Rotation>,
    Option<&'a CenterOfMass>,
);

/// Observer: a root body or collider spawned with a `Transform` has its physics pose at once,
/// so game code reading `Position` before the first fixed step sees where it was put.
fn place_on_spawn(
    event: On<Insert<Transform>>,
    mut bodies: Query<SpawnPose, (Posed, Without<ChildOf>, Without<SyncedTransform>)>,
) {
    let Ok((t, mut x, q, com)) = bodies.get_mut(event.event().entity) else {
        return;
    };
    if *t == Transform::IDENTITY {
        return;
    }
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    let rotation = match q {
        Some(mut q) => {
            q.0 = t.rotation.normalize();
            q.0
        }
        None => Quat::IDENTITY,
    };
    let centre = t.translation + rotation * c;
    if centre.is_finite() {
        x.0 = centre.into();
    }
}

type ChildPose<'a> = (
    Entity,
    &'a Transform,
    Option<&'a SyncedTransform>,
    Option<&'a ColliderOffset>,
);

/// A child collider's written `Transform` becomes its [`ColliderOffset`] in the body.
fn read_child_offsets(
    mut commands: Commands,
    children: Query<ChildPose, (With<ColliderOf>, Without<Quarantined>)>,
) {
    for (e, t, synced, offset) in &children {
        if synced.is_some_and(|s| s.matches(t)) {
            continue;
        }
        let new = ColliderOffset {
            translation: t.translation,
            rotation: t.rotation,
        };
        let mut cmd = commands.entity(e);
        if offset != Some(&new) {
            cmd.insert(new);
        }
        cmd.insert(SyncedTransform::of(t));
    }
}

type Written<'a> = (
    &'a Position,
    Option<&'a Rotation>,
    Option<&'a CenterOfMass>,
    Option<&'a ChildOf>,
    &'a mut Transform,
    Option<&'a mut SyncedTransform>,
    Option<&'a mut PoseHistory>,
);

/// Bodies whose pose the step moves.
type Moving = (
    With<LinearVelocity>,
    Without<ColliderOf>,
    Without<Quarantined>,
);

/// Moving bodies' poses become their `Transform`s (frame origin x − R c, in the parent's
/// frame), written only where they changed so that change detection stays meaningful.
fn write_transforms(
    mut commands: Commands,
    mut bodies: Query<(Entity, Written), Moving>,
    globals: Query<&GlobalTransform>,
) {
    for (e, (x, q, com, parent, mut t, synced, history)) in &mut bodies {
        let (pt, pr) = parent_pose(parent, &globals);
        let q = q.copied().unwrap_or_else(|| Rotation(pr * t.rotation));
        let c = com.map_or(Vec3::ZERO, |c| c.0);
        let origin = Vec3::from(x.0) - q.0 * c;
        let (translation, rotation) = if parent.is_some() {
            (pr.inverse() * (origin - pt), pr.inverse() * q.0)
        } else {
            (origin, q.0)
        };
        if t.translation != translation || t.rotation != rotation {
            t.translation = translation;
            t.rotation = rotation;
        }
        if let Some(mut h) = history {
            h.push(translation, rotation);
        }
        match synced {
            Some(mut s) => {
                if !s.matches(&t) {
                    *s = SyncedTransform::of(&t);
                }
            }
            None => {
                commands.entity(e).insert(SyncedTransform::of(&t));
            }
        }
    }
}

/// Marks a [`KinematicTarget`] hooke set from a written `Transform`, for one step.
#[derive(Component, Debug, Clone, Copy)]
pub(crate) struct TargetFromTransform;

/// After the step: a kinematic body moved by its `Transform` stops where it got to, until the
/// next write.
fn release_transform_targets(
    mut commands: Commands,
    mut bodies: Query<
        (Entity, &mut LinearVelocity, Option<&mut AngularVelocity>),
        With<TargetFromTransform>,
    >,
) {
    for (e, mut v, w) in &mut bodies {
        v.0 = Vec3A::ZERO;
        if let Some(mut w) = w {
            w.0 = Vec3A::ZERO;
        }
        commands
            .entity(e)
            .remove::<(KinematicTarget, TargetFromTransform)>();
    }
}

/// A body or collider's `Transform` has a scale other than one, which hooke does not apply
/// to its collider or mass: scale the shape itself (`Collider::cuboid` with the scaled half
/// extents, say). Written once per entity, the first time hooke sees the scale.
#[derive(bevy_ecs::message::Message, Debug, Clone, Copy, PartialEq)]
pub struct TransformScaleIgnored {
    /// The entity.
    pub entity: Entity,
    /// Its `Transform` scale.
    pub scale: Vec3,
}

/// Marks an entity whose ignored scale was reported.
#[derive(Component, Debug, Clone, Copy)]
pub(crate) struct ScaleReported;

type Scaled = (
    Or<(With<RigidBody>, With<Collider>)>,
    Without<ScaleReported>,
    Changed<Transform>,
);

/// Reports once each body or collider whose `Transform` scale is not one.
fn report_scales(
    mut commands: Commands,
    entities: Query<(Entity, &Transform), Scaled>,
    mut messages: bevy_ecs::message::MessageWriter<TransformScaleIgnored>,
) {
    for (e, t) in &entities {
        if t.scale != Vec3::ONE {
            messages.write(TransformScaleIgnored {
                entity: e,
                scale: t.scale,
            });
            commands.entity(e).insert(ScaleReported);
        }
    }
}
