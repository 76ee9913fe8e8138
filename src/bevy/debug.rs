//! The debug view (feature `debug-plugin`): colliders, bounding boxes, contacts, joints,
//! cloth, soft bodies and velocities drawn with `bevy_gizmos`, each toggled in
//! [`PhysicsGizmos`].
//!
//! ```no_run
//! # use bevy_app::prelude::*;
//! # use hooke::prelude::*;
//! # use hooke::bevy::{PhysicsDebugPlugin, PhysicsGizmos};
//! # use bevy_gizmos::prelude::*;
//! App::new()
//!     // .add_plugins(DefaultPlugins): rendering, assets and `GizmoPlugin`
//!     .add_plugins((PhysicsPlugins, PhysicsDebugPlugin))
//!     .insert_gizmo_config(
//!         PhysicsGizmos { aabbs: Some(bevy_color::palettes::css::ORANGE.into()), ..default() },
//!         GizmoConfig::default(),
//!     );
//! # fn default<T: Default>() -> T { T::default() }
//! ```
//!
//! Everything is drawn at its physics pose ([`Position`], [`Rotation`]) in `PostUpdate`,
//! once per frame: a mesh whose `Transform` is interpolated lags that pose by up to a step.

use bevy_app::{App, Plugin, PostUpdate};
use bevy_color::Color;
use bevy_ecs::prelude::*;
use bevy_gizmos::prelude::*;
use bevy_math::Isometry3d;
use bevy_platform::collections::HashMap;
use bevy_reflect::Reflect;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::Shape;

use crate::cloth::Cloth;
use crate::collision::narrow_phase::Contacts;
use crate::collision::{Collider, ColliderAabb, ColliderOf, shape_pose};
use crate::core::quarantine::Quarantined;
use crate::core::rest::Sleeping;
use crate::core::time::PhysicsTime;
use crate::joints::{Kinds, bodies as joint_bodies};
use crate::particles::{LinearVelocity, Nodes, Position};
use crate::rigid::{CenterOfMass, RigidBody, Rotation};
use crate::soft::SoftBody;
use crate::springs::{Spring, SpringNetwork};

/// How long a contact's normal is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Reflect)]
pub enum ContactGizmoScale {
    /// Every normal this long (m).
    Constant(f32),
    /// The pair's contact force (its normal impulse over the step) times this (m per N),
    /// at least 1 cm: the longer the arrow, the harder the push.
    Force(f32),
}

/// What the debug view draws and in which colour; `None` leaves it out. A gizmo config
/// group: change it through `GizmoConfigStore::config_mut::<PhysicsGizmos>()`, or at start
/// with `insert_gizmo_config`.
#[derive(Debug, Clone, Copy, PartialEq, Reflect, GizmoConfigGroup)]
pub struct PhysicsGizmos {
    /// Colliders of awake dynamic bodies.
    pub colliders: Option<Color>,
    /// Colliders of static and kinematic bodies.
    pub fixed_colliders: Option<Color>,
    /// Colliders of sleeping bodies (drawn in `colliders`' place).
    pub sleeping: Option<Color>,
    /// Colliders of quarantined bodies (always drawn when set: the body stopped).
    pub quarantined: Option<Color>,
    /// Each collider's bounding box as of the last step ([`ColliderAabb`]).
    pub aabbs: Option<Color>,
    /// Contact points of touching pairs, as small crosses.
    pub contact_points: Option<Color>,
    /// Each touching pair's normal (from the lower entity to the higher), at the pair's
    /// points' centre.
    pub contact_normals: Option<Color>,
    /// How long the normals are.
    pub contact_normal_scale: ContactGizmoScale,
    /// Joints: from each body's centre to its anchor, and between the two anchors (a gap).
    pub joints: Option<Color>,
    /// Springs between nodes (ropes, hair, a mass-spring net), cloth excepted.
    pub springs: Option<Color>,
    /// Cloth: its triangles' edges.
    pub cloth: Option<Color>,
    /// Soft bodies: their surface triangles' edges.
    pub soft_bodies: Option<Color>,
    /// Each rigid body's linear velocity, from its centre of mass.
    pub velocities: Option<Color>,
    /// How long a velocity arrow is per m/s (s).
    pub velocity_scale: f32,
}

