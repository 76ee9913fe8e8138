//! The cost of the Bevy layer (feature `bevy`): one `App::update` that runs exactly one
//! fixed step (`TimeUpdateStrategy::FixedTimesteps(1)`) against one `step_physics` on a bare
//! `World` holding the same scene. The App side pays everything a game pays per step: the
//! main schedule, `Time`, Transform reads and writes, message registration and Bevy's own
//! transform propagation.

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::timing::{Config, compare, line};

fn settings(world: &mut World) {
    world.insert_resource(PhysicsTime::new(1.0 / 60.0, 4).unwrap());
    world.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0)).unwrap());
    world.resource_mut::<DiagnosticsSettings>().energy = false;
    world.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
}

fn app(spawn: &dyn Fn(&mut World)) -> App {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
    app.insert_resource(Time::<Fixed>::from_hz(60.0));
    app.insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    app.finish();
    app.cleanup();
    settings(app.world_mut());
    spawn(app.world_mut());
    app
}

fn bare(spawn: &dyn Fn(&mut World)) -> World {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    settings(&mut world);
    spawn(&mut world);
    world
}

/// A scene: its name, how it spawns, the steps to settle first, and the line's note.
type Scene<'a> = (&'a str, &'a dyn Fn(&mut World), usize, &'a str);

pub fn bevy_layer(cfg: &Config) {
    let falling = scenes::falling_boxes_spec(1000);
    let heap = |w: &mut World| {
        scenes::spawn_boxes(w, &falling).unwrap();
    };
    let tumbling = |w: &mut World| scenes::tumbling_boxes(w, 1000).unwrap();
    let scenes: [Scene; 2] = [
        (
            "heap1000",
            &heap,
            240,
            "1,000 boxes resting on the ground; goal <= 1.10",
        ),
        (
            "tumbling1000",
            &tumbling,
            0,
            "1,000 free tumbling boxes, no contacts: the layer against the cheapest step",
        ),
    ];
    for (name, spawn, settle, note) in scenes {
        let mut a = app(spawn);
        let mut w = bare(spawn);
        // Bevy's first update starts its clock and runs no fixed step.
        a.update();
        for _ in 0..settle {
            a.update();
            w.step_physics();
        }
        let steps = a.world().resource::<PhysicsTime>().steps();
        assert_eq!(
            steps,
            w.resource::<PhysicsTime>().steps(),
            "one step per update"
        );
        let (ours, reference) = compare(cfg, || a.update(), || w.step_physics());
        line(
            &format!("bevy_app_step_vs_bare_world_{name}"),
            ours,
            reference,
            note,
        );
    }
}
