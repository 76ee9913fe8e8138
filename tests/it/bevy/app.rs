//! hooke in a Bevy `App` (feature `bevy`), tried the way a game uses it. Each test is a trap a
//! new user fell into before the `bevy` feature existed; see issue 11.
#![cfg(feature = "bevy")]

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::{GlobalTransform, Transform};
use glam::{Quat, Vec3};
use hooke::bevy::{PhysicsDiagnosticsPlugin, PoseHistory, TransformInterpolation};
use hooke::collision::CollisionEventsEnabled;
use hooke::collision::ContactStart;
use hooke::collision::ContactStarted;
use hooke::core::time::PhysicsTime;
use hooke::prelude::*;

/// An App with time, transforms and every hooke plugin, whose frames are `frame_hz` long.
fn app(frame_hz: f64) -> App {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / frame_hz,
    )));
    app.finish();
    app.cleanup();
    app
}

fn frames(app: &mut App, n: usize) {
    for _ in 0..n {
        app.update();
    }
}

fn ground(commands: &mut Commands) -> Entity {
    commands
        .spawn((
            RigidBody::Static,
            Collider::cuboid(50.0, 0.5, 50.0).unwrap(),
            Transform::from_xyz(0.0, -0.5, 0.0),
        ))
        .id()
}

fn spawn<B: Bundle>(app: &mut App, bundle: B) -> Entity {
    app.world_mut().spawn(bundle).id()
}

fn translation(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Transform>(e).unwrap().translation
}

fn fixed_steps(app: &App) -> u64 {
    app.world().resource::<PhysicsTime>().steps()
}

#[test]
fn a_body_spawned_like_avian_falls() {
    let mut app = app(60.0);
    let body = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Transform::from_xyz(0.0, 5.0, 0.0),
        ),
    );
    // Placed at spawn, before any fixed step reads the Transform.
    assert_eq!(
        app.world().get::<Position>(body).unwrap().get(),
        Vec3::new(0.0, 5.0, 0.0)
    );
    frames(&mut app, 61);
    let n = fixed_steps(&app) as f32;
    assert!(n > 60.0, "{n} fixed steps");
    // Symplectic Euler with 4 substeps at Time<Fixed>'s 64 Hz: y = 5 − g h² m(m+1)/2 after
    // m = 4n substeps; the Transform is the frame origin, here the centre of mass.
    let (h, m) = (1.0 / 256.0f32, 4.0 * n);
    let expected = 5.0 - 9.81 * h * h * m * (m + 1.0) / 2.0;
    let y = translation(&app, body).y;
    assert!((y - expected).abs() < 1e-3, "y {y}, closed form {expected}");
}

#[test]
fn a_body_spawned_with_position_keeps_it() {
    let mut app = app(60.0);
    let body = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position::from(Vec3::new(3.0, 10.0, 0.0)),
        ),
    );
    frames(&mut app, 2);
    let t = translation(&app, body);
    assert!((t.x - 3.0).abs() < 1e-6 && t.y > 9.9 && t.y < 10.0, "{t}");
}

#[test]
fn a_child_collider_moves_with_its_parent() {
    let mut app = app(60.0);
    let mut commands = app.world_mut().commands();
    ground(&mut commands);
    let body = commands
        .spawn((
            RigidBody::Dynamic,
            Transform::from_xyz(0.0, 3.0, 0.0),
            children![
                (
                    Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
                    Transform::from_xyz(-1.0, 0.0, 0.0)
                ),
                (
                    Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
                    Transform::from_xyz(1.0, 0.0, 0.0)
                ),
            ],
        ))
        .id();
    app.world_mut().flush();
    frames(&mut app, 180);
    let world = app.world();
    let mass = world.get::<Mass>(body).unwrap().value();
    assert!((mass - 2000.0).abs() < 0.1, "two 1000 kg cubes: {mass}");
    let t = translation(&app, body);
    assert!(
        (t.y - 0.5).abs() < 0.01,
        "the dumbbell rests on both cubes: {t}"
    );
    let children: Vec<Entity> = world.get::<Children>(body).unwrap().iter().collect();
    for (c, dx) in children.iter().zip([-1.0f32, 1.0]) {
        let g = world.get::<GlobalTransform>(*c).unwrap().translation();
        assert!((g - (t + Vec3::X * dx)).length() < 0.01, "child at {g}");
        assert!(world.get::<ColliderOf>(*c).is_some());
    }
}

