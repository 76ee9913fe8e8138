//! Every bad input hooke handles gets a typed error or a quarantine, never a panic.

use crate::common;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use common::*;
use hooke::prelude::*;
use hooke::tools::scenes;

fn world() -> World {
    scenes::world_with(
        0.01,
        1,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap()
}

#[test]
fn mass_must_be_positive_and_finite() {
    for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-45] {
        assert!(
            matches!(Mass::new(bad), Err(Error::InvalidMass(_))),
            "{bad}"
        );
    }
    assert_eq!(Mass::new(2.0).unwrap().inverse(), 0.5);
    assert!(Mass::PINNED.is_pinned() && Mass::PINNED.value().is_infinite());
}

#[test]
fn non_finite_vectors_are_rejected_everywhere() {
    let nan = Vec3::new(0.0, f32::NAN, 0.0);
    let inf = Vec3::new(f32::INFINITY, 0.0, 0.0);
    for bad in [nan, inf] {
        assert!(matches!(
            ParticleBundle::new(bad, Vec3::ZERO, 1.0),
            Err(Error::NonFinite {
                what: "position",
                ..
            })
        ));
        assert!(matches!(
            ParticleBundle::new(Vec3::ZERO, bad, 1.0),
            Err(Error::NonFinite {
                what: "velocity",
                ..
            })
        ));
        assert!(ParticleBundle::pinned(bad).is_err());
        assert!(Position::try_new(bad).is_err());
        assert!(ExternalForce::try_new(bad).is_err());
        assert!(ExternalImpulse::try_new(bad).is_err());
        assert!(Gravity::new(bad).is_err());
        assert!(VelocityField::uniform(bad).is_err());
        assert!(VelocityField::vortex(bad, Vec3::Z, 1.0).is_err());
        let mut nodes = Nodes::new();
        assert!(nodes.push(bad, Vec3::ZERO, 1.0).is_err());
        assert!(nodes.push_pinned(bad).is_err());
        assert!(nodes.is_empty());
    }
    let zero = VelocityField::vortex(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap_err();
    assert!(
        zero.to_string().contains("vortex axis length must be > 0"),
        "{zero}"
    );
    // A huge finite axis is a direction like any other (it was called non-finite, "got NaN").
    let Ok(VelocityField::Vortex { omega, .. }) =
        VelocityField::vortex(Vec3::ZERO, Vec3::new(0.0, 1e30, 1e30), 2.0)
    else {
        panic!("a huge finite axis is accepted");
    };
    assert!((omega - Vec3::new(0.0, 2.0, 2.0) / 2f32.sqrt()).length() < 1e-6);
    assert!(VelocityField::vortex(Vec3::ZERO, Vec3::Z, f32::NAN).is_err());
    let e = ParticleBundle::new(nan, Vec3::ZERO, 1.0).unwrap_err();
    assert!(e.to_string().contains("position must be finite"), "{e}");
}

#[test]
fn spring_constructors_reject_bad_values() {
    let mut world = world();
    let a = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    let b = world
        .spawn(ParticleBundle::new(Vec3::X, Vec3::ZERO, 1.0).unwrap())
        .id();
    assert_eq!(
        Spring::from_strain(a, a, 1.0, 1.0, 0.0).unwrap_err(),
        Error::SelfSpring(a)
    );
    assert!(matches!(
        Spring::from_strain(a, b, 0.0, 1.0, 0.0),
        Err(Error::NotPositive {
            what: "rest length",
            ..
        })
    ));
    assert!(matches!(
        Spring::from_strain(a, b, -1.0, 1.0, 0.0),
        Err(Error::NotPositive { .. })
    ));
    assert!(matches!(
        Spring::new(a, b, -1.0, 1.0, 0.0),
        Err(Error::Negative {
            what: "rest length",
            ..
        })
    ));
    assert!(matches!(
        Spring::new(a, b, 1.0, -1.0, 0.0),
        Err(Error::Negative {
            what: "spring stiffness",
            ..
        })
    ));
    assert!(matches!(
        Spring::new(a, b, 1.0, 1.0, -1.0),
        Err(Error::Negative {
            what: "spring damping",
            ..
        })
    ));
    assert!(matches!(
        Spring::new(a, b, f32::NAN, 1.0, 0.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(
        Spring::new(a, b, 0.0, 1.0, 0.0).is_ok(),
        "zero-length springs are allowed"
    );

    let gone = world.spawn_empty().id();
    world.despawn(gone);
    let s = Spring::new(a, gone, 1.0, 1.0, 0.0).unwrap();
    assert_eq!(s.spawn(&mut world).unwrap_err(), Error::MissingEntity(gone));
    let not_a_body = world.spawn_empty().id();
    let s = Spring::new(a, not_a_body, 1.0, 1.0, 0.0).unwrap();
    assert_eq!(
        s.spawn(&mut world).unwrap_err(),
        Error::MissingEntity(not_a_body)
    );

    let mut net = SpringNetwork::new();
    assert!(net.push(3, 3, 1.0, 1.0, 0.0).is_err());
    assert!(net.push(0, 1, -1.0, 1.0, 0.0).is_err());
    assert!(net.is_empty());
}

#[test]
fn builders_reject_degenerate_shapes() {
    let mut world = world();
    assert!(matches!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 1).spawn(&mut world),
        Err(Error::TooFew {
            what: "chain nodes",
            min: 2,
            got: 1
        })
    ));
    assert!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 4)
            .node_mass(0.0)
            .spawn(&mut world)
            .is_err()
    );
    assert!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 4)
            .stiffness(-1.0)
            .spawn(&mut world)
            .is_err()
    );
    assert!(ClothBuilder::new(Vec3::ZERO, 2, 10, 0.1).build().is_err());
    assert!(ClothBuilder::new(Vec3::ZERO, 10, 10, 0.0).build().is_err());
    // Nothing was spawned by the failed builds.
    assert_eq!(world.query::<&Spring>().iter(&world).count(), 0);
}

