//! A `Transform` written by game code is a teleport, with or without interpolation or
//! extrapolation, whatever the frame rate against the physics rate: no write is lost.
#![cfg(feature = "bevy")]

use std::time::Duration;

use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy};
use bevy_transform::TransformPlugin;
use bevy_transform::components::Transform;
use hooke::bevy::{TransformExtrapolation, TransformInterpolation};
use hooke::core::time::PhysicsTime;
use hooke::prelude::*;

/// The x the game writes into the body's `Transform` in `Update`, if any this frame.
#[derive(Resource, Default)]
struct Teleport(Option<f32>);

#[derive(Clone, Copy, Debug)]
enum Smoothing {
    None,
    Interpolate,
    Extrapolate,
}

/// An App at `PhysicsPlugins` whose frames are `frame_hz` long and whose physics steps at
/// `physics_hz`, with a ball rolling along z (so x changes only by teleports).
fn app(frame_hz: f64, physics_hz: f64, smoothing: Smoothing) -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
        1.0 / frame_hz,
    )));
    app.insert_resource(Time::<Fixed>::from_hz(physics_hz));
    app.init_resource::<Teleport>();
    app.finish();
    app.cleanup();
    let mut body = app.world_mut().spawn((
        RigidBody::Dynamic,
        Collider::ball(0.5).unwrap(),
        Transform::from_xyz(0.0, 50.0, 0.0),
        LinearVelocity::from(glam::Vec3::new(0.0, 0.0, 2.0)),
    ));
    match smoothing {
        Smoothing::None => {}
        Smoothing::Interpolate => {
            body.insert(TransformInterpolation);
        }
        Smoothing::Extrapolate => {
            body.insert(TransformExtrapolation);
        }
    }
    let body = body.id();
    app.add_systems(
        Update,
        move |mut teleport: ResMut<Teleport>, mut transforms: Query<&mut Transform>| {
            if let Some(x) = teleport.0.take() {
                transforms.get_mut(body).unwrap().translation.x = x;
            }
        },
    );
    (app, body)
}

#[test]
fn every_transform_write_lands_at_every_frame_rate_with_or_without_smoothing() {
    let rates = [
        (144.0, 60.0),
        (144.0, 30.0),
        (240.0, 64.0),
        (60.0, 60.0),
        (30.0, 60.0),
        (20.0, 64.0),
    ];
    for (frame_hz, physics_hz) in rates {
        for smoothing in [
            Smoothing::None,
            Smoothing::Interpolate,
            Smoothing::Extrapolate,
        ] {
            let (mut app, body) = app(frame_hz, physics_hz, smoothing);
            let case = format!("{frame_hz} Hz frames, {physics_hz} Hz physics, {smoothing:?}");
            for _ in 0..3 {
                app.update();
            }
            let mut landed = 0;
            for k in 1..=12 {
                let x = 10.0 * k as f32;
                app.world_mut().resource_mut::<Teleport>().0 = Some(x);
                // Written in `Update`, after this frame's steps: the next step is a later
                // frame's, and until it the frames show what the game wrote.
                app.update();
                let steps = app.world().resource::<PhysicsTime>().steps();
                let mut frames = 0;
                loop {
                    let shown = app.world().get::<Transform>(body).unwrap().translation.x;
                    assert_eq!(shown, x, "{case}: write {k} shown as {shown} before a step");
                    app.update();
                    if app.world().resource::<PhysicsTime>().steps() > steps {
                        break;
                    }
                    frames += 1;
                    assert!(frames < 10, "{case}: no step");
                }
                // The next step starts from it, and so does what the frames show after it
                // (interpolated between two equal x, to rounding).
                let at = app.world().get::<Position>(body).unwrap().get().x;
                let shown = app.world().get::<Transform>(body).unwrap().translation.x;
                assert_eq!(at, x, "{case}: write {k} lost");
                assert!(
                    (shown - x).abs() < 1e-5 * x,
                    "{case}: write {k} shown as {shown}"
                );
                landed += 1;
            }
            assert_eq!(landed, 12, "{case}");
        }
    }
}

/// Where the game moves the platform each frame (x, m), written in `Update`.
#[derive(Resource, Default)]
struct PlatformX(f32);

#[test]
fn a_kinematic_platform_moved_by_its_transform_carries_the_crate_on_it() {
    // The platform slides along x at 0.5 m/s by its Transform; the crate resting on it rides
    // along. Written in `Update` at 120 or 60 Hz frames over 60 Hz physics (each step moves
    // it as far), or in `FixedUpdate` under 144 and 30 Hz frames. (Written in `Update` at
    // frame rates that do not divide the physics rate, steps move it by two frames' worth
    // or three, and friction, which drags the crate down to the slower steps faster than it
    // lifts it to the quicker ones, lets it slip: move a platform in `FixedUpdate` then.)
    for (frame_hz, fixed) in [(120.0, false), (60.0, false), (144.0, true), (30.0, true)] {
        let mut app = App::new();
        app.add_plugins((TimePlugin, TransformPlugin, PhysicsPlugins));
        app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / frame_hz,
        )));
        app.insert_resource(Time::<Fixed>::from_hz(60.0));
        app.init_resource::<PlatformX>();
        app.finish();
        app.cleanup();
        let platform = app
            .world_mut()
            .spawn((
                RigidBody::Kinematic,
                Collider::cuboid(2.0, 0.1, 2.0).unwrap(),
                Transform::from_xyz(0.0, 1.0, 0.0),
            ))
            .id();
        let crate_ = app
            .world_mut()
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
                Transform::from_xyz(0.0, 1.3, 0.0),
            ))
            .id();
        let slide =
            move |time: Res<Time>, mut x: ResMut<PlatformX>, mut t: Query<&mut Transform>| {
                if time.elapsed_secs() > 1.0 {
                    x.0 += 0.5 * time.delta_secs();
                    t.get_mut(platform).unwrap().translation.x = x.0;
                }
            };
        if fixed {
            app.add_systems(FixedUpdate, slide);
        } else {
            app.add_systems(Update, slide);
        }
        let frames = (4.0 * frame_hz) as usize;
        for _ in 0..frames {
            app.update();
        }
        let world = app.world();
        let moved = world.resource::<PlatformX>().0;
        let platform_x = world.get::<Position>(platform).unwrap().get().x;
        let crate_x = world.get::<Position>(crate_).unwrap().get();
        assert!(moved > 1.4, "{frame_hz} Hz: the platform moved {moved} m");
        assert!(
            (platform_x - moved).abs() < 0.01,
            "{frame_hz} Hz: platform at {platform_x}, written {moved}"
        );
        // Carried: it slips only while friction brings it up to speed, v² / (2 μ g) =
        // 0.25 / (2 × 0.5 × 9.81) = 2.5 cm, then rides at the platform's speed, resting on it.
        let slip = platform_x - crate_x.x;
        assert!(
            (0.0..0.032).contains(&slip) && (crate_x.y - 1.3).abs() < 0.01,
            "{frame_hz} Hz: crate at {crate_x}, platform at x = {platform_x}"
        );
        let speed = world.get::<LinearVelocity>(crate_).unwrap().get().x;
        assert!(
            (speed - 0.5).abs() < 0.02,
            "{frame_hz} Hz: the crate at {speed} m/s"
        );
        // Between writes it stands still: no velocity left over after a step.
        let v = world.get::<LinearVelocity>(platform).unwrap().get();
        assert_eq!(v, glam::Vec3::ZERO);
    }
}