#[test]
fn writing_a_static_shelfs_transform_moves_it_and_a_ball_lands_on_it() {
    let mut app = app(60.0);
    let shelf = spawn(
        &mut app,
        (
            RigidBody::Static,
            Collider::cuboid(1.0, 0.1, 1.0).unwrap(),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ),
    );
    let ball = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Transform::from_xyz(10.0, 4.0, 0.0),
        ),
    );
    frames(&mut app, 5);
    // As a game would: through `get_mut`, no insert.
    app.world_mut()
        .get_mut::<Transform>(shelf)
        .unwrap()
        .translation = Vec3::new(10.0, 2.0, 0.0);
    frames(&mut app, 120);
    let y = translation(&app, ball).y;
    assert!(
        (y - 2.3).abs() < 0.01,
        "the ball rests on the moved shelf: y {y}"
    );
    let p = app.world().get::<Position>(shelf).unwrap().get();
    assert_eq!(p, Vec3::new(10.0, 2.0, 0.0));
}

#[test]
fn physics_time_is_time_fixed_at_every_frame_rate() {
    for hz in [20.0, 60.0, 144.0] {
        let mut app = app(hz);
        spawn(&mut app, (RigidBody::Dynamic, Collider::ball(0.5).unwrap()));
        frames(&mut app, 600);
        let fixed = app.world().resource::<Time<Fixed>>();
        let (t_fixed, dt) = (fixed.elapsed_secs_f64(), fixed.timestep());
        let time = app.world().resource::<PhysicsTime>();
        assert_eq!(time.elapsed(), t_fixed, "at {hz} Hz frames");
        assert_eq!(time.dt(), dt.as_secs_f32());
        assert_eq!(time.steps(), (t_fixed / dt.as_secs_f64()).round() as u64);
        // 600 frames of 1/hz s, less the first frame (Bevy's clock starts on it) and the
        // fraction of a step not yet run.
        let wall = 599.0 / hz;
        assert!(
            (t_fixed - wall).abs() <= dt.as_secs_f64(),
            "{t_fixed} vs {wall}"
        );
    }
}

#[derive(Resource, Default)]
struct Landed(Vec<Entity>);

#[derive(Resource, Default)]
struct Observed(Vec<Entity>);

#[test]
fn a_reader_in_update_sees_every_landing_at_20_hz_frames() {
    let mut app = app(20.0);
    app.init_resource::<Landed>().init_resource::<Observed>();
    app.add_systems(
        Update,
        |mut reader: MessageReader<ContactStarted>, mut landed: ResMut<Landed>| {
            for m in reader.read() {
                for e in [m.a, m.b] {
                    if !landed.0.contains(&e) {
                        landed.0.push(e);
                    }
                }
            }
        },
    );
    let mut commands = app.world_mut().commands();
    let ground = ground(&mut commands);
    let balls: Vec<Entity> = (0..20)
        .map(|i| {
            // Staggered heights: the landings fall on different steps of different frames.
            let h = 0.3 + 0.037 * i as f32;
            commands
                .spawn((
                    RigidBody::Dynamic,
                    Collider::ball(0.1).unwrap(),
                    Transform::from_xyz(i as f32, h, 0.0),
                    CollisionEventsEnabled,
                ))
                .observe(|event: On<ContactStart>, mut seen: ResMut<Observed>| {
                    seen.0.push(event.entity);
                })
                .id()
        })
        .collect();
    app.world_mut().flush();
    frames(&mut app, 40);
    let landed = &app.world().resource::<Landed>().0;
    let seen = balls.iter().filter(|b| landed.contains(b)).count();
    assert_eq!(seen, 20, "landings seen in Update");
    assert!(landed.contains(&ground));
    let observed = &app.world().resource::<Observed>().0;
    assert_eq!(
        balls.iter().filter(|b| observed.contains(b)).count(),
        20,
        "landings observed"
    );
    // And the App rotates them: once everything rests, nothing piles up.
    frames(&mut app, 40);
    let left = app.world().resource::<Messages<ContactStarted>>().len();
    assert!(left < 5, "{left} old messages kept");
}

#[derive(Resource, Default)]
struct StepPoses(Vec<Vec3>);

