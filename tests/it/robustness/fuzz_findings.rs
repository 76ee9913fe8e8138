//! Regressions for what the fuzzer (`robustness::fuzz`) found, one test each.

use super::harness;

use bevy_ecs::prelude::*;
use hooke::collision::ColliderAabb;
use hooke::collision::ContactSettings;
use hooke::particles::GravityScale;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenes;

/// A plate spun to 2.7e11 rad/s next to a ball, two more spinners and a jelly: a body was
/// flung to 2e8 m within one step while the step's last pass left it slow, and it stayed
/// there unquarantined for 49 steps (the guard checked speed only).
#[test]
fn a_body_flung_out_of_the_world_is_quarantined() {
    use super::world_cases::{Meddle, Thing, WorldCase};
    use glam::Vec3;
    use harness::Tally;
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
        .spawn(Spring::from_strain(d1, d2, 1.0, 10.0, 0.0).unwrap())
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
    world.spawn(Spring::from_strain(a, b, 1.0, 50.0, 0.1).unwrap());
    world.step_physics();
    let snapshot = Snapshot::capture(&world).unwrap();
    let mut copy = World::new();
    copy.add_physics(PhysicsPlugins);
    snapshot.restore(&mut copy).unwrap();
    copy.flush();
    let quarantined = copy.query::<&Quarantined>().iter(&copy).count();
    assert_eq!(quarantined, 0);
}

/// Energies of large but finite states stay finite: ½ ω·L and ½ k s² of a heavy fast spinner
/// and a stiff stretched spring overflow f32 (they were summed in f32).
#[test]
fn energies_of_large_finite_states_are_finite() {
    use glam::Vec3;
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    world.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let ball = Collider::ball(1.0).unwrap();
    let props = MassProperties::from_shape(&**ball.shape(), 1e30).unwrap();
    let spinner = world
        .spawn((RigidBodyBundle::dynamic(props).unwrap(), ball))
        .id();
    world.get_mut::<AngularVelocity>(spinner).unwrap().0.y = 9e4;
    let a = world
        .spawn(ParticleBundle::pinned(Vec3::ZERO).unwrap())
        .id();
    let b = world
        .spawn(ParticleBundle::pinned(Vec3::new(1e4, 0.0, 0.0)).unwrap())
        .id();
    Spring::new(a, b, 1.0, 1e33, 0.0)
        .unwrap()
        .spawn(&mut world)
        .unwrap();
    world.step_physics();
    assert!(world.get::<Quarantined>(spinner).is_none());
    let d = world.resource::<PhysicsDiagnostics>();
    // ½ I ω² with I = 0.4 m r², m = 4/3 π 1e30 kg.
    let expected_rot = 0.5 * 0.4 * (4.0 / 3.0 * std::f64::consts::PI * 1e30) * 8.1e9;
    assert!(
        (d.rotational_energy / expected_rot - 1.0).abs() < 1e-3,
        "{} vs {expected_rot}",
        d.rotational_energy
    );
    let expected_spring = 0.5 * 1e33 * (1e4f64 - 1.0).powi(2);
    assert!(
        (d.spring_energy / expected_spring - 1.0).abs() < 1e-3,
        "{} vs {expected_spring}",
        d.spring_energy
    );
    assert!(d.total_energy().is_finite());
}

