//! A character controller driven from an `Update` system in a Bevy `App` at its defaults:
//! the walk written each frame is the walk done, at frame rates above and below physics.
#![cfg(feature = "bevy")]

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use hooke::prelude::*;

#[derive(Component)]
struct Player;

fn walk_east(mut players: Query<&mut CharacterInput, With<Player>>) {
    for mut input in &mut players {
        input.velocity = Vec3::new(2.0, 0.0, 0.0);
    }
}

#[test]
fn the_walk_written_each_frame_is_the_walk_done() {
    for frame_hz in [30.0, 60.0, 144.0] {
        let mut app = App::new();
        app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / frame_hz,
        )));
        app.add_systems(Update, walk_east);
        app.finish();
        app.cleanup();
        app.world_mut().spawn((
            RigidBody::Static,
            Collider::cuboid(50.0, 0.5, 50.0).unwrap(),
            Transform::from_xyz(0.0, -0.5, 0.0),
        ));
        let player = app
            .world_mut()
            .spawn((
                Player,
                CharacterController::default(),
                Collider::capsule_y(0.5, 0.3).unwrap(),
                Transform::from_xyz(0.0, 0.81, 0.0),
            ))
            .id();
        app.update();
        let start = app.world().get::<Position>(player).unwrap().get();
        let t0 = app.world().resource::<PhysicsTime>().elapsed();
        for _ in 0..(2.0 * frame_hz) as usize {
            app.update();
        }
        let end = app.world().get::<Position>(player).unwrap().get();
        let t = (app.world().resource::<PhysicsTime>().elapsed() - t0) as f32;
        assert!(
            ((end.x - start.x) - 2.0 * t).abs() < 1e-3,
            "{frame_hz} Hz frames: walked {} m in {t} s",
            end.x - start.x
        );
        assert!((end.y - 0.81).abs() < 1e-3, "{frame_hz} Hz: {end}");
        assert!(app.world().get::<CharacterState>(player).unwrap().grounded);
        let shown = app.world().get::<Transform>(player).unwrap().translation;
        assert!(
            (shown - end).length() < 0.1,
            "{frame_hz} Hz: Transform follows: {shown} vs {end}"
        );
    }
}
