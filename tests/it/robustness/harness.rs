//! The fuzz harness shared by `robustness::fuzz` (a bounded budget in CI) and
//! `examples/fuzz.rs` (the long run): property tests over every public constructor and over
//! random small worlds built through the public API, counting what happened to each input.
#![allow(dead_code)]

use std::panic::{AssertUnwindSafe, catch_unwind};

use bevy_ecs::prelude::*;
use hooke::core::time::PhysicsTime;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::soft::{CellSplit, Material, StrainModel, TetMesh};
use hooke::tools::scenes;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};

/// What the inputs did.
#[derive(Debug, Default, Clone)]
pub struct Tally {
    /// The smallest failing case proptest shrank the first failure to, with its reason
    /// (a failure).
    pub failure: Option<String>,
    /// Constructor calls, or fuzzed worlds.
    pub inputs: usize,
    /// Constructor calls that returned `Ok`.
    pub accepted: usize,
    /// Typed errors.
    pub errors: usize,
    /// Panics (each a failure).
    pub panics: usize,
    /// Bodies quarantined (worlds).
    pub quarantines: usize,
    /// Bodies left with a non-finite or unbounded state and no quarantine (each a failure).
    pub silent: usize,
    /// Steps run (worlds).
    pub steps: usize,
    /// Snapshots that did not continue bit-identically (each a failure).
    pub snapshot_mismatches: usize,
    /// Snapshots refused at restore with a typed error because a live body held a value
    /// that fails its checks (a material written through `get_mut` and not yet read).
    pub snapshot_refused: usize,
}

/// Floats a game could hand over, good and bad: the range a game uses, and the edges.
pub fn wild() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -100.0f32..100.0,
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(f32::MAX),
        1 => Just(f32::MIN_POSITIVE),
        1 => Just(1e-30f32),
        1 => Just(1e30f32),
        1 => Just(-1e30f32),
        1 => 1e6f32..1e12,
    ]
}

pub fn wild_vec() -> impl Strategy<Value = Vec3> {
    (wild(), wild(), wild()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn wild_count() -> impl Strategy<Value = usize> {
    prop_oneof![
        6 => 0usize..12,
        1 => Just(usize::MAX),
        1 => Just(1usize << 40),
        1 => Just(u32::MAX as usize + 1),
    ]
}

/// One constructor's outcome: `Ok`, a typed error, or a panic.
fn call<T>(tally: &mut Tally, f: impl FnOnce() -> hooke::Result<T>) -> Option<T> {
    tally.inputs += 1;
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(v)) => {
            tally.accepted += 1;
            Some(v)
        }
        Ok(Err(_)) => {
            tally.errors += 1;
            None
        }
        Err(_) => {
            tally.panics += 1;
            None
        }
    }
}