/// A kinematic body given an infinite velocity at step 8 moved to infinity in the substep's
/// integration; the cloth it touched was then pushed out of it in the relax pass, after the
/// cloth's own check, and held a NaN node for one step, unreported. The nodes now skip a
/// collider whose state went bad (it is quarantined by its own check).
#[test]
fn a_cloth_touching_a_body_gone_bad_is_not_handed_its_nan() {
    use super::world_cases::{Meddle, Thing, WorldCase};
    use glam::Vec3;
    use harness::Tally;
    let v = Vec3::new;
    let case = WorldCase {
        integrator: 1,
        substeps: 1,
        things: vec![
            Thing::Rope(
                v(1.6556039, 1.9004717, -3.82871),
                v(1.9262378, -2.1756353, 0.03983877),
                3,
                914.10785,
                6.540923,
            ),
            Thing::Kinematic(
                v(0.23707527, 2.3590405, 2.4933476),
                v(4.663382, -1.3013146, -1.5363545),
            ),
            Thing::Particle(
                v(-3.9456575, 4.6993375, 3.7081163),
                v(6.074169, 5.01801, -6.805982),
                1e6,
            ),
            Thing::Cloth(v(2.8395312, 1.6123738, -1.673399), 2, 0.14282854),
            Thing::Spinner(
                v(2.6094797, 3.6236725, -1.4542127),
                v(198.84665, 123.498886, 26.627428),
            ),
            Thing::Cloth(v(-3.2008512, 0.21102, -1.8036999), 6, 0.20240441),
        ],
        meddles: vec![
            (12, Meddle::Despawn(1402820561424497449)),
            (
                8,
                Meddle::SetVelocity(7576034661957303090, v(f32::INFINITY, 1e30, f32::MAX)),
            ),
            (25, Meddle::Despawn(17597925222388597335)),
            (50, Meddle::Despawn(7581547906091735811)),
        ],
        steps: 64,
    };
    let mut t = Tally::default();
    harness::run_world(&case, &mut t, true);
    assert_eq!(
        (t.panics, t.silent, t.snapshot_mismatches),
        (0, 0, 0),
        "{t:?}"
    );
    assert!(
        t.quarantines >= 1,
        "the kinematic body is quarantined: {t:?}"
    );
}

/// A fuzzed world (a stiff explicit jelly, two crates, a ball and a kinematic body; game
/// code spins a crate to 2e11 rad/s at step 20) held `step_physics` for minutes: the
/// continuous collision check followed the crate's arc by conservative advancement, whose
/// steps grow with the turns. Past 16 turns a step it casts along a line, and the crate is
/// quarantined as spun out. Fails by the watchdog instead of hanging CI.
#[test]
fn a_body_spun_absurdly_fast_does_not_hold_the_step() {
    use super::world_cases::{Meddle, Thing, WorldCase};
    use glam::Vec3;
    use harness::Tally;
    let v = Vec3::new;
    let case = WorldCase {
        integrator: 3,
        substeps: 2,
        things: vec![
            Thing::Crate(
                v(-2.308208, 3.353462, -3.1796749),
                v(-2.7441907, -3.7959654, -6.443566),
                v(0.8450341, 0.5409387, 0.06812489),
            ),
            Thing::Ball(
                v(-2.6559381, 3.0255773, 3.4105127),
                v(3.6945114, 6.4854684, -7.7592583),
                1.487864,
            ),
            Thing::Jelly(v(1.6671848, 1.5948277, -0.7907054), 3546595300.0, false),
            Thing::Crate(
                v(-0.14638935, 1.0459354, 2.6344457),
                v(-7.3769016, 1.2360449, 2.2048204),
                v(0.03875513, 0.0894303, 0.43374178),
            ),
            Thing::Kinematic(
                v(-0.82752043, 2.5176105, -1.1994445),
                v(-1.8355292, -2.6379144, -0.80410504),
            ),
        ],
        meddles: vec![
            (
                2,
                Meddle::Target(11209856509608799323, v(f32::NAN, f32::NEG_INFINITY, -15.6)),
            ),
            (
                36,
                Meddle::Target(4551478632771304437, v(1e30, 1.1754944e-38, 50.49)),
            ),
            (
                20,
                Meddle::SetSpin(10662481609487081879, v(1.1754944e-38, 2.1623246e11, 89.45)),
            ),
            (27, Meddle::SetRestitution(10041987931408365298, 1e30)),
        ],
        steps: 62,
    };
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut t = Tally::default();
        harness::run_world(&case, &mut t, true);
        let _ = done.send(t);
    });
    let t = finished
        .recv_timeout(std::time::Duration::from_secs(300))
        .expect("the world finishes (it held for minutes)");
    assert_eq!(
        (t.panics, t.silent, t.snapshot_mismatches),
        (0, 0, 0),
        "{t:?}"
    );
}

