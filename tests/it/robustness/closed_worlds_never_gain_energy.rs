//! Issue 37: a fuzz of closed worlds (no gravity, no damping, no sources) found 7 of 200
//! whose energy grew (×1.3 to ×400) before anything was quarantined. A closed world's
//! energy may only fall: contacts (any restitution ≤ 1, any friction), springs, cloth and
//! soft bodies exchange it and lose it, never make it.
//!
//! Random worlds inside a closed static box: balls and spinning crates, ropes, cloth and
//! jellies, each in its own cell so that nothing starts overlapping (an overlap is stored
//! energy the push-out releases), at random speeds, restitution and friction, with gravity
//! and every damping off, under each integrator that keeps energy bounded (symplectic Euler,
//! velocity Verlet, RK4 and implicit Euler; forward Euler gains energy by design), at 4 to 8
//! substeps and spins up to 104 rad/s (at most 0.43 rad a substep: faster, the bounded
//! energy error of the free-rotation splitting on a body with three unequal moments is no
//! longer small). The total energy `PhysicsDiagnostics::total_energy` (kinetic, rotational,
//! spring and elastic) must never pass the start by more than the scheme's own wobble: a
//! symplectic scheme's measured energy oscillates about the conserved one by O(h ω), which
//! the local substeps of the default stability policy keep below a few percent.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::cloth::ClothBuilder;
use hooke::collision::{Collider, Friction, Restitution};
use hooke::core::quarantine::Quarantined;
use hooke::integrator::Integrator;
use hooke::prelude::*;
use hooke::rigid::{AngularVelocity, RigidBody};
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::springs::ChainBuilder;
use hooke::tools::scenes;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

use super::harness::runner;

/// One thing in a closed world, placed in its own 3 m cell.
#[derive(Debug, Clone)]
enum Thing {
    /// Radius, velocity.
    Ball(f32, Vec3),
    /// Half extents, velocity, spin.
    Crate(Vec3, Vec3, Vec3),
    /// Nodes, stiffness (N/m), end offset, velocity of its free nodes.
    Rope(usize, f32, Vec3, Vec3),
    /// Nodes per side, spacing, velocity.
    Cloth(usize, f32, Vec3),
    /// Young's modulus, implicit, velocity.
    Jelly(f32, bool, Vec3),
}

#[derive(Debug, Clone)]
struct Closed {
    integrator: Integrator,
    substeps: u32,
    restitution: f32,
    friction: f32,
    things: Vec<Thing>,
}