/// Every public constructor, with the case's numbers.
fn constructors(
    t: &mut Tally,
    (a, b, c, d): (f32, f32, f32, f32),
    (u, v, w): (Vec3, Vec3, Vec3),
    (n, m): (usize, usize),
) -> Result<(), TestCaseError> {
    let panics = t.panics;
    let q = Quat::from_xyzw(a, b, c, d);
    let e = Entity::from_raw_u32(1).unwrap();
    let f = Entity::from_raw_u32(2).unwrap();
    call(t, || Position::try_new(u));
    call(t, || LinearVelocity::try_new(u));
    call(t, || Mass::new(a));
    call(t, || ParticleBundle::new(u, v, a));
    call(t, || ParticleBundle::pinned(u));
    call(t, || hooke::particles::Gravity::new(u));
    call(t, || VelocityField::uniform(u));
    call(t, || VelocityField::vortex(u, v, a));
    call(t, || Spring::from_strain(e, f, a, b, c));
    call(t, || Spring::new(e, f, a, b, c));
    call(t, || Spring::from_strain(e, e, 1.0, 1.0, 0.0));
    call(t, || {
        Spring::from_strain(e, f, 1.0, 1.0, 0.0)?.with_anchors(u, v)
    });
    if let Some(col) = call(t, || Collider::ball(a)) {
        prop_assert!(a > 0.0 && a.is_finite(), "ball({a}) accepted");
        let _ = col;
    }
    call(t, || Collider::cuboid(a, b, c));
    call(t, || Collider::capsule_y(a, b));
    call(t, || Collider::cylinder(a, b));
    call(t, || Collider::convex_hull(&[u, v, w]));
    call(t, || {
        Collider::convex_hull(&[u, v, w, u + v, v + w, Vec3::splat(a)])
    });
    call(t, || Collider::trimesh(vec![u, v, w], vec![[0, 1, 2]]));
    call(t, || Collider::trimesh(vec![u, v, w], vec![[0, 1, 3]]));
    call(t, || {
        Collider::heightfield(n, m, vec![a; n.min(64) * m.min(64)], u)
    });
    call(t, || {
        let part = Collider::cuboid(a.abs(), 1.0, 1.0)?;
        Collider::compound(vec![(u, q, part)])
    });
    call(t, || {
        let inner = Collider::compound(vec![(Vec3::ZERO, Quat::IDENTITY, Collider::ball(1.0)?)])?;
        Collider::compound(vec![(u, q, inner)])
    });
    call(t, || ColliderDensity::try_new(a));
    call(t, || ColliderOffset::try_new(u, q));
    call(t, || Rotation::try_new(q));
    call(t, || Inertia::new(u, q));
    call(t, || Inertia::diagonal(a, b, c));
    call(t, || {
        MassProperties::new(a, u, Inertia::diagonal(1.0, 1.0, 1.0)?)
    });
    call(t, || {
        MassProperties::from_tensor(a, u, glam::Mat3::from_cols(u, v, w))
    });
    call(t, || {
        RigidBodyBundle::dynamic(MassProperties::new(
            1.0,
            Vec3::ZERO,
            Inertia::diagonal(1.0, 1.0, 1.0)?,
        )?)?
        .at(u)?
        .with_rotation(q)?
        .with_velocity(v)?
        .with_angular_velocity(w)
    });
    call(t, || PhysicsTime::new(a, n as u32));
    call(t, || {
        PhysicsTime::new(1.0 / 60.0, 4)?.with_max_steps_per_frame(m as u32)
    });
    call(t, || TetMesh::cuboid(u, [n, m, 1], CellSplit::Six));
    call(t, || TetMesh::ball(a, n));
    call(t, || {
        TetMesh::new(vec![u, v, w, Vec3::ONE], vec![[0, 1, 2, 3]])
    });
    call(t, || Material::new(a, b, c));
    call(t, || Material::new(1e5, 0.3, 1000.0)?.with_damping(a, b));
    call(t, || hooke::soft::NodeTargets::new([(n, u)]));
    call(t, || hooke::soft::NodeAttachments::new(e, [n, m]));
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    call(t, || {
        ChainBuilder::rope(u, v, n)
            .stiffness(a)
            .damping(b)
            .spawn(&mut world)
    });
    call(t, || {
        ChainBuilder::hair(u, v, m)
            .node_mass(a)
            .bending(b)
            .spawn(&mut world)
    });
    call(t, || {
        ClothBuilder::new(u, n, m, a)
            .stiffness(b, c, d)
            .spawn(&mut world)
    });
    call(t, || {
        ClothBuilder::new(u, n, m, 0.1)
            .build_cloth()?
            .2
            .with_drag(a)
    });
    call(t, || {
        hooke::soft::SoftBody::build(
            &TetMesh::cuboid(Vec3::ONE, [1, 1, 1], CellSplit::Six)?,
            u,
            Material::new(1e5, 0.3, 1000.0)?,
            StrainModel::Green,
        )
    });
    if t.panics > panics {
        return Err(TestCaseError::fail("a constructor panicked"));
    }
    Ok(())
}

/// A runner whose cases follow from `seed`: the same seed, the same inputs (CI runs are
/// reproducible; the long run takes a seed to explore further).
pub fn runner(cases: u32, seed: u64) -> TestRunner {
    let mut bytes = [0u8; 32];
    for (i, chunk) in bytes.chunks_mut(8).enumerate() {
        chunk.copy_from_slice(
            &(seed ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)).to_le_bytes(),
        );
    }
    TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            // Shrinking reruns whole worlds: enough to reach a small case, bounded in time.
            max_shrink_iters: 200,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &bytes),
    )
}

