//! The cost of the Bevy layer (feature `bevy`): one `App::update` that runs exactly one
//! fixed step (`TimeUpdateStrategy::FixedTimesteps(1)`) against one `step_physics` on a bare
//! `World` holding the same scene. The App side pays everything a game pays per step: the
//! main schedule, `Time`, Transform reads and writes, message registration and Bevy's own
//! transform propagation. With `--features debug-plugin`, the heap again with the debug view
//! added (and Bevy's gizmo and asset plugins it draws through): switched off in its gizmo
//! config, and on.

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

/// Whether the App has the debug view, and whether it is switched on.
#[derive(Clone, Copy, PartialEq)]
enum Debug {
    Absent,
    Off,
    On,
}

fn app(spawn: &dyn Fn(&mut World), debug: Debug) -> App {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
    #[cfg(not(feature = "debug-plugin"))]
    let _ = debug;
    #[cfg(feature = "debug-plugin")]
    if debug != Debug::Absent {
        use bevy_gizmos::config::{GizmoConfig, GizmoConfigStore};
        app.add_plugins((
            bevy_app::TaskPoolPlugin::default(),
            bevy_asset::AssetPlugin::default(),
            bevy_gizmos::GizmoPlugin,
            hooke::bevy::PhysicsDebugPlugin,
        ));
        let mut store = app.world_mut().resource_mut::<GizmoConfigStore>();
        let (config, _): (&mut GizmoConfig, _) = store.config_mut::<hooke::bevy::PhysicsGizmos>();
        config.enabled = debug == Debug::On;
    }
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
type Scene<'a> = (&'a str, &'a dyn Fn(&mut World), usize, &'a str, Debug);

pub fn bevy_layer(cfg: &Config) {
    let falling = scenes::falling_boxes_spec(1000);
    let heap = |w: &mut World| {
        scenes::spawn_boxes(w, &falling).unwrap();
    };
    let tumbling = |w: &mut World| scenes::tumbling_boxes(w, 1000).unwrap();
    let mut scenes: Vec<Scene> = vec![
        (
            "heap1000",
            &heap,
            240,
            "1,000 boxes resting on the ground; goal <= 1.10",
            Debug::Absent,
        ),
        (
            "tumbling1000",
            &tumbling,
            0,
            "1,000 free tumbling boxes, no contacts: the layer against the cheapest step",
            Debug::Absent,
        ),
    ];
    if cfg!(feature = "debug-plugin") {
        scenes.push((
            "heap1000_debug_view_off",
            &heap,
            240,
            "the heap with PhysicsDebugPlugin added, its gizmo config disabled; goal <= 1.10",
            Debug::Off,
        ));
        scenes.push((
            "heap1000_debug_view_on",
            &heap,
            240,
            "the heap drawn: its colliders and contacts into the gizmo buffers each update",
            Debug::On,
        ));
    }
    for (name, spawn, settle, note, debug) in scenes {
        let mut a = app(spawn, debug);
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