fn vec(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn thing() -> impl Strategy<Value = Thing> {
    prop_oneof![
        (0.1f32..0.6, vec(20.0)).prop_map(|(r, v)| Thing::Ball(r, v)),
        (
            vec(0.5).prop_map(|h| h.abs() + Vec3::splat(0.05)),
            vec(20.0),
            prop_oneof![vec(10.0), vec(60.0)]
        )
            .prop_map(|(h, v, w)| Thing::Crate(h, v, w)),
        (
            2usize..10,
            prop_oneof![10.0f32..1e4, 1e6f32..1e9],
            vec(1.0),
            vec(3.0)
        )
            .prop_map(|(n, k, d, v)| Thing::Rope(n, k, d, v)),
        (3usize..6, 0.1f32..0.3, vec(3.0)).prop_map(|(n, s, v)| Thing::Cloth(n, s, v)),
        (1e4f32..1e6, any::<bool>(), vec(5.0)).prop_map(|(e, i, v)| Thing::Jelly(e, i, v)),
    ]
}

fn closed() -> impl Strategy<Value = Closed> {
    (
        prop_oneof![
            Just(Integrator::SymplecticEuler),
            Just(Integrator::VelocityVerlet),
            Just(Integrator::Rk4),
            Just(Integrator::ImplicitEuler),
        ],
        prop_oneof![Just(4u32), 4u32..9],
        0.0f32..1.0,
        0.0f32..1.0,
        prop::collection::vec(thing(), 1..8),
    )
        .prop_map(
            |(integrator, substeps, restitution, friction, things)| Closed {
                integrator,
                substeps,
                restitution,
                friction,
                things,
            },
        )
}

/// The box's inside half extent (m): eight 3 m cells in a 2 × 2 × 2 block, with a margin.
const INSIDE: f32 = 3.5;

fn cell(k: usize) -> Vec3 {
    Vec3::new(
        if k & 1 == 0 { -1.5 } else { 1.5 },
        if k & 2 == 0 { -1.5 } else { 1.5 },
        if k & 4 == 0 { -1.5 } else { 1.5 },
    )
}

fn set_nodes_velocity(w: &mut World, e: Entity, v: Vec3) {
    let mut n = w.get_mut::<Nodes>(e).unwrap();
    for i in 0..n.len() {
        if n.inverse_masses()[i] > 0.0 {
            n.set_velocity(i, v).unwrap();
        }
    }
}

fn build(case: &Closed) -> World {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.insert_resource(Gravity::ZERO);
    w.insert_resource(case.integrator);
    w.insert_resource(hooke::core::time::PhysicsTime::new(1.0 / 60.0, case.substeps).unwrap());
    let wall = 0.5;
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let mut half = Vec3::splat(INSIDE + 2.0 * wall);
            half[axis] = wall;
            let mut at = Vec3::ZERO;
            at[axis] = side * (INSIDE + wall);
            w.spawn((
                RigidBody::Static,
                Collider::cuboid(half.x, half.y, half.z).unwrap(),
                Position::from(at),
                Restitution(case.restitution),
                Friction(case.friction),
            ));
        }
    }
    for (k, thing) in case.things.iter().enumerate() {
        let c = cell(k);
        match *thing {
            Thing::Ball(r, v) => {
                let e = scenes::dynamic_ball(&mut w, r, c).unwrap();
                w.entity_mut(e).insert((
                    LinearVelocity::from(v),
                    Restitution(case.restitution),
                    Friction(case.friction),
                ));
            }
            Thing::Crate(h, v, spin) => {
                let e = scenes::dynamic_box(&mut w, h, c).unwrap();
                w.entity_mut(e).insert((
                    LinearVelocity::from(v),
                    AngularVelocity::from(spin),
                    Restitution(case.restitution),
                    Friction(case.friction),
                ));
            }
            Thing::Rope(n, k, d, v) => {
                let start = c - Vec3::X;
                let chain = ChainBuilder::rope(start, start + Vec3::X * 2.0 + d * 0.5, n)
                    .stiffness(k)
                    .damping(0.0)
                    .spawn(&mut w)
                    .unwrap();
                for e in chain.nodes {
                    if let Some(mut l) = w.get_mut::<LinearVelocity>(e) {
                        l.0 = v.into();
                    }
                }
            }
            Thing::Cloth(n, s, v) => {
                let e = ClothBuilder::new(c - Vec3::new(0.5, 0.0, 0.5), n, n, s)
                    .damping(0.0)
                    .pin_corners(false)
                    .spawn(&mut w)
                    .unwrap();
                set_nodes_velocity(&mut w, e, v);
            }
            Thing::Jelly(young, implicit, v) => {
                let mesh = TetMesh::cuboid(Vec3::splat(0.4), [2, 2, 2], CellSplit::Six).unwrap();
                let material = Material::new(young, 0.3, 1000.0).unwrap();
                let body = SoftBody::build(&mesh, c, material, StrainModel::Corotated).unwrap();
                let e = w.spawn(body).id();
                if implicit {
                    w.entity_mut(e)
                        .insert(hooke::integrator::ImplicitEuler::default());
                }
                set_nodes_velocity(&mut w, e, v);
            }
        }
    }
    w
}

/// The energy at the start and its largest value in 3 s, whether anything was quarantined,
/// and whether a system past its explicit limit was left to its scheme with a
/// `StabilityWarning` (the policy rescues only systems under symplectic Euler, the default:
/// one given another integrator on purpose keeps it and is told).
fn run(case: &Closed) -> (f64, f64, bool, bool) {
    let mut w = build(case);
    // The first step measures the start (elastic energy is read from a force pass).
    w.step_physics();
    let start = w.resource::<PhysicsDiagnostics>().total_energy();
    let mut most = start;
    for _ in 0..180 {
        w.step_physics();
        most = most.max(w.resource::<PhysicsDiagnostics>().total_energy());
    }
    let quarantined = w
        .query_filtered::<(), With<Quarantined>>()
        .iter(&w)
        .next()
        .is_some();
    let d = w.resource::<PhysicsDiagnostics>();
    let told = d.stability_warnings > d.rescued;
    (start, most, quarantined, told)
}

/// How far a closed world's energy may rise over its start: the measured energy of a
/// symplectic scheme oscillates about the conserved one.
const WOBBLE: f64 = 0.05;

/// Rounding: a rope at rest holds 1e-10 J of spring energy that the steps move about (J).
const FLOOR: f64 = 1e-6;

#[test]
fn closed_worlds_never_gain_energy() {
    let cases = std::env::var("HOOKE_ENERGY_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48);
    let mut runner = runner(cases, 0xC105ED);
    let worst = std::cell::RefCell::new((0.0f64, String::new()));
    let result = runner.run(&closed(), |case| {
        let (start, most, quarantined, told) = run(&case);
        if told {
            return Ok(());
        }
        let rise = (most - start - FLOOR).max(0.0) / start.max(FLOOR);
        if rise > worst.borrow().0 {
            *worst.borrow_mut() = (rise, format!("{case:?}"));
        }
        if quarantined {
            return Err(TestCaseError::fail(format!("quarantined: {case:?}")));
        }
        if rise > WOBBLE {
            return Err(TestCaseError::fail(format!(
                "energy rose {:.1} % ({start:.3} J to {most:.3} J): {case:?}",
                rise * 100.0
            )));
        }
        Ok(())
    });
    let worst = worst.into_inner();
    println!(
        "{cases} closed worlds: the largest rise {:.2} % in {}",
        worst.0 * 100.0,
        worst.1
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}
