//! A 2.5D game through a Bevy `App` at its defaults: crates spawned with `Transform` and
//! `LockedAxes::XY_PLANE`, kicked every frame by an `Update` system with impulses that lean
//! out of the plane, stay in their plane and turn only about z, at frame rates above and
//! below physics; the component is registered for inspectors.
#![cfg(feature = "bevy")]

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_ecs::reflect::{AppTypeRegistry, ReflectComponent};
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use hooke::prelude::*;

#[derive(Component)]
struct Crate;

/// Every frame, each crate gets a kick up and out of the screen, off centre.
fn kick(mut commands: Commands, crates: Query<Entity, With<Crate>>, mut frame: Local<u32>) {
    *frame += 1;
    if frame.is_multiple_of(20) {
        for e in &crates {
            commands
                .entity(e)
                .apply_impulse(Vec3::new(30.0, 400.0, 300.0));
        }
    }
}

#[test]
fn kicked_crates_stay_in_their_plane() {
    for frame_hz in [30.0, 144.0] {
        let mut app = App::new();
        app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / frame_hz,
        )));
        app.add_systems(Update, kick);
        app.finish();
        app.cleanup();
        app.world_mut().spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 20.0).unwrap(),
            Transform::from_xyz(0.0, -0.5, 0.0),
        ));
        let crates: Vec<Entity> = (0..6)
            .map(|i| {
                app.world_mut()
                    .spawn((
                        Crate,
                        RigidBody::Dynamic,
                        Collider::cuboid(0.4, 0.3, 0.4).unwrap(),
                        Transform::from_xyz(-2.0 + 0.7 * i as f32, 0.3 + 0.7 * i as f32, 0.0)
                            .with_rotation(Quat::from_rotation_z(0.3 * i as f32)),
                        LockedAxes::XY_PLANE,
                    ))
                    .id()
            })
            .collect();
        for _ in 0..(3.0 * frame_hz) as usize {
            app.update();
        }
        let world = app.world();
        let mut moved = 0.0f32;
        for (i, &e) in crates.iter().enumerate() {
            let t = world.get::<Transform>(e).unwrap();
            assert!(
                !world.entity(e).contains::<Quarantined>(),
                "{frame_hz} Hz: crate {i}"
            );
            assert_eq!(
                t.translation.z, 0.0,
                "{frame_hz} Hz: crate {i} left the plane"
            );
            let (axis, angle) = t.rotation.to_axis_angle();
            assert!(
                angle.abs() < 1e-6
                    || axis.abs_diff_eq(Vec3::Z, 1e-5)
                    || axis.abs_diff_eq(Vec3::NEG_Z, 1e-5),
                "{frame_hz} Hz: crate {i} turned about {axis}"
            );
            moved = moved.max((t.translation.x - (-2.0 + 0.7 * i as f32)).abs());
        }
        assert!(
            moved > 0.1,
            "{frame_hz} Hz: the kicks moved the crates in the plane"
        );
        let registry = world.resource::<AppTypeRegistry>().read();
        let registration = registry
            .get_with_short_type_path("LockedAxes")
            .expect("LockedAxes is registered");
        assert!(registration.data::<ReflectComponent>().is_some());
    }
}
