//! Issue 15: bad input reproduced on the previous main, each now a typed error, a
//! quarantine or a correction, never a panic or a silent NaN.

use crate::common;
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemState;
use glam::{Quat, Vec3, Vec3A};
use hooke::collision::ContactSettings;
use hooke::collision::{QueryFilter, SpatialQuery};
use hooke::core::restore::{InvalidSetting, ResourceRestored};
use hooke::core::time::SubstepTime;
use hooke::parry3d::shape::SharedShape;
use hooke::prelude::*;
use hooke::rigid::AngularMomentum;
use hooke::sleep::SleepSettings;
use hooke::tools::scenes;

fn world() -> World {
    common::gravity_world(4)
}

fn messages<M: Message + Clone>(w: &World) -> Vec<M> {
    let m = w.resource::<Messages<M>>();
    m.get_cursor().read(m).cloned().collect()
}

#[test]
fn a_heightfield_whose_size_overflows_is_an_error() {
    // 2^62 × 4 wrapped to 0, matched the empty height list and overflowed parry's allocation.
    let r = Collider::heightfield(1 << 62, 4, vec![], Vec3::ONE);
    assert!(matches!(r, Err(Error::OutOfRange { .. })), "{r:?}");
}

#[test]
fn shapes_beyond_parrys_domain_are_errors() {
    // These made parry's EPA panic inside step_physics (index out of bounds, epa3.rs:100).
    for shape in [
        SharedShape::cylinder(1e20, 1.0),
        SharedShape::cuboid(1e30, 1e30, 1e30),
    ] {
        let r = Collider::new(shape);
        assert!(matches!(r, Err(Error::OutOfRange { .. })), "{r:?}");
    }
    assert!(Collider::cuboid(1e30, 1.0, 1.0).is_err());
    assert!(Collider::cuboid(1e5, 0.5, 1e5).is_ok());
}

#[test]
fn shapes_without_size_are_errors() {
    for shape in [
        SharedShape::ball(0.0),
        SharedShape::ball(-1.0),
        SharedShape::cuboid(-1.0, 1.0, 1.0),
        SharedShape::cuboid(0.0, 1.0, 1.0),
        SharedShape::capsule_y(1.0, 0.0),
    ] {
        let r = Collider::new(shape.clone());
        assert!(r.is_err(), "{:?} accepted", shape.shape_type());
    }
    // Flat hulls: three points, and four in one plane.
    assert!(Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y]).is_err());
    assert!(
        Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)]).is_err()
    );
    assert!(Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z]).is_ok());
}

#[test]
fn a_huge_but_finite_quaternion_normalises() {
    // |q|² overflowed and the zero quaternion came back.
    let r = Rotation::try_new(Quat::from_xyzw(0.0, 0.0, 0.0, 1e20)).unwrap();
    assert_eq!(r.0, Quat::IDENTITY);
    let r = Rotation::try_new(Quat::from_xyzw(3e38, 3e38, 0.0, 0.0)).unwrap();
    assert!((r.0.length() - 1.0).abs() < 1e-6, "{}", r.0);
    assert!(Rotation::try_new(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).is_err());
}

fn box_scene() -> (World, Entity) {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 2.0, 0.0)).unwrap();
    w.step_physics();
    (w, b)
}

#[test]
fn removed_plugin_resources_are_restored_and_reported() {
    type Remove = fn(&mut World);
    let cases: [(&str, Remove); 6] = [
        ("ContactSettings", |w| {
            let _ = w.remove_resource::<ContactSettings>();
        }),
        ("Contacts", |w| {
            w.remove_resource::<Contacts>();
        }),
        ("SleepSettings", |w| {
            let _ = w.remove_resource::<SleepSettings>();
        }),
        ("Integrator", |w| {
            w.remove_resource::<Integrator>();
        }),
        ("SubstepTime", |w| {
            w.remove_resource::<SubstepTime>();
        }),
        ("PhysicsTime", |w| {
            w.remove_resource::<PhysicsTime>();
        }),
    ];
    for (name, remove) in cases {
        let (mut w, b) = box_scene();
        remove(&mut w);
        // Each of these panicked in the next step.
        w.step_physics();
        let restored = messages::<ResourceRestored>(&w);
        assert!(
            restored.iter().any(|r| r.name.ends_with(name)),
            "{name}: {restored:?}"
        );
        for _ in 0..120 {
            w.step_physics();
        }
        let y = w.get::<Position>(b).unwrap().get().y;
        assert!((y - 0.5).abs() < 0.01, "{name}: the box ended at {y}");
    }
}