/// Runs `cases` constructor cases from `seed`; returns the tally.
pub fn fuzz_constructors(cases: u32, seed: u64) -> Tally {
    let mut tally = Tally::default();
    let mut runner = runner(cases, seed);
    let strategy = (
        (wild(), wild(), wild(), wild()),
        (wild_vec(), wild_vec(), wild_vec()),
        (wild_count(), wild_count()),
    );
    // Shrinking reruns failing cases: they go to a scratch tally, so the counts are of the
    // generated cases only.
    let mut scratch = Tally::default();
    let cell = std::cell::RefCell::new((&mut tally, &mut scratch, false));
    let result = runner.run(&strategy, |(s, v, n)| {
        let (tally, scratch, failed) = &mut *cell.borrow_mut();
        let out = constructors(if *failed { scratch } else { tally }, s, v, n);
        *failed |= out.is_err();
        out
    });
    tally.failure = shrunk(result);
    tally
}

/// A failing property is shrunk with this harness's runner and reported by [`shrunk`]: a
/// property failing from 1,000 up is reported at exactly 1,000.
#[test]
fn a_failing_case_is_shrunk_and_reported() {
    let mut runner = runner(100, 15);
    let result = runner.run(&(0u32..1_000_000), |n| {
        if n >= 1000 {
            Err(TestCaseError::fail("too big"))
        } else {
            Ok(())
        }
    });
    let failure = shrunk(result).expect("the property fails");
    assert!(failure.ends_with("minimal case: 1000"), "{failure}");
}

/// The minimal failing case of a run, as text.
pub fn shrunk<T: std::fmt::Debug>(result: Result<(), TestError<T>>) -> Option<String> {
    match result {
        Ok(()) => None,
        Err(TestError::Fail(reason, minimal)) => {
            Some(format!("{reason}; minimal case: {minimal:?}"))
        }
        Err(TestError::Abort(reason)) => Some(format!("aborted: {reason}")),
    }
}

pub use super::world_cases::{WorldCase, world_case};
use super::world_cases::{apply, spawn};

/// The bits of every simulated value of `e` (for the snapshot check).
fn bits(world: &World, e: Entity) -> Vec<u32> {
    let Ok(r) = world.get_entity(e) else {
        return vec![u32::MAX];
    };
    let mut out = Vec::new();
    if let Some(x) = r.get::<Position>() {
        out.extend(x.0.to_array().map(f32::to_bits));
    }
    if let Some(v) = r.get::<LinearVelocity>() {
        out.extend(v.0.to_array().map(f32::to_bits));
    }
    if let Some(q) = r.get::<Rotation>() {
        out.extend(q.0.to_array().map(f32::to_bits));
    }
    if let Some(n) = r.get::<Nodes>() {
        out.extend(
            n.positions()
                .iter()
                .flat_map(|x| x.to_array())
                .map(f32::to_bits),
        );
    }
    out.push(u32::from(r.contains::<Quarantined>()));
    out
}

/// Largest |x| and |v| a live body may have: 1e6 m is Collider::MAX_EXTENT, and the
/// divergence guard quarantines anything past 1e4 m/s.
const BOUND: f32 = 1e6;

