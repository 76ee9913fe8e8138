//! Regression: spawning the way Bevy users spawn. `(RigidBody::Dynamic, Collider)` made a
//! *static* collider (a body was dynamic only with a `Mass`, which `RigidBody` did not
//! require): the box floated at y = 5.000 for 3 s. A collider on a child entity became a
//! separate static box at the world origin. These tests spawn through required components
//! only, at the default settings.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::Error;
use hooke::collision::ColliderDensity;
use hooke::collision::ColliderOf;
use hooke::collision::ColliderOffset;
use hooke::core::quarantine::QuarantineReason;
use hooke::prelude::*;
use hooke::rigid::CenterOfMass;
use hooke::tools::scenes;

use crate::common;

fn y(w: &World, e: Entity) -> f32 {
    w.get::<Position>(e).unwrap().get().y
}

fn steps(w: &mut World, n: usize) {
    for _ in 0..n {
        w.step_physics();
    }
}

#[test]
fn a_dynamic_body_with_only_a_collider_falls_with_the_mass_of_its_shape() {
    let mut w = common::gravity_world(4);
    let b = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Position::from(Vec3::new(0.0, 5.0, 0.0)),
        ))
        .id();
    // A 1 m cube at the default 1000 kg/m³: 1000 kg, I = m (1² + 1²)/12 about each axis.
    let m = w.get::<Mass>(b).unwrap().value();
    assert!((m - 1000.0).abs() < 1e-2, "mass {m}");
    let i = w.get::<Inertia>(b).unwrap().principal();
    assert!(
        (i - Vec3::splat(1000.0 / 6.0)).abs().max_element() < 1e-2,
        "{i}"
    );
    steps(&mut w, 60);
    // Symplectic Euler at h = 1/240 s: y = y0 − g h² n(n+1)/2 after n = 240 substeps.
    let h = 1.0 / 240.0f32;
    let expected = 5.0 - 9.81 * h * h * 240.0 * 241.0 / 2.0;
    assert!(
        (y(&w, b) - expected).abs() < 1e-3,
        "y {} vs {expected}",
        y(&w, b)
    );
}

#[test]
fn density_sets_the_mass_and_a_given_mass_is_kept() {
    let mut w = common::gravity_world(4);
    let light = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            ColliderDensity::try_new(500.0).unwrap(),
        ))
        .id();
    let expected = 500.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.125;
    let m = w.get::<Mass>(light).unwrap().value();
    assert!((m - expected).abs() < 1e-2 * expected, "{m} vs {expected}");
    // A density inserted later re-weighs the body.
    w.entity_mut(light).insert(ColliderDensity(1000.0));
    let m = w.get::<Mass>(light).unwrap().value();
    assert!((m - 2.0 * expected).abs() < 2e-2 * expected, "{m}");

    let given = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Mass::new(3.0).unwrap(),
        ))
        .id();
    assert_eq!(w.get::<Mass>(given).unwrap().value(), 3.0);
    assert!(ColliderDensity::try_new(-1.0).is_err());
    assert!(ColliderDensity::try_new(f32::NAN).is_err());
}

#[test]
fn kinematic_and_static_mean_what_they_say() {
    let mut w = common::contact_world(4);
    let kin = w
        .spawn((
            RigidBody::Kinematic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Position::from(Vec3::new(0.0, 3.0, 0.0)),
            LinearVelocity::from(Vec3::X),
        ))
        .id();
    let shelf = w
        .spawn((
            RigidBody::Static,
            Collider::cuboid(2.0, 0.1, 2.0).unwrap(),
            Position::from(Vec3::new(10.0, 1.0, 0.0)),
        ))
        .id();
    let ball = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.2).unwrap(),
            Position::from(Vec3::new(10.0, 3.0, 0.0)),
        ))
        .id();
    steps(&mut w, 120);
    let x = w.get::<Position>(kin).unwrap().get();
    assert!(
        (x - Vec3::new(2.0, 3.0, 0.0)).length() < 1e-3,
        "kinematic at {x}"
    );
    assert_eq!(y(&w, shelf), 1.0);
    assert!(w.get::<Mass>(shelf).is_none() && w.get::<LinearVelocity>(shelf).is_none());
    assert!(
        (y(&w, ball) - 1.3).abs() < 0.01,
        "ball rests at {}",
        y(&w, ball)
    );

    // Made static by inserting the kind: it stops and stays.
    w.entity_mut(ball).insert(RigidBody::Static);
    let at = y(&w, ball);
    steps(&mut w, 30);
    assert_eq!(y(&w, ball), at);
    assert!(w.get::<Mass>(ball).is_none());
}

/// A body whose two child colliders sit 1 m either side of it along x.
fn dumbbell(w: &mut World, at: Vec3) -> (Entity, [Entity; 2]) {
    let body = w.spawn((RigidBody::Dynamic, Position::from(at))).id();
    let parts = [-1.0f32, 1.0].map(|dx| {
        w.spawn((
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            ColliderOffset::try_new(Vec3::new(dx, 0.0, 0.0), Quat::IDENTITY).unwrap(),
            ChildOf(body),
        ))
        .id()
    });
    (body, parts)
}

