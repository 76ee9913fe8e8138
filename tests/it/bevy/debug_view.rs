//! The debug view (feature `debug-plugin`) in a headless App: what it drew, read back from
//! the gizmo buffers `bevy_gizmos` hands a renderer.
#![cfg(feature = "debug-plugin")]

use std::any::TypeId;
use std::time::Duration;

use bevy_app::TaskPoolPlugin;
use bevy_app::prelude::*;
use bevy_asset::{AssetPlugin, Assets};
use bevy_color::{Color, LinearRgba};
use bevy_gizmos::GizmoHandles;
use bevy_gizmos::GizmoPlugin;
use bevy_gizmos::config::GizmoConfigStore;
use bevy_gizmos::prelude::GizmoAsset;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use glam::Vec3;
use hooke::bevy::{PhysicsDebugPlugin, PhysicsGizmos};
use hooke::prelude::*;

/// A headless App at `PhysicsPlugins` with the debug view, 60 Hz frames.
fn app() -> App {
    let mut app = App::new();
    app.add_plugins((
        TaskPoolPlugin::default(),
        TimePlugin,
        TransformPlugin,
        AssetPlugin::default(),
        GizmoPlugin,
        PhysicsPlugins,
        PhysicsDebugPlugin,
    ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 60.0,
    )));
    app.finish();
    app.cleanup();
    app
}

/// The line segments the debug view drew in the last frame with `colour`: list segments
/// and consecutive strip vertices (strips end at NaN separators).
fn drawn(app: &App, colour: Option<Color>) -> Vec<[Vec3; 2]> {
    let Some(colour) = colour else {
        return Vec::new();
    };
    let colour = LinearRgba::from(colour);
    let handles = app.world().resource::<GizmoHandles>();
    let Some(Some(handle)) = handles.handles().get(&TypeId::of::<PhysicsGizmos>()) else {
        return Vec::new();
    };
    let assets = app.world().resource::<Assets<GizmoAsset>>();
    let buffer = assets.get(handle).expect("the gizmo asset").buffer();
    let mut out = Vec::new();
    for (p, c) in buffer
        .list_positions
        .chunks(2)
        .zip(buffer.list_colors.chunks(2))
    {
        if c[0] == colour {
            out.push([p[0], p[1]]);
        }
    }
    let strip = &buffer.strip_positions;
    for i in 1..strip.len() {
        let (a, b) = (strip[i - 1], strip[i]);
        if a.is_finite() && b.is_finite() && buffer.strip_colors[i] == colour {
            out.push([a, b]);
        }
    }
    out
}

fn config(app: &mut App) -> &mut PhysicsGizmos {
    app.world_mut()
        .resource_mut::<GizmoConfigStore>()
        .into_inner()
        .config_mut::<PhysicsGizmos>()
        .1
}