/// Counts the live bodies of `world` whose state is non-finite or out of bounds.
pub fn silent_bad(world: &mut World) -> usize {
    let mut bad = 0;
    let verbose = std::env::var_os("HOOKE_FUZZ_VERBOSE").is_some();
    let mut q = world.query_filtered::<(
        Entity,
        &Position,
        Option<&LinearVelocity>,
        Option<&RigidBody>,
    ), Without<Quarantined>>();
    for (e, x, v, kind) in q.iter(world) {
        let v = v.map_or(Vec3A::ZERO, |v| v.0);
        // A static body stays where its input put it (an edited file may put it far away):
        // far is not a blow-up there, only non-finite is.
        let far = kind != Some(&RigidBody::Static) && x.0.abs().max_element() > BOUND;
        if !(x.0.is_finite() && v.is_finite()) || far {
            if verbose {
                println!("silently bad: {e} x {:?} v {v:?}", x.0);
            }
            bad += 1;
        }
    }
    let mut q = world.query_filtered::<(Entity, &Nodes), Without<Quarantined>>();
    for (e, n) in q.iter(world) {
        if !n.is_finite() || n.positions().iter().any(|x| x.abs().max_element() > BOUND) {
            if verbose {
                let bad = n
                    .positions()
                    .iter()
                    .position(|x| !x.is_finite() || x.abs().max_element() > BOUND);
                println!(
                    "silently bad mesh: {e} max speed {}, node {bad:?} at {:?} of {}",
                    n.max_speed(),
                    bad.map(|i| n.positions()[i]),
                    n.len()
                );
            }
            bad += 1;
        }
    }
    bad
}

/// The world of `case` before its first step: the ground and its things (those whose
/// constructors accepted the case's numbers).
fn build(case: &WorldCase) -> (World, Vec<Entity>) {
    let integrator = [
        Integrator::SymplecticEuler,
        Integrator::ExplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
        Integrator::ImplicitEuler,
    ][case.integrator];
    let mut world = scenes::world_with(
        1.0 / 60.0,
        case.substeps,
        integrator,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .expect("valid settings");
    scenes::ground(&mut world).expect("ground");
    let mut all = Vec::new();
    for t in &case.things {
        if let Ok(es) = spawn(&mut world, t) {
            all.extend(es);
        }
    }
    (world, all)
}

/// The world of `case` after its steps and meddling, with no checks (a state to save).
pub fn play(case: &WorldCase) -> World {
    let (mut world, all) = build(case);
    for step in 0..case.steps {
        for (at, m) in &case.meddles {
            if *at == step {
                apply(&mut world, &all, m);
            }
        }
        world.step_physics();
    }
    world
}

/// Runs one world; adds to the tally.
pub fn run_world(case: &WorldCase, tally: &mut Tally, check_snapshot: bool) {
    tally.inputs += 1;
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let (mut world, all) = build(case);
        let mut silent = 0;
        for step in 0..case.steps {
            for (at, m) in &case.meddles {
                if *at == step {
                    apply(&mut world, &all, m);
                }
            }
            world.step_physics();
            tally.steps += 1;
            let now = silent_bad(&mut world);
            if now > 0 && std::env::var_os("HOOKE_FUZZ_VERBOSE").is_some() {
                println!("  at step {step}");
            }
            silent += now;
        }
        let quarantined = world.query::<&Quarantined>().iter(&world).count();
        let mut mismatch = false;
        if check_snapshot {
            let snapshot = Snapshot::capture(&world).expect("no custom fields here");
            let read = Snapshot::from_bytes(&snapshot.to_bytes()).expect("own bytes read back");
            let mut copy = World::new();
            copy.add_physics(PhysicsPlugins);
            let map = match read.restore(&mut copy) {
                Ok(map) => map,
                Err(e @ hooke::snapshot::SnapshotError::Invalid { .. }) => {
                    if std::env::var_os("HOOKE_FUZZ_VERBOSE").is_some() {
                        println!("refused: {e}");
                    }
                    return (silent, quarantined, false, true);
                }
                Err(e) => panic!("own snapshot not restored: {e}"),
            };
            let trace = std::env::var_os("HOOKE_FUZZ_SNAPSHOT_TRACE").is_some();
            for _ in 0..10 {
                if trace {
                    for &e in snapshot.entities() {
                        let c = map.get(e).unwrap();
                        println!(
                            "{e}: {:?} {:?} | {:?} {:?}",
                            world.get::<Position>(e).map(|x| x.0),
                            world.get::<Quarantined>(e).map(|q| q.reason.clone()),
                            copy.get::<Position>(c).map(|x| x.0),
                            copy.get::<Quarantined>(c).map(|q| q.reason.clone())
                        );
                    }
                }
                world.step_physics();
                copy.step_physics();
            }
            for &e in snapshot.entities() {
                let c = map.get(e);
                let (a, b) = (
                    bits(&world, e),
                    c.map(|c| bits(&copy, c)).unwrap_or_default(),
                );
                if a != b {
                    if !mismatch {
                        println!("snapshot mismatch at {e}: {a:?}\n vs {b:?}");
                    }
                    mismatch = true;
                }
            }
        }
        (silent, quarantined, mismatch, false)
    }));
    match outcome {
        Ok((silent, quarantined, mismatch, refused)) => {
            tally.snapshot_refused += usize::from(refused);
            tally.silent += silent;
            tally.quarantines += quarantined;
            tally.snapshot_mismatches += usize::from(mismatch);
            if silent > 0 || mismatch {
                println!("failure (silent {silent}, snapshot mismatch {mismatch}): {case:?}");
            }
        }
        Err(_) => {
            tally.panics += 1;
            println!("panic: {case:?}");
        }
    }
}