/// Game code's absurd spin is caught and named, not left spinning unreported.
#[test]
fn a_body_spun_past_the_guard_is_quarantined_as_spun_out() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::ground(&mut world).unwrap();
    let spun = scenes::dynamic_box(&mut world, Vec3::splat(0.3), Vec3::new(0.0, 0.3, 0.0)).unwrap();
    world.step_physics();
    world.get_mut::<AngularVelocity>(spun).unwrap().0 = Vec3A::new(0.0, 2.16e11, 89.45);
    world.step_physics();
    let q = world.get::<Quarantined>(spun).expect("quarantined");
    assert!(
        matches!(q.reason, QuarantineReason::SpunOut { angular_speed } if angular_speed > 2e11),
        "{:?}",
        q.reason
    );
}

/// Found by the long fuzz (seed 1, case 3117): a crate whose friction game code set to −∞
/// slid into a cloth. The node contacts read the friction unchecked, so a node's velocity
/// turned NaN after the mesh's own check had run, and the cloth was caught a step late (a
/// silent NaN for a step) and removed for the crate's fault. Now the node contacts check
/// the friction as the rigid contacts do: the crate leaves, named by its error, and the
/// cloth runs on.
#[test]
fn a_bad_friction_quarantines_the_collider_not_the_cloth_it_touches() {
    use super::world_cases::{Meddle, Thing, WorldCase};
    use glam::Vec3;
    use harness::Tally;
    let case = WorldCase {
        integrator: 0,
        substeps: 1,
        things: vec![
            Thing::Cloth(Vec3::new(0.0, 4.0, 0.0), 5, 0.48538855),
            Thing::Crate(
                Vec3::new(2.700706, 4.0, 0.0),
                Vec3::new(-1.5741526, 0.0, 0.0),
                Vec3::new(0.02, 0.41757783, 0.8432839),
            ),
        ],
        meddles: vec![(0, Meddle::SetFriction(1, f32::NEG_INFINITY))],
        steps: 30,
    };
    let mut t = Tally::default();
    harness::run_world(&case, &mut t, true);
    assert_eq!(
        (t.panics, t.silent, t.snapshot_mismatches),
        (0, 0, 0),
        "{t:?}"
    );
    assert_eq!(t.quarantines, 1, "the crate alone: {t:?}");
}

/// Found by the long fuzz (seed 1, case 3927): a box spun to 184 rad/s under explicit Euler
/// hit the ground and left the step at 17.5 km/s, past the guard, after its integrator's
/// check. The next step's check caught it by its change tick, which a restored copy does
/// not carry, so the copy moved it 10 m before catching it another way. The check now runs
/// at the end of each step as well: a saved state holds no unreported runaway, and the
/// copy continues bit for bit. (That box no longer runs away: its contacts now follow its
/// turning inertia. A kinematic slab at 9 km/s bouncing a crate off itself at restitution 1
/// puts the crate past the guard inside the step the same way.)
#[test]
fn a_runaway_left_by_the_step_is_caught_before_a_snapshot_sees_it() {
    use super::world_cases::{Meddle, Thing, WorldCase};
    use glam::Vec3;
    use harness::Tally;
    let case = WorldCase {
        integrator: 1,
        substeps: 1,
        things: vec![
            Thing::Kinematic(Vec3::new(0.0, 5000.0, 0.0), Vec3::new(0.0, -9000.0, 0.0)),
            Thing::Crate(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::splat(0.3)),
        ],
        meddles: vec![(0, Meddle::SetRestitution(1, 1.0))],
        steps: 34,
    };
    let mut t = Tally::default();
    harness::run_world(&case, &mut t, true);
    assert_eq!(
        (t.panics, t.silent, t.snapshot_mismatches),
        (0, 0, 0),
        "{t:?}"
    );
    assert_eq!(t.quarantines, 1, "{t:?}");
}