#[test]
fn time_step_errors() {
    assert_eq!(
        PhysicsTime::new(0.0, 1).unwrap_err(),
        Error::InvalidTimeStep(0.0)
    );
    assert!(PhysicsTime::new(f32::NAN, 1).is_err());
    assert!(PhysicsTime::new(f32::INFINITY, 1).is_err());
    assert_eq!(PhysicsTime::new(0.01, 0).unwrap_err(), Error::ZeroSubsteps);
    assert!(world().advance_physics(f32::NAN).is_err());
}

fn quarantine_reason(world: &World, e: Entity) -> Option<QuarantineReason> {
    world.get::<Quarantined>(e).map(|q| q.reason.clone())
}

#[test]
fn directly_inserted_bad_components_are_quarantined_by_hooks() {
    let mut world = world();
    let bad_pos = world
        .spawn((Position::from(Vec3::NAN), Mass::new(1.0).unwrap()))
        .id();
    let bad_vel = world
        .spawn((
            LinearVelocity::from(Vec3::INFINITY),
            Mass::new(1.0).unwrap(),
        ))
        .id();
    let bad_damp = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap(),
            LinearDamping(-1.0),
        ))
        .id();
    let bad_scale = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap(),
            GravityScale(f32::NAN),
        ))
        .id();
    let good = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    world.flush();
    for e in [bad_pos, bad_vel, bad_damp, bad_scale] {
        assert!(
            matches!(
                quarantine_reason(&world, e),
                Some(QuarantineReason::InvalidInput(_))
            ),
            "{e} not quarantined"
        );
    }
    assert!(quarantine_reason(&world, good).is_none());
    for _ in 0..10 {
        world.step_physics();
    }
    assert!(x(&world, good).y < 0.0);
    assert_eq!(
        x(&world, bad_damp),
        Vec3::ZERO,
        "quarantined bodies are not simulated"
    );
    assert_eq!(world.resource::<PhysicsDiagnostics>().counts.quarantined, 4);
}