/// Which cases of a run to run and whether to announce each (`case K` on stdout, for a
/// supervising parent; see `supervisor`).
#[derive(Debug, Default, Clone, Copy)]
pub struct Cases {
    /// Cases before this one are generated and skipped.
    pub skip: u32,
    /// Print `case K` before case K.
    pub announce: bool,
    next: u32,
}

impl Cases {
    /// From case `skip` on, announced.
    pub fn announced_from(skip: u32) -> Self {
        Self {
            skip,
            announce: true,
            next: 0,
        }
    }

    /// Whether to run the next generated case (not a shrinking rerun). Announced, it prints
    /// the tally of the cases `done` so far first, which the supervisor keeps if the child
    /// dies in this case.
    pub fn take(&mut self, done: &Tally) -> bool {
        let k = self.next;
        self.next += 1;
        if k < self.skip {
            return false;
        }
        if self.announce {
            use std::io::Write;
            println!(
                "done{}",
                &super::supervisor::tally_line(done)["tally".len()..]
            );
            println!("case {k}");
            let _ = std::io::stdout().flush();
        }
        true
    }
}

/// Runs `cases` random worlds from `seed`; returns the tally.
pub fn fuzz_worlds(cases: u32, seed: u64, check_snapshot: bool) -> Tally {
    fuzz_worlds_of(cases, seed, check_snapshot, Cases::default())
}

/// [`fuzz_worlds`] of some of the cases.
pub fn fuzz_worlds_of(cases: u32, seed: u64, check_snapshot: bool, which: Cases) -> Tally {
    let which = std::cell::RefCell::new(which);
    let mut tally = Tally::default();
    let mut runner = runner(cases, seed);
    let mut scratch = Tally::default();
    let cell = std::cell::RefCell::new((&mut tally, &mut scratch, false));
    let verbose = std::env::var_os("HOOKE_FUZZ_VERBOSE").is_some();
    let trace = std::env::var_os("HOOKE_FUZZ_TRACE").is_some();
    let result = runner.run(&world_case(), |case| {
        if trace {
            // The last case written before a hang is the one that hangs.
            eprintln!("world: {case:?}");
        }
        let start = std::time::Instant::now();
        let (tally, scratch, failed) = &mut *cell.borrow_mut();
        if !*failed && !which.borrow_mut().take(tally) {
            return Ok(());
        }
        // Shrinking reruns failing cases: they go to a scratch tally (see fuzz_constructors).
        let t: &mut Tally = if *failed { scratch } else { tally };
        let before = (t.panics, t.silent, t.snapshot_mismatches);
        run_world(&case, t, check_snapshot);
        let took = start.elapsed().as_secs_f64();
        if verbose && took > 2.0 {
            println!("slow world ({took:.1} s): {case:?}");
        }
        if (t.panics, t.silent, t.snapshot_mismatches) != before {
            *failed = true;
            return Err(TestCaseError::fail(
                "a panic, a silent non-finite or unbounded body, or a snapshot mismatch",
            ));
        }
        Ok(())
    });
    tally.failure = shrunk(result);
    tally
}
