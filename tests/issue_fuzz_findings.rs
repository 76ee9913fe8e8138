//! Regressions for what the fuzzer (`tests/fuzz.rs`) found, one test each.

#[path = "fuzz/harness.rs"]
mod harness;

use bevy_ecs::prelude::*;
use hooke::collision::ColliderAabb;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::{ContactSettings, GravityScale, scenes};

/// A plate spun to 2.7e11 rad/s next to a ball, two more spinners and a jelly: a body was
/// flung to 2e8 m within one step while the step's last pass left it slow, and it stayed
/// there unquarantined for 49 steps (the guard checked speed only).
#[test]
fn a_body_flung_out_of_the_world_is_quarantined() {
    use glam::Vec3;
    use harness::{Meddle, Tally, Thing, WorldCase};
    let case = WorldCase {
        integrator: 2,
        substeps: 4,
        things: vec![
            Thing::Ball(
                Vec3::new(-1.08, 2.394054, -1.2452469),
                Vec3::new(4.468486, 4.062965, -2.7563262),
                1.4960209,
            ),
            Thing::Kinematic(
                Vec3::new(-1.349126, 0.18774915, -0.40701675),
                Vec3::new(-4.9971046, 4.1282544, 2.3106985),
            ),
            Thing::Spinner(
                Vec3::new(-1.8901224, 4.765708, 0.5364053),
                Vec3::new(-89.564476, -3.6473188, 35.50615),
            ),
            Thing::Jelly(Vec3::new(1.729151, 7.833995, -3.8114598), 194300.31, false),
            Thing::Spinner(
                Vec3::new(2.3267925, 1.4634721, -3.960173),
                Vec3::new(154.71007, -86.13392, 92.9736),
            ),
        ],
        meddles: vec![(
            13,
            Meddle::SetSpin(3153646486790439651, Vec3::new(1e-30, 273258890000.0, 0.0)),
        )],
        steps: 63,
    };
    let mut t = Tally::default();
    harness::run_world(&case, &mut t, true);
    assert_eq!(
        (t.panics, t.silent, t.snapshot_mismatches),
        (0, 0, 0),
        "{t:?}"
    );
    assert!(t.quarantines >= 2, "{t:?}");
}

#[test]
fn a_body_written_far_out_is_quarantined_out_of_bounds() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    let e = scenes::dynamic_box(&mut world, Vec3::splat(0.5), Vec3::ZERO).unwrap();
    world.step_physics();
    world.get_mut::<Position>(e).unwrap().0 = Vec3A::new(2e8, 0.0, 0.0);
    world.step_physics();
    let q = world.get::<Quarantined>(e).expect("quarantined");
    assert!(
        matches!(q.reason, QuarantineReason::OutOfBounds { distance, node: None } if distance >= 2e8),
        "{:?}",
        q.reason
    );
}

/// A new `ContactSettings::margin` left static colliders' boxes grown by the old one (they
/// are only recomputed when the broad phase rebuilds): a restored snapshot, which rebuilds,
/// then saw other boxes and a soft body took other contacts.
#[test]
fn a_new_margin_reaches_static_boxes() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    let ground = scenes::ground(&mut world).unwrap();
    world.step_physics();
    let before = *world.get::<ColliderAabb>(ground).unwrap();
    world.resource_mut::<ContactSettings>().margin = 0.0;
    world.step_physics();
    let after = *world.get::<ColliderAabb>(ground).unwrap();
    let d = ContactSettings::default().margin;
    assert!(
        (before.max.y - after.max.y - d).abs() < 1e-6,
        "{before:?} -> {after:?}"
    );
}

/// A spring whose table comes before its ends' (its archetype was made first) was restored
/// before them, and its insert hook, finding no ends yet, quarantined it.
#[test]
fn springs_restored_before_their_ends_are_not_quarantined() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    // Make the spring archetype exist before the ends' archetype.
    let d1 = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    let d2 = world
        .spawn(ParticleBundle::new(Vec3::X, Vec3::ZERO, 1.0).unwrap())
        .id();
    let ds = world
        .spawn(Spring::new(d1, d2, 1.0, 10.0, 0.0).unwrap())
        .id();
    for e in [ds, d1, d2] {
        world.despawn(e);
    }
    let end = |x: f32, w: &mut World| {
        w.spawn((
            ParticleBundle::new(Vec3::new(x, 2.0, 0.0), Vec3::ZERO, 1.0).unwrap(),
            GravityScale(0.5),
        ))
        .id()
    };
    let (a, b) = (end(0.0, &mut world), end(1.2, &mut world));
    world.spawn(Spring::new(a, b, 1.0, 50.0, 0.1).unwrap());
    world.step_physics();
    let snapshot = Snapshot::capture(&world).unwrap();
    let mut copy = World::new();
    copy.add_physics(PhysicsPlugins);
    snapshot.restore(&mut copy).unwrap();
    copy.flush();
    let quarantined = copy.query::<&Quarantined>().iter(&copy).count();
    assert_eq!(quarantined, 0);
}
