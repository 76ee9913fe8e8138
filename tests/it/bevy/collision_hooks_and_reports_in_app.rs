//! Collision hooks, contact reports and dominance through a Bevy `App` at its defaults: the
//! one-way platform and the belt of `hooke::tools::hook_scenes` behave as in a bare world,
//! and an `Update` system reads each step's `ContactReport`s with a `MessageReader`.
#![cfg(feature = "bevy")]

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use hooke::prelude::*;
use hooke::tools::hook_scenes::{HooksCourse, PlatformHooks};

/// The largest force on the crate any report of the run carried (N), read in `Update`.
#[derive(Resource, Default)]
struct Loads {
    reports: usize,
    strongest: f32,
}

fn read_reports(mut reports: MessageReader<ContactReport>, mut loads: ResMut<Loads>) {
    for r in reports.read() {
        loads.reports += 1;
        loads.strongest = loads.strongest.max(r.normal_impulse / r.dt);
    }
}

#[test]
fn hooks_and_reports_work_in_an_app() {
    for frame_hz in [30.0, 144.0] {
        let mut app = App::new();
        app.add_plugins((
            TimePlugin,
            TransformPlugin,
            PhysicsPlugins,
            CollisionHooksPlugin::<PlatformHooks>::default(),
        ));
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / frame_hz,
        )));
        app.init_resource::<Loads>();
        app.add_systems(Update, read_reports);
        app.finish();
        app.cleanup();
        let course = HooksCourse::default();
        let parts = course.spawn(app.world_mut()).unwrap();
        app.world_mut()
            .entity_mut(parts.crate_)
            .insert(ContactReporting::default());
        for _ in 0..(2.5 * frame_hz) as usize {
            app.update();
        }
        let world = app.world();
        let ball = world.get::<Position>(parts.ball).unwrap().get();
        let top = course.platform_top + course.ball_radius;
        assert!(
            (ball.y - top).abs() < 0.02,
            "{frame_hz} Hz: the ball rests on the platform at {}",
            ball.y
        );
        let v = world.get::<LinearVelocity>(parts.crate_).unwrap().get();
        assert!(
            (v.x - course.belt_speed).abs() < 0.02,
            "{frame_hz} Hz: the belt carries the crate at {v}"
        );
        let loads = world.resource::<Loads>();
        let weight = course.crate_kg * 9.81;
        // One report per step while it rides the belt; its load is its weight.
        let steps = world.resource::<PhysicsTime>().elapsed() * 60.0;
        assert!(
            loads.reports as f64 > 0.9 * steps,
            "{} reports in {steps} steps",
            loads.reports
        );
        assert!(
            loads.strongest > 0.99 * weight,
            "{} N vs {weight} N",
            loads.strongest
        );
    }
}
