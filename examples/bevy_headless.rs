//! hooke in a headless Bevy App: bodies spawned with `Commands`, stepped in
//! `FixedPostUpdate` on `Time<Fixed>`, their `Transform`s printed.
//!
//! ```sh
//! cargo run --release --features bevy --example bevy_headless
//! ```
//!
//! A ground, a three-box stack, a dumbbell made of two child colliders, a rope, and a ball
//! thrown at the stack at t = 0.5 s. A reader in `Update` counts contact starts.

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_app::{AppExit, ScheduleRunnerPlugin};
use bevy_ecs::prelude::*;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use hooke::prelude::*;

/// Frames to run (3 s at 60 frames per second; physics steps at Time<Fixed>'s 64 Hz).
const FRAMES: u32 = 180;

#[derive(Component)]
struct Label(&'static str);

#[derive(Resource, Default)]
struct Frame(u32);

#[derive(Resource, Default)]
struct ContactsSeen(usize);

fn main() {
    App::new()
        .add_plugins((
            TimePlugin,
            TransformPlugin,
            // As fast as the machine goes, each frame 1/60 s of game time: the output is
            // the same on every run.
            ScheduleRunnerPlugin::run_loop(Duration::ZERO),
            PhysicsPlugins,
        ))
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / 60.0,
        )))
        .init_resource::<Frame>()
        .init_resource::<ContactsSeen>()
        .add_systems(Startup, spawn_scene)
        .add_systems(Update, (count_contacts, throw_ball, report).chain())
        .run();
}

fn spawn_scene(mut commands: Commands) -> Result {
    commands.spawn((
        Label("ground"),
        RigidBody::Static,
        Collider::cuboid(20.0, 0.5, 20.0)?, // half extents (m)
        Transform::from_xyz(0.0, -0.5, 0.0),
    ));
    for i in 0..3 {
        commands.spawn((
            Label(["box 1", "box 2", "box 3"][i]),
            RigidBody::Dynamic, // mass from the collider at 1000 kg/m³: 125 kg
            Collider::cuboid(0.25, 0.25, 0.25)?,
            Transform::from_xyz(0.0, 0.25 + 0.5 * i as f32, 0.0),
            TransformInterpolation,
        ));
    }
    commands.spawn((
        Label("dumbbell"),
        RigidBody::Dynamic,
        Transform::from_xyz(0.0, 2.0, -3.0),
        children![
            (Collider::ball(0.3)?, Transform::from_xyz(-0.6, 0.0, 0.0)),
            (Collider::ball(0.3)?, Transform::from_xyz(0.6, 0.0, 0.0)),
            (Collider::cuboid(0.3, 0.05, 0.05)?, Transform::default()),
        ],
    ));
    let rope = ChainBuilder::rope(Vec3::new(3.0, 3.0, 3.0), Vec3::new(5.0, 3.0, 3.0), 11)
        .stiffness(2000.0)
        .spawn_with(&mut commands)?;
    if let Some(&end) = rope.nodes.last() {
        commands
            .entity(end)
            .insert((Label("rope end"), Transform::default()));
    }
    Ok(())
}

fn throw_ball(mut commands: Commands, frame: Res<Frame>) -> Result {
    if frame.0 == 30 {
        commands.spawn((
            Label("ball"),
            RigidBody::Dynamic,
            Collider::ball(0.15)?,
            ColliderDensity::try_new(7800.0)?, // steel
            Transform::from_xyz(-4.0, 0.6, 0.0),
            LinearVelocity::from(Vec3::new(12.0, 1.0, 0.0)),
        ));
    }
    Ok(())
}

fn count_contacts(mut started: MessageReader<ContactStarted>, mut seen: ResMut<ContactsSeen>) {
    seen.0 += started.read().count();
}

fn report(
    mut frame: ResMut<Frame>,
    seen: Res<ContactsSeen>,
    time: Res<PhysicsTime>,
    bodies: Query<(&Label, &Transform)>,
    mut exit: MessageWriter<AppExit>,
) {
    frame.0 += 1;
    if frame.0.is_multiple_of(45) || frame.0 == FRAMES {
        println!(
            "frame {:3}  physics t = {:.4} s ({} steps), contact starts seen: {}",
            frame.0,
            time.elapsed(),
            time.steps(),
            seen.0
        );
        let mut rows: Vec<_> = bodies.iter().collect();
        rows.sort_by_key(|(l, _)| l.0);
        for (label, t) in rows {
            let (axis, angle) = t.rotation.to_axis_angle();
            println!(
                "  {:9} translation ({:7.3}, {:7.3}, {:7.3}) m   rotation {:6.1}° about ({:5.2}, {:5.2}, {:5.2})",
                label.0,
                t.translation.x,
                t.translation.y,
                t.translation.z,
                angle.to_degrees(),
                axis.x,
                axis.y,
                axis.z
            );
        }
    }
    if frame.0 >= FRAMES {
        exit.write(AppExit::Success);
    }
}