#[test]
fn interpolation_renders_on_the_segment_between_the_last_two_steps() {
    let mut app = app(144.0);
    app.init_resource::<StepPoses>();
    let body = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 50.0, 0.0),
            LinearVelocity::from(Vec3::new(3.0, 0.0, 0.0)),
            TransformInterpolation,
        ),
    );
    // Each step's physics pose, recorded right after the step.
    app.add_systems(
        FixedPostUpdate,
        (move |bodies: Query<&Position>, mut poses: ResMut<StepPoses>| {
            poses.0.push(bodies.get(body).unwrap().get());
        })
        .after(hooke::bevy::PhysicsAppSystems::Step),
    );
    let (mut checked, mut between) = (0, 0);
    for _ in 0..100 {
        app.update();
        let poses = &app.world().resource::<StepPoses>().0;
        if poses.len() < 2 {
            continue;
        }
        let (p0, p1) = (poses[poses.len() - 2], poses[poses.len() - 1]);
        let alpha = app.world().resource::<Time<Fixed>>().overstep_fraction();
        let shown = translation(&app, body);
        let expected = p0.lerp(p1, alpha);
        assert!((shown - expected).length() < 1e-4, "{shown} vs {expected}");
        let [h0, h1] = app.world().get::<PoseHistory>(body).unwrap().poses();
        assert_eq!((h0.0, h1.0), (p0, p1));
        checked += 1;
        // 144 Hz frames against 64 Hz steps: most frames fall between two steps.
        if alpha > 0.2 && alpha < 0.8 && (p1 - p0).length() > 1e-3 {
            between += 1;
        }
    }
    assert!(
        checked > 90 && between > 20,
        "{checked} frames, {between} between steps"
    );
    assert_eq!(app.world().get::<Rotation>(body).unwrap().0, Quat::IDENTITY);
}

#[test]
fn diagnostics_reach_the_diagnostics_store() {
    let mut app = App::new();
    app.add_plugins((
        TimePlugin,
        TransformPlugin,
        PhysicsPlugins,
        bevy_diagnostic::DiagnosticsPlugin,
        PhysicsDiagnosticsPlugin,
    ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 60.0,
    )));
    for i in 0..3 {
        spawn(
            &mut app,
            (
                RigidBody::Dynamic,
                Collider::ball(0.5).unwrap(),
                Transform::from_xyz(2.0 * i as f32, 5.0, 0.0),
            ),
        );
    }
    // A rope too stiff for the substep: rescued, and the rescue's price reported.
    hooke::springs::ChainBuilder::rope(Vec3::new(0.0, 8.0, 0.0), Vec3::new(1.0, 8.0, 0.0), 20)
        .stiffness(3.7e5)
        .spawn(app.world_mut())
        .unwrap();
    app.finish();
    app.cleanup();
    frames(&mut app, 10);
    let store = app.world().resource::<bevy_diagnostic::DiagnosticsStore>();
    let bodies = store
        .get(&PhysicsDiagnosticsPlugin::RIGID_BODIES)
        .and_then(|d| d.value());
    assert_eq!(bodies, Some(3.0));
    let rescued = store
        .get(&PhysicsDiagnosticsPlugin::RESCUED)
        .and_then(|d| d.value());
    assert_eq!(rescued, Some(1.0));
    let price = store
        .get(&PhysicsDiagnosticsPlugin::NUMERICAL_DAMPING)
        .and_then(|d| d.value())
        .unwrap();
    assert!(price.is_finite(), "{price}");
    let ke = store
        .get(&PhysicsDiagnosticsPlugin::KINETIC_ENERGY)
        .and_then(|d| d.value())
        .unwrap();
    assert!(ke > 0.0, "falling bodies have kinetic energy: {ke}");
}

#[test]
fn the_schedule_is_configurable() {
    let mut app = App::new();
    app.add_plugins((
        TimePlugin,
        TransformPlugin,
        PhysicsPlugins
            .build()
            .set(hooke::bevy::PhysicsSchedulePlugin::new(FixedUpdate)),
    ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / 64.0,
    )));
    let body = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 5.0, 0.0),
        ),
    );
    app.finish();
    app.cleanup();
    frames(&mut app, 11);
    assert_eq!(fixed_steps(&app), 10);
    assert!(translation(&app, body).y < 5.0);
}

#[test]
fn extrapolation_renders_ahead_of_the_last_step_by_the_velocity() {
    let mut app = app(144.0);
    app.world_mut()
        .insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let v = Vec3::new(2.0, 0.0, -1.0);
    let body = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 1.0, 0.0),
            LinearVelocity::from(v),
            hooke::bevy::TransformExtrapolation,
        ),
    );
    let mut ahead = 0;
    for _ in 0..60 {
        app.update();
        if fixed_steps(&app) == 0 {
            continue;
        }
        let fixed = app.world().resource::<Time<Fixed>>();
        let lead = fixed.overstep().as_secs_f32();
        let x = app.world().get::<Position>(body).unwrap().get();
        let shown = translation(&app, body);
        assert!(
            (shown - (x + v * lead)).length() < 1e-4,
            "{shown} vs {x} + v·{lead}"
        );
        if lead > 1e-3 {
            ahead += 1;
        }
    }
    assert!(ahead > 30, "{ahead} frames ahead of the step");
}