impl Default for PhysicsGizmos {
    /// Colliders, contacts, joints, cloth, springs and soft bodies on; boxes and velocities
    /// off.
    fn default() -> Self {
        Self {
            colliders: Some(Color::srgb(0.3, 0.8, 1.0)),
            fixed_colliders: Some(Color::srgb(0.6, 0.6, 0.6)),
            sleeping: Some(Color::srgb(0.2, 0.35, 0.5)),
            quarantined: Some(Color::srgb(1.0, 0.0, 1.0)),
            aabbs: None,
            contact_points: Some(Color::srgb(1.0, 0.9, 0.0)),
            contact_normals: Some(Color::srgb(1.0, 0.3, 0.1)),
            contact_normal_scale: ContactGizmoScale::Constant(0.25),
            joints: Some(Color::srgb(0.2, 1.0, 0.3)),
            springs: Some(Color::srgb(0.9, 0.7, 0.4)),
            cloth: Some(Color::srgb(0.9, 0.5, 0.8)),
            soft_bodies: Some(Color::srgb(0.5, 1.0, 0.7)),
            velocities: None,
            velocity_scale: 0.1,
        }
    }
}

/// Draws the physics state with gizmos (needs `bevy_gizmos`' `GizmoPlugin`, which Bevy's
/// `DefaultPlugins` include). Not in [`crate::plugins::PhysicsPlugins`]: add it beside it.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsDebugPlugin;

impl Plugin for PhysicsDebugPlugin {
    fn build(&self, app: &mut App) {
        app.init_gizmo_group::<PhysicsGizmos>();
        app.add_systems(
            PostUpdate,
            (
                draw_colliders,
                draw_contacts,
                draw_joints,
                draw_springs,
                draw_meshes,
                draw_velocities,
            )
                .run_if(debug_view_enabled),
        );
    }
}

/// Whether the debug view's gizmo group is switched on: when it is off, nothing of it runs.
fn debug_view_enabled(store: Res<GizmoConfigStore>) -> bool {
    store.config::<PhysicsGizmos>().0.enabled
}

/// A body's shape frame pose from its physics state.
fn pose_of(x: &Position, q: Option<&Rotation>, com: Option<&CenterOfMass>) -> Pose {
    shape_pose(x.0, q.map_or(Quat::IDENTITY, |q| q.0), com)
}

type ColliderView<'a> = (
    &'a Collider,
    &'a Position,
    Option<&'a Rotation>,
    Option<&'a CenterOfMass>,
    Option<&'a RigidBody>,
    Has<Sleeping>,
    Has<Quarantined>,
    Option<&'a ColliderAabb>,
    Option<&'a Transform>,
);

/// Colliders by state, and their boxes. A body's child colliders are parts of its
/// compound, drawn with it.
fn draw_colliders(
    mut gizmos: Gizmos<PhysicsGizmos>,
    colliders: Query<ColliderView, Without<ColliderOf>>,
) {
    let config = *gizmos.config_ext;
    let any = [
        config.colliders,
        config.fixed_colliders,
        config.sleeping,
        config.quarantined,
        config.aabbs,
    ];
    if !gizmos.config.enabled || any.iter().all(Option::is_none) {
        return;
    }
    for (collider, x, q, com, body, asleep, quarantined, aabb, t) in &colliders {
        let colour = if quarantined {
            config.quarantined
        } else if !matches!(body, None | Some(RigidBody::Dynamic)) {
            config.fixed_colliders
        } else if asleep {
            config.sleeping
        } else {
            config.colliders
        };
        // A quarantined body's state may be NaN: its `Transform` keeps its last good pose.
        let mut pose = pose_of(x, q, com);
        if !(pose.translation.is_finite() && pose.rotation.is_finite())
            && let Some(t) = t
        {
            pose = Pose::from_parts(t.translation, t.rotation);
        }
        if let Some(colour) = colour {
            draw_shape(&mut gizmos, collider.shape().as_ref(), &pose, colour);
        }
        if let (Some(colour), Some(b)) = (config.aabbs, aabb) {
            draw_box(&mut gizmos, b.min, b.max, colour);
        }
    }
}