#[test]
fn the_debug_view_draws_each_part_where_it_is_and_each_toggle_removes_it() {
    let mut app = app();
    let world = app.world_mut();
    world.spawn((
        RigidBody::Static,
        Collider::cuboid(5.0, 0.5, 5.0).unwrap(),
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    let ball = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 0.5, 0.0),
        ))
        .id();
    let crate_ = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.3, 0.3, 0.3).unwrap(),
            Transform::from_xyz(2.0, 3.0, 0.0),
            LinearVelocity::from(Vec3::new(1.0, 0.0, 0.0)),
        ))
        .id();
    // A rod hinged to the world at (−2, 3, 0), hanging.
    let rod = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.05, 0.5, 0.05).unwrap(),
            Transform::from_xyz(-2.0, 2.5, 0.0),
        ))
        .id();
    world.spawn(
        RevoluteJoint::to_world(rod, Vec3::Z)
            .with_anchors(Vec3::new(-2.0, 3.0, 0.0), Vec3::new(0.0, 0.5, 0.0)),
    );
    let cloth = ClothBuilder::new(Vec3::new(3.0, 4.0, 3.0), 4, 4, 0.1)
        .spawn(world)
        .unwrap();
    let rope = ChainBuilder::rope(Vec3::new(-3.0, 5.0, -3.0), Vec3::new(-2.0, 5.0, -3.0), 5)
        .spawn(world)
        .unwrap();
    let _ = (cloth, rope);
    let jelly = hooke::tools::scenes::jelly(world, Vec3::new(-3.0, 0.5, 3.0), true).unwrap();
    // A body whose velocity turns NaN: quarantined, and drawn so.
    let broken = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Transform::from_xyz(4.0, 1.0, -4.0),
        ))
        .id();
    for _ in 0..3 {
        app.update();
    }
    app.world_mut()
        .get_mut::<LinearVelocity>(broken)
        .unwrap()
        .0
        .x = f32::NAN;
    for _ in 0..17 {
        app.update();
    }
    let defaults = PhysicsGizmos::default();
    assert!(
        app.world()
            .get::<hooke::core::quarantine::Quarantined>(broken)
            .is_some()
    );
    // Its state is NaN; it is drawn at its last good pose (its `Transform`, x = 4).
    let quarantined = drawn(&app, defaults.quarantined);
    assert!(
        quarantined.len() > 20 && quarantined.iter().flatten().all(|p| p.x > 3.7),
        "{} segments",
        quarantined.len()
    );

    // Colliders: the ball's sphere lies on its surface (radius 0.5 about its centre).
    let centre = app.world().get::<Position>(ball).unwrap().get();
    let awake = drawn(&app, defaults.colliders);
    let on_ball: Vec<_> = awake
        .iter()
        .filter(|[a, _]| ((*a - centre).length() - 0.5).abs() < 1e-3)
        .collect();
    assert!(
        on_ball.len() > 20,
        "{} of {} segments on the ball",
        on_ball.len(),
        awake.len()
    );
    // The crate's 12 edges, each 0.6 m long, about its centre.
    let c = app.world().get::<Position>(crate_).unwrap().get();
    let edges = awake
        .iter()
        .filter(|[a, b]| ((*a - *b).length() - 0.6).abs() < 1e-4 && (*a - c).length() < 0.53)
        .count();
    assert_eq!(edges, 12, "the crate's edges");
    // The ground is fixed: its own colour, its top face at y = 0.
    let fixed = drawn(&app, defaults.fixed_colliders);
    assert_eq!(fixed.len(), 12);
    assert!(fixed.iter().flatten().any(|p| p.y.abs() < 1e-5));

    // The ball rests on the ground: its contact point near (0, 0, 0), its normal along y.
    let points = drawn(&app, defaults.contact_points);
    assert!(!points.is_empty(), "no contact point drawn");
    assert!(
        points
            .iter()
            .flatten()
            .all(|p| p.y.abs() < 0.05 && p.x.abs() < 0.05 && p.z.abs() < 0.05),
        "{points:?}"
    );
    let normals = drawn(&app, defaults.contact_normals);
    let shaft = normals.first().expect("a contact normal");
    let dir = (shaft[1] - shaft[0]).normalize();
    assert!(dir.y.abs() > 0.999, "normal {dir}");

    // The hinge: from the world anchor to the rod's anchor (a gap of nearly nothing) and on
    // to the rod's centre, 0.5 m below.
    let joints = drawn(&app, defaults.joints);
    assert_eq!(joints.len(), 3);
    let gap = (joints[1][1] - joints[1][0]).length();
    assert!(gap < 1e-3, "gap {gap}");
    assert!((joints[0][0] - Vec3::new(-2.0, 3.0, 0.0)).length() < 1e-6);
    let rod_x = app.world().get::<Position>(rod).unwrap().get();
    assert!((joints[2][1] - rod_x).length() < 1e-6);
    assert!(((joints[2][1] - joints[2][0]).length() - 0.5).abs() < 1e-3);

    // The jelly's surface: a 0.4 m cube of 3 × 3 × 3 cells, 6 × 9 squares of two
    // triangles, 162 edges, all within the cube's reach of its nodes.
    let soft = drawn(&app, defaults.soft_bodies);
    assert_eq!(soft.len(), 162);
    let nodes = app.world().get::<Nodes>(jelly).unwrap().positions();
    let mid: Vec3 = nodes.iter().map(|p| Vec3::from(*p)).sum::<Vec3>() / nodes.len() as f32;
    assert!(soft.iter().flatten().all(|p| (*p - mid).length() < 0.4));
    // Cloth: a 4 × 4 grid of nodes, 3 × 3 squares of two triangles, 3 edges each.
    assert_eq!(drawn(&app, defaults.cloth).len(), 18 * 3);
    // The rope: 4 springs between its 5 nodes, end to end from the pinned one.
    let rope_lines = drawn(&app, defaults.springs);
    assert_eq!(rope_lines.len(), 4, "{rope_lines:?}");
    assert_eq!(rope_lines[0][0], Vec3::new(-3.0, 5.0, -3.0));

    // Off by default: boxes and velocities. Turned on, the crate's box holds its collider
    // and its arrow points along +x.
    let (aabb, velocity) = (Color::srgb(1.0, 0.5, 0.0), Color::srgb(0.0, 0.0, 1.0));
    assert!(drawn(&app, Some(aabb)).is_empty() && drawn(&app, Some(velocity)).is_empty());
    config(&mut app).aabbs = Some(aabb);
    config(&mut app).velocities = Some(velocity);
    app.update();
    let boxes = drawn(&app, Some(aabb));
    assert_eq!(boxes.len() % 12, 0);
    assert!(boxes.len() >= 4 * 12, "{} box edges", boxes.len());
    let c = app.world().get::<Position>(crate_).unwrap().get();
    let near: Vec<Vec3> = boxes
        .iter()
        .flatten()
        .copied()
        .filter(|p| (*p - c).length() < 1.0)
        .collect();
    let (lo, hi) = near
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    // The box holds the crate (half extent 0.3), grown by no more than its margin.
    assert!(
        (c - lo).cmpge(Vec3::splat(0.3)).all() && (hi - c).cmpge(Vec3::splat(0.3)).all(),
        "{lo} {hi} about {c}"
    );
    assert!((hi - lo).max_element() < 1.0, "{lo} {hi}");
    let arrows = drawn(&app, Some(velocity));
    assert!(
        arrows
            .iter()
            .any(|[a, b]| (*a - c).length() < 1e-5 && b.x > a.x)
    );

    // The ball falls asleep on the ground and is drawn in the sleeping colour.
    for _ in 0..240 {
        app.update();
    }
    assert!(
        app.world()
            .get::<hooke::core::rest::Sleeping>(ball)
            .is_some()
    );
    let c = app.world().get::<Position>(ball).unwrap().get();
    let asleep = drawn(&app, defaults.sleeping);
    assert!(
        asleep
            .iter()
            .filter(|[a, _]| ((*a - c).length() - 0.5).abs() < 1e-3)
            .count()
            > 20
    );
    assert!(
        !drawn(&app, defaults.colliders)
            .iter()
            .any(|[a, _]| ((*a - c).length() - 0.5).abs() < 1e-3)
    );

    // Each toggle removes its part.
    let all = *config(&mut app);
    *config(&mut app) = PhysicsGizmos {
        colliders: None,
        fixed_colliders: None,
        contact_points: None,
        contact_normals: None,
        joints: None,
        sleeping: None,
        quarantined: None,
        soft_bodies: None,
        cloth: None,
        springs: None,
        aabbs: None,
        velocities: None,
        ..all
    };
    app.update();
    for colour in [
        all.colliders,
        all.fixed_colliders,
        all.contact_points,
        all.contact_normals,
        all.joints,
        all.sleeping,
        all.quarantined,
        all.soft_bodies,
        all.cloth,
        all.springs,
        all.aabbs,
        all.velocities,
    ] {
        assert!(drawn(&app, colour).is_empty(), "{colour:?} still drawn");
    }
}

#[test]
fn force_scaled_contact_arrows_are_as_long_as_the_weight_they_carry() {
    // A 2 kg box resting on the ground: with arrows of 0.05 m per newton, its normal is
    // 0.05 × m g = 0.981 m long (the pair's impulse is its last substep's, over h).
    let mut app = app();
    config(&mut app).contact_normal_scale = hooke::bevy::ContactGizmoScale::Force(0.05);
    let world = app.world_mut();
    world.spawn((
        RigidBody::Static,
        Collider::cuboid(5.0, 0.5, 5.0).unwrap(),
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    world.spawn((
        RigidBody::Dynamic,
        Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
        Mass::new(2.0).unwrap(),
        Transform::from_xyz(0.0, 0.25, 0.0),
    ));
    for _ in 0..30 {
        app.update();
    }
    let normals = drawn(&app, PhysicsGizmos::default().contact_normals);
    let shaft = normals.first().expect("a contact normal");
    let length = (shaft[1] - shaft[0]).length();
    let expected = 0.05 * 2.0 * 9.81;
    assert!(
        (length - expected).abs() < 0.02 * expected,
        "arrow {length} m vs {expected} m"
    );
}