#[test]
fn despawning_mid_run_leaves_the_rest_running() {
    let mut app = app(20.0);
    let mut commands = app.world_mut().commands();
    ground(&mut commands);
    let keep = commands
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Transform::from_xyz(0.0, 2.0, 0.0),
            TransformInterpolation,
        ))
        .id();
    let gone = commands
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
            Transform::from_xyz(1.0, 0.2, 0.0),
            TransformInterpolation,
            CollisionEventsEnabled,
        ))
        .id();
    let dumbbell = commands
        .spawn((
            RigidBody::Dynamic,
            Transform::from_xyz(-3.0, 1.0, 0.0),
            children![
                (
                    Collider::ball(0.2).unwrap(),
                    Transform::from_xyz(-0.5, 0.0, 0.0)
                ),
                (
                    Collider::ball(0.2).unwrap(),
                    Transform::from_xyz(0.5, 0.0, 0.0)
                ),
            ],
        ))
        .id();
    app.world_mut().flush();
    frames(&mut app, 5);
    app.world_mut().entity_mut(gone).despawn();
    let part = app.world().get::<Children>(dumbbell).unwrap()[1];
    app.world_mut().entity_mut(part).despawn();
    frames(&mut app, 40);
    let y = translation(&app, keep).y;
    assert!((y - 0.2).abs() < 0.01, "the ball landed: {y}");
    let m = app.world().get::<Mass>(dumbbell).unwrap().value();
    let one = 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.008;
    assert!((m - one).abs() < 0.01 * one, "one ball left: {m} kg");
    let t = translation(&app, dumbbell);
    assert!(
        (t.y - 0.2).abs() < 0.02,
        "the one-ball dumbbell rests on it: {t}"
    );
    assert_eq!(
        app.world()
            .resource::<PhysicsDiagnostics>()
            .quarantined_total,
        0
    );
}

#[test]
fn a_door_hinged_in_an_app_swings_about_its_hinge() {
    // `PhysicsPlugins` as a plugin group brings the joints: a 1 m door hinged at its left
    // edge about the vertical, pushed at its free edge, turns and keeps its hinge in place.
    let mut app = app(144.0);
    let door = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 1.0, 0.05).unwrap(),
            Transform::from_xyz(0.5, 1.5, 0.0),
            GravityScale(0.0),
            LinearVelocity(Vec3A::new(0.0, 0.0, 1.0)),
        ),
    );
    spawn(
        &mut app,
        RevoluteJoint::to_world(door, Vec3::Y)
            .with_anchors(Vec3::new(0.0, 1.5, 0.0), Vec3::new(-0.5, 0.0, 0.0)),
    );
    frames(&mut app, 144);
    let t = app.world().get::<Transform>(door).unwrap();
    let hinge = t.translation + t.rotation * Vec3::new(-0.5, 0.0, 0.0);
    assert!(hinge.distance(Vec3::new(0.0, 1.5, 0.0)) < 0.01, "{hinge}");
    // It turned about y (away from its start), and only about y.
    let (axis, angle) = t.rotation.to_axis_angle();
    assert!(angle > 0.5, "turned {angle} rad");
    assert!(axis.y.abs() > 0.999, "about {axis}");
}

#[derive(Resource, Default)]
struct ScalesSeen(Vec<(Entity, Vec3)>);

#[test]
fn a_scaled_transform_is_reported_once_not_silently_ignored() {
    let mut app = app(60.0);
    app.init_resource::<ScalesSeen>();
    app.add_systems(
        Update,
        |mut reader: MessageReader<hooke::bevy::TransformScaleIgnored>,
         mut seen: ResMut<ScalesSeen>| {
            seen.0.extend(reader.read().map(|m| (m.entity, m.scale)));
        },
    );
    let scaled = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 5.0, 0.0).with_scale(Vec3::splat(2.0)),
        ),
    );
    let plain = spawn(
        &mut app,
        (
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(3.0, 5.0, 0.0),
        ),
    );
    frames(&mut app, 30);
    let seen = &app.world().resource::<ScalesSeen>().0;
    assert_eq!(seen, &vec![(scaled, Vec3::splat(2.0))]);
    assert!(!seen.iter().any(|(e, _)| *e == plain));
}