/// Draws `shape` at `pose`: balls, boxes and capsules as themselves, hulls and triangle
/// meshes by their edges, compounds part by part, anything else by its bounding box.
fn draw_shape(gizmos: &mut Gizmos<PhysicsGizmos>, shape: &dyn Shape, pose: &Pose, colour: Color) {
    let iso = Isometry3d::new(pose.translation, pose.rotation);
    if let Some(ball) = shape.as_ball() {
        gizmos.sphere(iso, ball.radius, colour);
    } else if let Some(cuboid) = shape.as_cuboid() {
        let t = Transform {
            translation: pose.translation,
            rotation: pose.rotation,
            scale: 2.0 * cuboid.half_extents,
        };
        gizmos.cube(t, colour);
    } else if let Some(capsule) = shape.as_capsule() {
        // Its two end balls and four lines along its sides.
        let (a, b) = (*pose * capsule.segment.a, *pose * capsule.segment.b);
        let r = capsule.radius;
        for end in [a, b] {
            gizmos.sphere(Isometry3d::new(end, pose.rotation), r, colour);
        }
        let (u, v) = (b - a).normalize_or(Vec3::Y).any_orthonormal_pair();
        for side in [u, -u, v, -v] {
            gizmos.line(a + r * side, b + r * side, colour);
        }
    } else if let Some(hull) = shape.as_convex_polyhedron() {
        let points = hull.points();
        for e in hull.edges() {
            let [i, j] = e.vertices;
            gizmos.line(
                *pose * points[i as usize],
                *pose * points[j as usize],
                colour,
            );
        }
    } else if let Some(mesh) = shape.as_trimesh() {
        let v = mesh.vertices();
        for t in mesh.indices() {
            for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                gizmos.line(*pose * v[i as usize], *pose * v[j as usize], colour);
            }
        }
    } else if let Some(compound) = shape.as_compound() {
        for (part, shape) in compound.shapes() {
            draw_shape(gizmos, shape.as_ref(), &(*pose * *part), colour);
        }
    } else {
        let b = shape.compute_aabb(pose);
        draw_box(gizmos, b.mins, b.maxs, colour);
    }
}

/// An axis-aligned box between `min` and `max` (m).
fn draw_box(gizmos: &mut Gizmos<PhysicsGizmos>, min: Vec3, max: Vec3, colour: Color) {
    let t = Transform::from_translation(0.5 * (min + max)).with_scale(max - min);
    gizmos.cube(t, colour);
}

type BodyPose<'a> = (&'a Position, Option<&'a Rotation>, Option<&'a CenterOfMass>);

/// Touching pairs: their points as crosses and their normal at the points' centre.
fn draw_contacts(
    mut gizmos: Gizmos<PhysicsGizmos>,
    contacts: Option<Res<Contacts>>,
    time: Option<Res<PhysicsTime>>,
    bodies: Query<BodyPose>,
) {
    let config = *gizmos.config_ext;
    let Some(contacts) = contacts else {
        return;
    };
    if !gizmos.config.enabled
        || (config.contact_points.is_none() && config.contact_normals.is_none())
    {
        return;
    }
    // A pair's normal impulse is its last substep's: the force times the substep.
    let h = time.map_or(1.0 / 240.0, |t| t.substep_dt());
    for (a, b) in contacts.touching() {
        let Ok((x, q, com)) = bodies.get(a) else {
            continue;
        };
        let Some(pair) = contacts.pair_in_world(a, b, pose_of(x, q, com)) else {
            continue;
        };
        if pair.sensor || pair.points.is_empty() {
            continue;
        }
        if let Some(colour) = config.contact_points {
            for &p in &pair.points {
                gizmos.cross(Isometry3d::from_translation(p), 0.03, colour);
            }
        }
        if let Some(colour) = config.contact_normals {
            let centre = pair.points.iter().sum::<Vec3>() / pair.points.len() as f32;
            let length = match config.contact_normal_scale {
                ContactGizmoScale::Constant(l) => l,
                ContactGizmoScale::Force(s) => (s * pair.normal_impulse / h).max(0.01),
            };
            gizmos.arrow(centre, centre + length * pair.normal, colour);
        }
    }
}

