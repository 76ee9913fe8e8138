//! A stack to knock over, a ball to throw and a character to walk: hooke in a windowed Bevy
//! game.
//!
//! - **WASD**: walk the character (a capsule with hooke's `CharacterController`) up the
//!   stairs, down the ramp, into the crate; **Space**: jump.
//! - **Left click**: throw a steel ball from the camera towards the cursor.
//! - **T**: throw one straight at the stack.
//! - **R**: rebuild the stack.
//! - **G**: show or hide the debug view (colliders, contacts, velocities).
//! - **Arrow keys**: orbit the camera, which follows the character.
//!
//! ```sh
//! cargo run --release --manifest-path examples/bevy_game/Cargo.toml   # add --ignore-rust-version on Rust < 1.97.1
//! cargo run --release --manifest-path examples/bevy_game/Cargo.toml -- --debug   # debug view on from the start
//! cargo run --release --manifest-path examples/bevy_game/Cargo.toml -- --walk    # the character walks the course by itself
//! ```

// Both preludes glob-imported, warnings denied: hooke's names must not clash with Bevy's.
#![deny(warnings)]

use bevy::prelude::*;
use hooke::bevy::{PhysicsDebugPlugin, PhysicsGizmos};
use hooke::prelude::*;
use hooke::tools::character_scenes::CharacterCourse;

/// Half extent of a crate (m).
const HALF: f32 = 0.25;

/// Where the character course sits on the floor (m): beside the stack.
const COURSE: Vec3 = Vec3::new(-7.0, 0.0, 5.0);

/// Walking speed (m/s) and jump speed (m/s: a 0.8 m jump).
const WALK: f32 = 3.0;
const JUMP: f32 = 4.0;

#[derive(Component)]
struct Player;

#[derive(Component)]
struct Crate;

#[derive(Component)]
struct Thrown;

