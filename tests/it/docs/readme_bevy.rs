//! The README's Bevy quick start, compiled and run as pasted (the block between the markers
//! is checked against the README), plus a frame-by-frame run of the same scene.
#![cfg(feature = "bevy")]
#![allow(dead_code)]

mod quick_start {
    // README-BEGIN
    use std::time::Duration;

    use bevy_app::ScheduleRunnerPlugin;
    use bevy_app::prelude::*;
    use bevy_ecs::prelude::*;
    use bevy_time::prelude::*;
    use bevy_transform::prelude::*;
    use hooke::prelude::*;

    fn main() -> AppExit {
        App::new()
            // With the `bevy` crate: `DefaultPlugins` (a window) or `MinimalPlugins` instead.
            .add_plugins((
                ScheduleRunnerPlugin::run_loop(Duration::from_secs_f64(1.0 / 60.0)),
                bevy_time::TimePlugin,
                TransformPlugin,
            ))
            .add_plugins(PhysicsPlugins) // every effect, one clock, Transform sync, interpolation
            .add_systems(Startup, setup)
            .add_systems(Update, (on_landing, stop_after_three_seconds))
            .run()
    }

    fn setup(mut commands: Commands) -> Result {
        commands.spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 20.0)?, // HALF extents (m): a 40 m × 1 m × 40 m slab
            Transform::from_xyz(0.0, -0.5, 0.0),
        ));
        commands.spawn((
            RigidBody::Dynamic, // mass and inertia from the collider at 1000 kg/m³
            Collider::cuboid(0.5, 0.5, 0.5)?,
            Transform::from_xyz(0.0, 5.0, 0.0),
            TransformInterpolation, // smooth between fixed steps
        ));
        // A compound body: colliders on child entities are parts of their parent body.
        commands.spawn((
            RigidBody::Dynamic,
            Transform::from_xyz(3.0, 2.0, 0.0),
            children![
                (Collider::ball(0.3)?, Transform::from_xyz(-0.6, 0.0, 0.0)),
                (
                    Collider::ball(0.3)?,
                    ColliderDensity::try_new(7800.0)?,
                    Transform::from_xyz(0.6, 0.0, 0.0)
                ),
            ],
        ));
        ChainBuilder::rope(Vec3::new(-3.0, 4.0, 0.0), Vec3::new(-1.0, 4.0, 0.0), 11)
            .spawn_with(&mut commands)?;
        Ok(())
    }

    fn on_landing(mut started: MessageReader<ContactStarted>) {
        for contact in started.read() {
            println!("{:?} touches {:?}", contact.a, contact.b);
        }
    }

    fn stop_after_three_seconds(time: Res<Time>, mut exit: MessageWriter<AppExit>) {
        if time.elapsed_secs() > 3.0 {
            exit.write(AppExit::Success);
        }
    }
    // README-END

    #[test]
    fn the_readme_block_is_this_code() {
        let me = include_str!("readme_bevy.rs");
        let begin = me.find("// README-BEGIN\n").unwrap() + "// README-BEGIN\n".len();
        let end = me.find("    // README-END").unwrap();
        let readme = include_str!("../../../README.md");
        // The test's copy is indented one level; compare word for word, whitespace aside.
        let squash = |s: &str| s.split_whitespace().collect::<String>();
        assert!(
            squash(readme).contains(&squash(&me[begin..end])),
            "README and test differ"
        );
    }

    #[test]
    fn the_readme_app_runs_three_seconds_and_exits() {
        let start = std::time::Instant::now();
        assert_eq!(main(), AppExit::Success);
        let took = start.elapsed().as_secs_f64();
        assert!(took > 2.9, "the runner loops until the app exits: {took} s");
    }

    #[test]
    fn the_readme_scene_settles() {
        use bevy_app::prelude::*;
        use bevy_ecs::prelude::*;
        use hooke::prelude::*;
        let mut app = App::new();
        app.add_plugins((
            bevy_time::TimePlugin,
            bevy_transform::TransformPlugin,
            PhysicsPlugins,
        ));
        app.insert_resource(bevy_time::TimeUpdateStrategy::ManualDuration(
            std::time::Duration::from_secs_f64(1.0 / 60.0),
        ));
        app.add_systems(Startup, setup);
        app.finish();
        app.cleanup();
        for _ in 0..240 {
            app.update();
        }
        let mut q = app
            .world_mut()
            .query_filtered::<&bevy_transform::components::Transform, With<TransformInterpolation>>(
            );
        let t = q.single(app.world()).unwrap();
        assert!(
            (t.translation.y - 0.5).abs() < 0.02,
            "the crate rests: {}",
            t.translation
        );
    }
}