#[test]
fn spring_inserted_to_a_missing_entity_is_quarantined() {
    let mut world = world();
    let a = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    let gone = world.spawn_empty().id();
    world.despawn(gone);
    let s = world
        .spawn(Spring::new(a, gone, 1.0, 1.0, 0.0).unwrap())
        .id();
    world.flush();
    assert_eq!(
        quarantine_reason(&world, s),
        Some(QuarantineReason::InvalidInput(Error::MissingEntity(gone)))
    );
    world.step_physics();
    assert!(x(&world, a).is_finite());
}

#[test]
fn out_of_range_spring_network_quarantines_the_mesh_without_panicking() {
    let mut world = world();
    let mut nodes = Nodes::new();
    nodes.push(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap();
    nodes.push(Vec3::X, Vec3::ZERO, 1.0).unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 7, 1.0, 1.0, 0.0).unwrap();
    assert!(!net.fits(&nodes));
    let mesh = world.spawn((nodes, net)).id();
    world.step_physics();
    world.step_physics();
    assert!(matches!(
        quarantine_reason(&world, mesh),
        Some(QuarantineReason::InvalidInput(
            Error::IndexOutOfRange { .. }
        ))
    ));
}

#[test]
fn non_finite_state_mid_step_is_quarantined_reported_and_contained() {
    let mut world = world();
    let chain = ChainBuilder::rope(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), 4)
        .spawn(&mut world)
        .unwrap();
    let other = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    world.step_physics();
    // Game code writes NaN through a mutable borrow: no hook sees it.
    let victim = chain.nodes[2];
    world.get_mut::<LinearVelocity>(victim).unwrap().0 = Vec3::NAN.into();
    world.step_physics();
    assert_eq!(
        quarantine_reason(&world, victim),
        Some(QuarantineReason::NonFiniteState)
    );
    let messages = world.resource::<Messages<BodyQuarantined>>();
    let mut cursor = messages.get_cursor();
    let reported: Vec<_> = cursor.read(messages).cloned().collect();
    assert_eq!(reported.len(), 1);
    assert_eq!(reported[0].entity, victim);
    assert_eq!(world.resource::<PhysicsDiagnostics>().quarantined_total, 1);
    for _ in 0..200 {
        world.step_physics();
    }
    // The neighbours on the same rope never picked up the NaN.
    for &n in &chain.nodes {
        if n != victim {
            assert!(
                x(&world, n).is_finite() && v(&world, n).is_finite(),
                "{n} poisoned"
            );
            assert!(quarantine_reason(&world, n).is_none());
        }
    }
    assert!(x(&world, other).y < -1.0);
    // Repairing the state and lifting the quarantine puts the body back.
    world.get_mut::<LinearVelocity>(victim).unwrap().0 = Vec3::ZERO.into();
    world.get_mut::<Position>(victim).unwrap().0 = Vec3::new(0.66, 0.0, 0.0).into();
    world.entity_mut(victim).remove::<Quarantined>();
    world.step_physics();
    assert!(v(&world, victim).y < 0.0);
}

#[test]
fn nan_from_a_custom_field_quarantines_only_the_tracer() {
    let mut world = world();
    world.spawn(VelocityField::custom(|x, _| {
        if x.x > 0.5 { Vec3::NAN } else { Vec3::X }
    }));
    let doomed = world
        .spawn((Position::from(Vec3::new(1.0, 0.0, 0.0)), Tracer))
        .id();
    let fine = world
        .spawn((Position::from(Vec3::new(-5.0, 0.0, 0.0)), Tracer))
        .id();
    world.step_physics();
    world.step_physics();
    assert_eq!(
        quarantine_reason(&world, doomed),
        Some(QuarantineReason::NonFiniteState)
    );
    assert_eq!(
        x(&world, doomed),
        Vec3::new(1.0, 0.0, 0.0),
        "state kept as it was"
    );
    assert!((x(&world, fine).x + 4.98).abs() < 1e-5);
}