#[test]
fn a_sleeping_body_given_nan_through_get_mut_is_quarantined() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    for _ in 0..300 {
        w.step_physics();
    }
    assert!(w.get::<Sleeping>(b).is_some());
    w.get_mut::<AngularMomentum>(b).unwrap().0 = Vec3A::NAN;
    for _ in 0..3 {
        w.step_physics();
    }
    // It stayed NaN forever, unreported, and the diagnostics' energy read NaN.
    assert!(w.get::<Quarantined>(b).is_some());
    assert!(
        w.resource::<PhysicsDiagnostics>()
            .kinetic_energy
            .is_finite()
    );
}

#[test]
fn spatial_queries_with_nan_or_zero_poses_find_nothing() {
    let (mut w, _) = box_scene();
    let mut state = SystemState::<SpatialQuery>::new(&mut w);
    let q = state.get(&w).unwrap();
    let ball = Collider::ball(0.5).unwrap();
    let f = QueryFilter::default();
    let at = Vec3::new(0.0, 5.0, 0.0);
    // These answered with NaN distances, points and normals, or with entities.
    for rot in [Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), Quat::NAN] {
        assert!(
            q.cast_shape(&ball, at, rot, Vec3::NEG_Y, 100.0, &f)
                .is_none()
        );
        assert!(q.overlaps(&ball, Vec3::ZERO, rot, &f).is_empty());
    }
    assert!(
        q.cast_shape(&ball, Vec3::NAN, Quat::IDENTITY, Vec3::NEG_Y, 100.0, &f)
            .is_none()
    );
    assert!(q.project_point(Vec3::NAN, 10.0, &f).is_none());
    assert!(q.overlaps(&ball, Vec3::NAN, Quat::IDENTITY, &f).is_empty());
    // And good queries still answer.
    let hit = q
        .cast_shape(&ball, at, Quat::IDENTITY, Vec3::NEG_Y, 100.0, &f)
        .unwrap();
    assert!(hit.distance.is_finite() && hit.normal.is_finite());
}

#[test]
fn a_restitution_of_5_written_through_get_mut_is_caught() {
    let mut w = world();
    let g = scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_ball(&mut w, 0.2, Vec3::new(0.0, 1.2, 0.0)).unwrap();
    w.entity_mut(b).insert(Restitution(0.5));
    w.entity_mut(g).insert(Restitution(0.5));
    w.step_physics();
    w.get_mut::<Restitution>(b).unwrap().0 = 5.0;
    let mut top = 0.0f32;
    for _ in 0..300 {
        w.step_physics();
        top = top.max(w.get::<Position>(b).unwrap().get().y);
    }
    // It bounced the ball from 1.2 m to 24.9 m.
    assert!(top <= 1.2, "rose to {top}");
    let q = w.get::<Quarantined>(b).expect("quarantined");
    assert!(
        matches!(q.reason, QuarantineReason::InvalidInput(_)),
        "{:?}",
        q.reason
    );
}

#[test]
fn one_nan_friction_in_a_pile_quarantines_that_box_once() {
    let mut w = world();
    let boxes = scenes::box_pile(&mut w, 100).unwrap();
    for _ in 0..60 {
        w.step_physics();
    }
    let bad = boxes[50];
    w.entity_mut(bad).insert(Friction(0.5));
    w.step_physics();
    w.get_mut::<Friction>(bad).unwrap().0 = f32::NAN;
    let mut reports = Vec::new();
    for _ in 0..120 {
        w.step_physics();
        reports.extend(messages::<BodyQuarantined>(&w));
    }
    reports.dedup();
    let quarantined: Vec<Entity> = boxes
        .iter()
        .copied()
        .filter(|&b| w.get::<Quarantined>(b).is_some())
        .collect();
    // It quarantined 49 boxes, each reported twice.
    assert_eq!(quarantined, vec![bad]);
    assert_eq!(
        reports.iter().filter(|r| r.entity == bad).count(),
        1,
        "{reports:?}"
    );
}

