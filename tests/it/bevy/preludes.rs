//! hooke's prelude glob-imports beside Bevy's without a clash (an "ambiguous glob import"
//! warning is a future error in Rust). The `bevy` umbrella crate cannot be built on this
//! toolchain, so this imports the preludes of the sub-crates it re-exports: `bevy_app`,
//! `bevy_ecs`, `bevy_time`, `bevy_transform` and `bevy_diagnostic`.
#![cfg(feature = "bevy")]
#![deny(warnings)]

use bevy_app::prelude::*;
use bevy_diagnostic::*;
use bevy_ecs::prelude::*;
use bevy_time::prelude::*;
use bevy_transform::prelude::*;
use hooke::prelude::*;

#[test]
fn both_preludes_name_what_a_game_uses() {
    let mut app = App::new();
    app.add_plugins((
        bevy_time::TimePlugin,
        TransformPlugin,
        PhysicsPlugins,
        DiagnosticsPlugin,
    ));
    app.add_plugins(PhysicsDiagnosticsPlugin);
    let _ = Time::<Fixed>::from_hz(60.0);
    let body = app
        .world_mut()
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Transform::from_xyz(0.0, 1.0, 0.0),
            TransformInterpolation,
        ))
        .id();
    let world: &World = app.world();
    let _: Entity = body;
    let _: Option<&Position> = world.get::<Position>(body);
    let _: fn(Vec3) -> Vec3 = |v| v;
    let _: Quat = Quat::IDENTITY;
    let _ = Integrator::SymplecticEuler;
    let _ = Error::ZeroSubsteps;
}