/// Joints: body centre to anchor on each side, and anchor to anchor.
fn draw_joints(mut gizmos: Gizmos<PhysicsGizmos>, joints: Query<Kinds>, bodies: Query<BodyPose>) {
    let Some(colour) = gizmos.config_ext.joints.filter(|_| gizmos.config.enabled) else {
        return;
    };
    for kinds in &joints {
        let Some(j) = joint_bodies(kinds) else {
            continue;
        };
        let side = |e: Entity, anchor: Vec3| {
            bodies
                .get(e)
                .ok()
                .map(|(x, q, com)| (x.get(), pose_of(x, q, com) * anchor))
        };
        let a = match j.a {
            Some(a) => side(a, j.anchor_a),
            None => Some((j.anchor_a, j.anchor_a)),
        };
        let (Some((ca, pa)), Some((cb, pb))) = (a, side(j.b, j.anchor_b)) else {
            continue;
        };
        gizmos.line(ca, pa, colour);
        gizmos.line(pa, pb, colour);
        gizmos.line(pb, cb, colour);
    }
}

/// Spring entities (ropes and hair of node entities, springs between bodies): anchor to
/// anchor.
fn draw_springs(
    mut gizmos: Gizmos<PhysicsGizmos>,
    springs: Query<&Spring>,
    bodies: Query<BodyPose>,
) {
    let Some(colour) = gizmos.config_ext.springs.filter(|_| gizmos.config.enabled) else {
        return;
    };
    for s in &springs {
        let (anchor_a, anchor_b) = s.anchors();
        // A spring's anchors are taken from the centre of mass (see `Spring::reading`).
        let end = |e: Entity, anchor: Vec3| {
            bodies
                .get(e)
                .ok()
                .map(|(x, q, _)| x.get() + q.map_or(anchor, |q| q.0 * anchor))
        };
        if let (Some(a), Some(b)) = (end(s.a(), anchor_a), end(s.b(), anchor_b)) {
            gizmos.line(a, b, colour);
        }
    }
}

/// Per soft body: its element count when its surface was found, and the surface's edges.
type Surfaces = HashMap<Entity, (usize, Vec<[u32; 2]>)>;

/// Spring networks, cloth and soft bodies by their edges. A soft body's surface is found
/// once per mesh and kept.
fn draw_meshes(
    mut gizmos: Gizmos<PhysicsGizmos>,
    nets: Query<(&Nodes, &SpringNetwork, Option<&Cloth>)>,
    soft: Query<(Entity, &Nodes, &SoftBody)>,
    mut surfaces: Local<Surfaces>,
) {
    let config = *gizmos.config_ext;
    if !gizmos.config.enabled {
        return;
    }
    let line = |gizmos: &mut Gizmos<PhysicsGizmos>, p: &[glam::Vec3A], [i, j]: [u32; 2], c| {
        if let (Some(a), Some(b)) = (p.get(i as usize), p.get(j as usize)) {
            gizmos.line(Vec3::from(*a), Vec3::from(*b), c);
        }
    };
    for (nodes, springs, cloth) in &nets {
        let p = nodes.positions();
        match (cloth, config.cloth, config.springs) {
            (Some(cloth), Some(c), _) => {
                for t in cloth.triangles() {
                    for e in [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]] {
                        line(&mut gizmos, p, e, c);
                    }
                }
            }
            (None, _, Some(c)) => {
                for &e in springs.ends() {
                    line(&mut gizmos, p, e, c);
                }
            }
            _ => {}
        }
    }
    let Some(c) = config.soft_bodies else {
        return;
    };
    for (e, nodes, body) in &soft {
        let tets = body.tets();
        let entry = surfaces.entry(e).or_default();
        if entry.0 != tets.len() || entry.1.is_empty() {
            *entry = (tets.len(), surface_edges(tets));
        }
        let p = nodes.positions();
        for &edge in &entry.1 {
            line(&mut gizmos, p, edge, c);
        }
    }
}

/// Rigid bodies' linear velocities as arrows.
fn draw_velocities(
    mut gizmos: Gizmos<PhysicsGizmos>,
    bodies: Query<(&Position, &LinearVelocity), With<RigidBody>>,
) {
    let (Some(colour), scale) = (
        gizmos.config_ext.velocities,
        gizmos.config_ext.velocity_scale,
    ) else {
        return;
    };
    for (x, v) in &bodies {
        let v = v.get();
        if v != Vec3::ZERO {
            gizmos.arrow(x.get(), x.get() + scale * v, colour);
        }
    }
}

/// The edges of the boundary of `tets` (its surface triangles), each once, sorted.
#[must_use]
fn surface_edges(tets: &[[u32; 4]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = crate::soft::mesh::surface_of(tets)
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}