#[test]
fn child_colliders_are_parts_of_their_body_and_move_with_it() {
    let mut w = common::contact_world(4);
    scenes::ground(&mut w).unwrap();
    let (body, parts) = dumbbell(&mut w, Vec3::new(0.0, 2.0, 0.0));
    assert_eq!(w.get::<ColliderOf>(parts[0]).map(|c| c.body), Some(body));
    // Two 1000 kg cubes: 2000 kg; about y each adds m d² = 1000 kg·m² (parallel axis).
    assert!((w.get::<Mass>(body).unwrap().value() - 2000.0).abs() < 0.1);
    let i = w.get::<Inertia>(body).unwrap();
    let iyy = (i.tensor() * Vec3::Y).y;
    assert!(
        (iyy - 2.0 * (1000.0 / 6.0 + 1000.0)).abs() < 0.5,
        "I_yy {iyy}"
    );
    steps(&mut w, 180);
    // Both cubes stand on the ground: the body's centre at their half height.
    assert!((y(&w, body) - 0.5).abs() < 0.01, "body at {}", y(&w, body));
    let (xb, qb) = (
        w.get::<Position>(body).unwrap().get(),
        w.get::<Rotation>(body).unwrap().0,
    );
    assert!(qb.angle_between(Quat::IDENTITY) < 0.01, "tilt {qb}");
    for (p, dx) in parts.iter().zip([-1.0, 1.0]) {
        // Each part's own pose is the body's pose composed with its offset.
        let x = w.get::<Position>(*p).unwrap().get();
        let expected = xb + qb * Vec3::new(dx, 0.0, 0.0);
        assert!(
            (x - expected).length() < 1e-5,
            "part at {x}, expected {expected}"
        );
        assert!((x.x - dx).abs() < 0.01, "the part stayed {dx} m out: {x}");
        assert_eq!(w.get::<Rotation>(*p).unwrap().0, qb);
    }
    // The ground touches the body, not a loose part.
    let contacts = w.resource::<Contacts>();
    assert!(
        contacts
            .touching()
            .iter()
            .any(|&(a, b)| a == body || b == body)
    );
    assert!(
        !contacts
            .touching()
            .iter()
            .any(|(a, b)| parts.contains(a) || parts.contains(b))
    );
}

#[test]
fn a_lone_offset_child_moves_the_centre_of_mass_not_the_frame() {
    let mut w = common::gravity_world(4);
    let body = w
        .spawn((RigidBody::Dynamic, Position::from(Vec3::new(0.0, 5.0, 0.0))))
        .id();
    w.spawn((
        Collider::ball(0.5).unwrap(),
        ColliderOffset::try_new(Vec3::new(2.0, 0.0, 0.0), Quat::IDENTITY).unwrap(),
        ChildOf(body),
    ));
    let c = w.get::<CenterOfMass>(body).unwrap().0;
    assert!((c - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5, "c {c}");
    // The frame origin stayed at (0, 5, 0): the centre of mass is 2 m along x from it.
    let x = w.get::<Position>(body).unwrap().get();
    assert!((x - Vec3::new(2.0, 5.0, 0.0)).length() < 1e-5, "x {x}");
}

#[test]
fn despawning_a_child_takes_its_mass_and_shape_away() {
    let mut w = common::contact_world(4);
    scenes::ground(&mut w).unwrap();
    let (body, parts) = dumbbell(&mut w, Vec3::new(0.0, 0.5, 0.0));
    w.entity_mut(parts[1]).despawn();
    assert!((w.get::<Mass>(body).unwrap().value() - 1000.0).abs() < 0.1);
    let c = w.get::<CenterOfMass>(body).unwrap().0;
    assert!((c - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-5, "c {c}");
    steps(&mut w, 120);
    // One cube left, still resting on the ground (no tilt: the mass is under it).
    assert!((y(&w, body) - 0.5).abs() < 0.01, "{}", y(&w, body));
    // Re-parenting the other part away makes it a free static collider again.
    w.entity_mut(parts[0]).remove::<ChildOf>();
    assert!(w.get::<ColliderOf>(parts[0]).is_none());
    assert!(w.get::<Collider>(body).is_none());
}

#[test]
fn a_composite_child_is_quarantined_and_the_body_goes_on() {
    let mut w = common::gravity_world(4);
    let body = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position::from(Vec3::new(0.0, 5.0, 0.0)),
        ))
        .id();
    let inner = Collider::compound(vec![(
        Vec3::ZERO,
        Quat::IDENTITY,
        Collider::ball(0.2).unwrap(),
    )])
    .unwrap();
    let child = w.spawn((inner, ChildOf(body))).id();
    let q = w.get::<Quarantined>(child).expect("quarantined");
    assert!(matches!(
        q.reason,
        QuarantineReason::InvalidInput(Error::CompositePart(_))
    ));
    steps(&mut w, 10);
    assert!(y(&w, body) < 5.0);
    // And the compound constructor says so instead of panicking inside parry.
    let nested = Collider::compound(vec![(
        Vec3::ZERO,
        Quat::IDENTITY,
        Collider::compound(vec![(
            Vec3::ZERO,
            Quat::IDENTITY,
            Collider::ball(0.1).unwrap(),
        )])
        .unwrap(),
    )]);
    assert!(matches!(nested, Err(Error::CompositePart(_))));
}

#[test]
fn ropes_and_cloth_spawn_from_commands() {
    let mut w = common::gravity_world(4);
    let mut queue = bevy_ecs::world::CommandQueue::default();
    let mut commands = Commands::new(&mut queue, &w);
    let chain = ChainBuilder::rope(Vec3::new(0.0, 5.0, 0.0), Vec3::new(2.0, 5.0, 0.0), 9)
        .spawn_with(&mut commands)
        .unwrap();
    let cloth = ClothBuilder::new(Vec3::ZERO, 4, 4, 0.1)
        .spawn_with(&mut commands)
        .unwrap();
    assert!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 1)
            .spawn_with(&mut commands)
            .is_err()
    );
    queue.apply(&mut w);
    steps(&mut w, 30);
    let end = w
        .get::<Position>(*chain.nodes.last().unwrap())
        .unwrap()
        .get();
    assert!(end.y < 5.0, "the free end swings down: {end}");
    assert!(w.get::<Nodes>(cloth).is_some());
}
