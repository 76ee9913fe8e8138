//! Named collision layers (a game's enum through `PhysicsLayer`) decide who touches whom
//! and what queries see; `MaxLinearSpeed` and `MaxAngularSpeed` cap a body's speeds.

use crate::common;
use bevy_ecs::prelude::*;
use hooke::collision::QueryFilter;
use hooke::prelude::*;

#[derive(Clone, Copy)]
enum Layer {
    Ground,
    Player,
    Ghost,
}

impl PhysicsLayer for Layer {
    fn index(self) -> u32 {
        self as u32
    }
}

fn ground(world: &mut World) {
    world.spawn((
        RigidBody::Static,
        Collider::cuboid(10.0, 0.5, 10.0).unwrap(),
        Position::from(Vec3::new(0.0, -0.5, 0.0)),
        CollisionLayers::from_layers([Layer::Ground], [Layer::Player]).unwrap(),
    ));
}

#[test]
fn a_player_falls_through_a_ghost_platform_and_lands_on_the_ground() {
    let mut world = common::default_world();
    ground(&mut world);
    let ghost = world
        .spawn((
            RigidBody::Static,
            Collider::cuboid(2.0, 0.1, 2.0).unwrap(),
            Position::from(Vec3::new(0.0, 2.0, 0.0)),
            CollisionLayers::from_layers([Layer::Ghost], [Layer::Ground]).unwrap(),
        ))
        .id();
    let player = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position::from(Vec3::new(0.0, 4.0, 0.0)),
            CollisionLayers::from_layers([Layer::Player], [Layer::Ground, Layer::Ghost]).unwrap(),
        ))
        .id();
    for _ in 0..180 {
        world.step_physics();
    }
    // The player filters the ghost, but the ghost does not filter the player: no contact.
    let y = world.get::<Position>(player).unwrap().get().y;
    assert!((y - 0.5).abs() < 0.02, "on the ground, not the ghost: {y}");

    // Queries pick layers by name too.
    let mut state: bevy_ecs::system::SystemState<SpatialQuery> =
        bevy_ecs::system::SystemState::new(&mut world);
    let query = state.get(&world).unwrap();
    let down = -Vec3::Y;
    let origin = Vec3::new(1.5, 5.0, 0.0);
    let all = query
        .cast_ray(origin, down, 10.0, &QueryFilter::default())
        .unwrap();
    assert_eq!(all.entity, ghost);
    let mask = LayerMask::from_layers([Layer::Ground]).unwrap();
    let grounds = query
        .cast_ray(origin, down, 10.0, &QueryFilter::default().with_mask(mask))
        .unwrap();
    assert!((grounds.point.y - 0.0).abs() < 1e-4, "{grounds:?}");
}

#[derive(Clone, Copy)]
struct Far;

impl PhysicsLayer for Far {
    fn index(self) -> u32 {
        40
    }
}

#[test]
fn a_layer_past_bit_31_is_a_typed_error() {
    assert!(matches!(
        CollisionLayers::from_layers([Far], [Far]),
        Err(Error::OutOfRange {
            what: "collision layer index",
            ..
        })
    ));
    assert_eq!(
        CollisionLayers::new(LayerMask(0b01) | LayerMask(0b10), LayerMask::ALL),
        CollisionLayers {
            memberships: 0b11,
            filters: u32::MAX
        }
    );
}

#[test]
fn speed_caps_hold_a_fall_and_a_spin() {
    let mut world = common::default_world();
    let faller = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position::from(Vec3::new(0.0, 100.0, 0.0)),
            MaxLinearSpeed(3.0),
        ))
        .id();
    let spinner = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.2, 0.3).unwrap(),
            Position::from(Vec3::new(5.0, 100.0, 0.0)),
            AngularVelocity::from(Vec3::new(1.0, 8.0, 0.5)),
            MaxAngularSpeed(2.0),
        ))
        .id();
    for _ in 0..120 {
        world.step_physics();
    }
    let v = world.get::<LinearVelocity>(faller).unwrap().get();
    assert!(
        (v.length() - 3.0).abs() < 1e-3,
        "free fall capped at 3 m/s: {v}"
    );
    let w = Vec3::from(world.get::<AngularVelocity>(spinner).unwrap().0);
    assert!(w.length() <= 2.0 + 1e-3, "{w}");
    let (q, inertia) = (
        world.get::<Rotation>(spinner).unwrap().0,
        *world.get::<Inertia>(spinner).unwrap(),
    );
    let l = world
        .get::<hooke::rigid::AngularMomentum>(spinner)
        .unwrap()
        .0;
    let from_l = Vec3::from(inertia.angular_velocity(q, l));
    assert!(
        (from_l - w).length() < 1e-3,
        "ω and L agree: {w} vs {from_l}"
    );
    // Bad caps are typed errors.
    let bad = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            MaxLinearSpeed(-1.0),
        ))
        .id();
    world.step_physics();
    assert!(world.get::<Quarantined>(bad).is_some());
}