#[derive(Resource)]
struct Look {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

#[derive(Resource)]
struct Assets3d {
    crate_mesh: Handle<Mesh>,
    crate_material: Handle<StandardMaterial>,
    ball_mesh: Handle<Mesh>,
    ball_material: Handle<StandardMaterial>,
}

fn main() {
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window {
                title: "hooke: knock the stack over".into(),
                ..default()
            }),
            ..default()
        }))
        .add_plugins((PhysicsPlugins, PhysicsDebugPlugin))
        .insert_gizmo_config(
            PhysicsGizmos {
                velocities: Some(Color::srgb(0.2, 0.4, 1.0)),
                ..default()
            },
            GizmoConfig {
                enabled: std::env::args().any(|a| a == "--debug"),
                // Drawn over the meshes, two pixels wide: the outlines lie on the surfaces.
                depth_bias: -1.0,
                line: GizmoLineConfig {
                    width: 2.0,
                    ..default()
                },
                ..default()
            },
        )
        .insert_resource(Time::<Fixed>::from_hz(60.0))
        .insert_resource(Look {
            yaw: 0.0,
            pitch: 0.35,
            distance: 10.0,
        })
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (
                steer_player,
                orbit_camera.after(steer_player),
                throw,
                rebuild,
                toggle_debug_view,
            ),
        )
        .run();
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) -> Result {
    let assets = Assets3d {
        crate_mesh: meshes.add(Cuboid::new(2.0 * HALF, 2.0 * HALF, 2.0 * HALF)),
        crate_material: materials.add(Color::srgb(0.8, 0.55, 0.3)),
        ball_mesh: meshes.add(Sphere::new(0.2)),
        ball_material: materials.add(Color::srgb(0.6, 0.6, 0.65)),
    };
    commands.spawn((
        RigidBody::Static,
        Collider::cuboid(15.0, 0.5, 15.0)?, // half extents: a 30 m × 1 m × 30 m floor
        Mesh3d(meshes.add(Cuboid::new(30.0, 1.0, 30.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.3, 0.5, 0.3))),
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    spawn_stack(&mut commands, &assets)?;
    commands.insert_resource(assets);
    spawn_course(&mut commands, &mut meshes, &mut materials)?;
    commands.spawn((
        DirectionalLight {
            illuminance: 10_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(4.0, 10.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((Camera3d::default(), Transform::default()));
    commands.spawn((
        Text::new(
            "WASD: walk  |  space: jump  |  left click: throw at the cursor  |  T: throw  |  R: rebuild  |  G: debug view  |  arrows: orbit",
        ),
        Node {
            position_type: PositionType::Absolute,
            top: px(8),
            left: px(8),
            ..default()
        },
    ));
    Ok(())
}

/// A 4 × 4 wall of crates, 6 high.
fn spawn_stack(commands: &mut Commands, assets: &Assets3d) -> Result {
    for row in 0..6 {
        for col in 0..4 {
            let x = (col as f32 - 1.5) * 2.0 * HALF + if row % 2 == 1 { 0.1 } else { 0.0 };
            commands.spawn((
                Crate,
                RigidBody::Dynamic,
                Collider::cuboid(HALF, HALF, HALF)?,
                ColliderDensity::try_new(300.0)?, // wood
                Mesh3d(assets.crate_mesh.clone()),
                MeshMaterial3d(assets.crate_material.clone()),
                Transform::from_xyz(x, HALF + row as f32 * 2.0 * HALF, 0.0),
                TransformInterpolation,
            ));
        }
    }
    Ok(())
}

/// The course of `hooke::tools::character_scenes` (stairs, a landing, a ramp down, a crate,
/// and a 60° ramp too steep to walk up) and the character at its start.
fn spawn_course(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
) -> Result {
    let course = CharacterCourse::default();
    let stone = materials.add(Color::srgb(0.6, 0.6, 0.65));
    for b in course.blocks() {
        commands.spawn((
            RigidBody::Static,
            Collider::cuboid(b.half.x, b.half.y, b.half.z)?,
            Mesh3d(meshes.add(Cuboid::from_size(2.0 * b.half))),
            MeshMaterial3d(stone.clone()),
            Transform::from_translation(COURSE + b.position).with_rotation(b.rotation),
        ));
    }
    commands.spawn((
        RigidBody::Dynamic,
        Collider::cuboid(0.5, 0.5, 0.5)?,
        ColliderDensity::try_new(course.crate_kg)?,
        Mesh3d(meshes.add(Cuboid::new(1.0, 1.0, 1.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.8, 0.55, 0.3))),
        Transform::from_translation(COURSE + course.crate_start()),
        TransformInterpolation,
    ));
    let (half, radius) = course.capsule;
    commands.spawn((
        Player,
        CharacterController::default(),
        Collider::capsule_y(half, radius)?,
        Mesh3d(meshes.add(Capsule3d::new(radius, 2.0 * half))),
        MeshMaterial3d(materials.add(Color::srgb(0.2, 0.45, 0.9))),
        Transform::from_translation(COURSE + course.character_starts()[0]),
        TransformInterpolation,
    ));
    Ok(())
}

/// WASD walks the character relative to the camera; space jumps while it is grounded.
fn steer_player(
    keys: Res<ButtonInput<KeyCode>>,
    look: Res<Look>,
    mut player: Single<(&mut CharacterInput, &CharacterState, &Transform), With<Player>>,
) {
    let (input, state, at) = &mut *player;
    let forward = -Vec3::new(look.yaw.sin(), 0.0, look.yaw.cos());
    let right = Vec3::new(-forward.z, 0.0, forward.x);
    let mut wish = Vec3::ZERO;
    for (key, dir) in [
        (KeyCode::KeyW, forward),
        (KeyCode::KeyS, -forward),
        (KeyCode::KeyD, right),
        (KeyCode::KeyA, -right),
    ] {
        if keys.pressed(key) {
            wish += dir;
        }
    }
    // `--walk`: along the course to the crate and on, stopping short of the floor's edge.
    if std::env::args().any(|a| a == "--walk") && at.translation.x < 12.0 {
        wish = Vec3::X;
    }
    input.velocity = wish.normalize_or_zero() * WALK;
    if keys.just_pressed(KeyCode::Space) && state.grounded {
        input.jump_speed = JUMP;
    }
}

fn orbit_camera(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut look: ResMut<Look>,
    mut camera: Single<&mut Transform, (With<Camera3d>, Without<Player>)>,
    player: Single<&Transform, With<Player>>,
) {
    let rate = 1.5 * time.delta_secs();
    if keys.pressed(KeyCode::ArrowLeft) {
        look.yaw -= rate;
    }
    if keys.pressed(KeyCode::ArrowRight) {
        look.yaw += rate;
    }
    if keys.pressed(KeyCode::ArrowUp) {
        look.pitch = (look.pitch + rate).min(1.4);
    }
    if keys.pressed(KeyCode::ArrowDown) {
        look.pitch = (look.pitch - rate).max(0.05);
    }
    let target = player.translation + Vec3::new(0.0, 0.5, 0.0);
    let eye = target
        + look.distance
            * Vec3::new(
                look.yaw.sin() * look.pitch.cos(),
                look.pitch.sin(),
                look.yaw.cos() * look.pitch.cos(),
            );
    **camera = Transform::from_translation(eye).looking_at(target, Vec3::Y);
}

fn throw(
    mut commands: Commands,
    mouse: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    window: Single<&Window>,
    camera: Single<(&Camera, &GlobalTransform)>,
    assets: Res<Assets3d>,
) -> Result {
    let (camera, eye) = *camera;
    let direction = if mouse.just_pressed(MouseButton::Left) {
        let Some(cursor) = window.cursor_position() else {
            return Ok(());
        };
        camera.viewport_to_world(eye, cursor)?.direction.as_vec3()
    } else if keys.just_pressed(KeyCode::KeyT) {
        (Vec3::new(0.0, 1.0, 0.0) - eye.translation()).normalize()
    } else {
        return Ok(());
    };
    commands.spawn((
        Thrown,
        RigidBody::Dynamic,
        Collider::ball(0.2)?,
        ColliderDensity::try_new(7800.0)?, // steel: 261 kg
        LinearVelocity::from(direction * 25.0),
        Mesh3d(assets.ball_mesh.clone()),
        MeshMaterial3d(assets.ball_material.clone()),
        Transform::from_translation(eye.translation() + direction),
        TransformInterpolation,
    ));
    Ok(())
}

fn rebuild(
    mut commands: Commands,
    keys: Res<ButtonInput<KeyCode>>,
    old: Query<Entity, Or<(With<Crate>, With<Thrown>)>>,
    assets: Res<Assets3d>,
) -> Result {
    if keys.just_pressed(KeyCode::KeyR) {
        for e in &old {
            commands.entity(e).despawn();
        }
        spawn_stack(&mut commands, &assets)?;
    }
    Ok(())
}

fn toggle_debug_view(keys: Res<ButtonInput<KeyCode>>, mut store: ResMut<GizmoConfigStore>) {
    if keys.just_pressed(KeyCode::KeyG) {
        let (config, _) = store.config_mut::<PhysicsGizmos>();
        config.enabled = !config.enabled;
    }
}