#[test]
fn bad_contact_settings_are_corrected_and_reported() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    {
        let mut s = w.resource_mut::<ContactSettings>();
        s.max_push_velocity = f32::NAN;
        s.margin = -1.0;
        s.damping_ratio = -1.0;
    }
    w.step_physics();
    let fields: Vec<&str> = messages::<InvalidSetting>(&w)
        .iter()
        .map(|m| m.field)
        .collect();
    assert_eq!(fields, ["damping_ratio", "max_push_velocity", "margin"]);
    assert_eq!(*w.resource::<ContactSettings>(), ContactSettings::default());
    for _ in 0..120 {
        w.step_physics();
    }
    // The box fell through the ground (y = −19 m after 2 s).
    let y = w.get::<Position>(b).unwrap().get().y;
    assert!((y - 0.5).abs() < 0.01, "{y}");
}

#[test]
fn a_body_whose_mass_is_removed_is_quarantined_and_reported_once() {
    let mut w = world();
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 3.0, 0.0)).unwrap();
    let p = w
        .spawn(ParticleBundle::new(Vec3::new(5.0, 3.0, 0.0), Vec3::ZERO, 1.0).unwrap())
        .id();
    // Made static, and turned into a tracer: both go without a Mass on purpose.
    let s = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(3.0, 3.0, 0.0)).unwrap();
    let t = w
        .spawn(ParticleBundle::new(Vec3::new(8.0, 3.0, 0.0), Vec3::ZERO, 1.0).unwrap())
        .id();
    w.step_physics();
    w.entity_mut(s).insert(RigidBody::Static);
    w.entity_mut(t).insert(Tracer);
    for e in [b, p, s, t] {
        w.entity_mut(e).remove::<Mass>();
    }
    // Before: neither integrated nor checked, so this NaN stayed, unreported.
    w.get_mut::<LinearVelocity>(b).unwrap().0 = Vec3A::NAN;
    w.step_physics();
    let reported: Vec<Entity> = messages::<BodyQuarantined>(&w)
        .into_iter()
        .map(|m| m.entity)
        .collect();
    w.step_physics();
    w.step_physics();
    for e in [b, p] {
        let q = w.get::<Quarantined>(e).expect("quarantined");
        assert!(
            q.reason.to_string().contains("Mass was removed"),
            "{}",
            q.reason
        );
    }
    assert_eq!(reported.len(), 2, "{reported:?}");
    assert!(w.get::<Quarantined>(s).is_none() && w.get::<Quarantined>(t).is_none());
    assert!(
        w.resource::<PhysicsDiagnostics>()
            .kinetic_energy
            .is_finite()
    );
    // Despawning a body removes its Mass too: nothing to report.
    w.despawn(t);
    w.step_physics();
}

/// A density or part offset written through `get_mut` re-weighs the body at the next step (it
/// was ignored: the body kept its old mass), and a bad one quarantines it.
#[test]
fn density_and_offset_written_through_get_mut_are_applied_or_caught() {
    let mut w = world();
    w.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let ball = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            ColliderDensity::try_new(500.0).unwrap(),
        ))
        .id();
    let m0 = w.get::<Mass>(ball).unwrap().value();
    w.get_mut::<ColliderDensity>(ball).unwrap().0 = 1000.0;
    w.step_physics();
    let m1 = w.get::<Mass>(ball).unwrap().value();
    assert!((m1 / m0 - 2.0).abs() < 1e-4, "{m0} -> {m1}");

    let body = w
        .spawn((RigidBody::Dynamic, Position::from(Vec3::ZERO)))
        .id();
    let parts = [-1.0f32, 1.0].map(|dx| {
        w.spawn((
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            ColliderOffset::try_new(Vec3::new(dx, 0.0, 0.0), Quat::IDENTITY).unwrap(),
            ChildOf(body),
        ))
        .id()
    });
    w.step_physics();
    assert!(w.get::<CenterOfMass>(body).unwrap().0.length() < 1e-6);
    // One part moved 2 m further out: the centre of mass moves 1 m toward it.
    w.get_mut::<ColliderOffset>(parts[1]).unwrap().translation.x = 3.0;
    w.step_physics();
    let com = w.get::<CenterOfMass>(body).unwrap().0;
    assert!((com - Vec3::X).length() < 1e-5, "{com}");

    w.get_mut::<ColliderDensity>(ball).unwrap().0 = f32::NAN;
    w.step_physics();
    let q = w
        .get::<Quarantined>(ball)
        .expect("a NaN density quarantines");
    assert!(q.reason.to_string().contains("density"), "{}", q.reason);
}
