//! Backward Euler for `Spring` entities (ropes from `ChainBuilder`, springs on rigid bodies),
//! through the global dial (`Integrator::ImplicitEuler`), a per-spring `ImplicitEuler`, and
//! the default `StabilityPolicy`, against closed forms.

use crate::common;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::quarantine::Quarantined;
use hooke::core::time::PhysicsTime;
use hooke::integrator::StabilityPolicy;
use hooke::integrator::StabilityWarning;
use hooke::integrator::{ImplicitEuler, ImplicitScheme, Rescue};
use hooke::prelude::*;
use hooke::springs::ChainBuilder;
use hooke::tools::scenes;

fn warnings(w: &World) -> Vec<StabilityWarning> {
    let m = w.resource::<Messages<StabilityWarning>>();
    m.get_cursor().read(m).cloned().collect()
}

/// Kinetic (translational and rotational), gravitational and spring energy (J).
fn total_energy(w: &World) -> f64 {
    let d = w.resource::<PhysicsDiagnostics>();
    d.kinetic_energy + d.gravitational_energy + d.spring_energy
}

#[test]
fn the_implicit_dial_on_the_unit_oscillator_matches_backward_euler_and_is_first_order() {
    let h = 1.0 / 60.0;
    let (mut w, body) = common::oscillator(h, Integrator::ImplicitEuler, 0.0);
    let e0 = common::oscillator_energy(&w, body);
    for _ in 0..600 {
        w.step_physics();
    }
    let ratio = common::oscillator_energy(&w, body) / e0;
    let omega2 = 4.0 * std::f64::consts::PI.powi(2);
    let closed = (1.0 / (1.0 + omega2 * f64::from(h).powi(2))).powi(600);
    println!(
        "entity spring, implicit dial: energy after 10 periods x{ratio:.5} (closed x{closed:.5})"
    );
    assert!((ratio / closed - 1.0).abs() < 0.02, "{ratio} vs {closed}");
    assert!((ratio - 0.0014).abs() < 0.0002);

    let error_at = |h: f32| {
        let (mut w, body) = common::oscillator(h, Integrator::ImplicitEuler, 0.0);
        for _ in 0..(0.3 / h).round() as usize {
            w.step_physics();
        }
        (common::x(&w, body).x - (common::TWO_PI * 0.3).cos()).abs()
    };
    let (coarse, fine) = (error_at(0.3 / 60.0), error_at(0.3 / 120.0));
    let order = (coarse / fine).log2();
    println!("error at t = 0.3 s: {coarse:.2e} -> {fine:.2e}, order {order:.2}");
    assert!((order - 1.0).abs() < 0.15, "{order}");
}

#[test]
fn one_backward_euler_step_of_a_particle_is_exact() {
    // v₁ = (v₀ − h ω² x₀) / (1 + h² ω²), x₁ = x₀ + h v₁ for x₀ = 1, v₀ = 0.
    let h = 0.1f64;
    let (mut w, body) = common::oscillator(h as f32, Integrator::ImplicitEuler, 0.0);
    w.step_physics();
    let omega2 = 4.0 * std::f64::consts::PI.powi(2);
    let v1 = -h * omega2 / (1.0 + h * h * omega2);
    let x1 = 1.0 + h * v1;
    let (x, v) = (common::x(&w, body).x, common::v(&w, body).x);
    println!("one step: x {x} (closed {x1:.6}), v {v} (closed {v1:.6})");
    assert!((f64::from(v) - v1).abs() < 1e-4 * v1.abs(), "{v} vs {v1}");
    assert!((f64::from(x) - x1).abs() < 1e-5, "{x} vs {x1}");
}

/// A 20-node rope whose top segment stretches 0.1 % under the rope's weight: k ≈ 3.7e5 N/m,
/// needing 36 substeps explicitly.
fn stiff_rope() -> ChainBuilder {
    let weight = 20.0 * 0.1 * 9.81;
    ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), 20)
        .stiffness(weight / (1e-3 / 19.0))
}

use common::default_world;

/// A world at the defaults whose stability policy solves what is past its limit by BDF2
/// (the policy's choice past its local-substep count, and what these tests exercise).
fn bdf2_world() -> World {
    let mut w = default_world();
    w.insert_resource(StabilityPolicy::SwitchToImplicit(ImplicitScheme::Bdf2));
    w
}

#[test]
fn a_stiff_rope_just_works_under_bdf2() {
    let mut w = bdf2_world();
    let rope = stiff_rope().spawn(&mut w).unwrap();
    w.step_physics();
    let told = warnings(&w);
    assert_eq!(told.len(), 1, "{told:?}");
    assert_eq!(told[0].rescue, Some(Rescue::Implicit(ImplicitScheme::Bdf2)));
    println!("{}", told[0].advice());
    for &s in &rope.springs {
        assert!(
            w.get::<ImplicitEuler>(s).is_some(),
            "every segment is switched"
        );
    }
    // 10 s at 60 Hz, 4 substeps: released horizontal, it swings down and keeps swinging (its
    // damping acts along the springs only), never gaining energy and never stretching far.
    let e0 = total_energy(&w);
    let mut most = f64::NEG_INFINITY;
    let mut strain = 0.0f32;
    for _ in 0..600 {
        w.step_physics();
        most = most.max(total_energy(&w) - e0);
        for &s in &rope.springs {
            strain = strain.max(w.get::<Spring>(s).unwrap().reading(&w).unwrap().strain);
        }
    }
    let d = w.resource::<PhysicsDiagnostics>();
    println!(
        "swinging stiff rope, 10 s: energy gain at most {most:.3e} J, largest strain {strain:.2e}"
    );
    assert_eq!(d.quarantined_total, 0);
    assert_eq!(d.stability_warnings, 1);
    assert!(most < 1e-3 * e0.abs().max(1.0), "{most} J gained");
    assert!(strain < 0.01, "{strain}");
}

#[test]
fn a_stiff_rope_hung_straight_comes_to_rest_under_bdf2_with_each_spring_carrying_the_weight_below()
{
    let mut w = bdf2_world();
    let rope = ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 20)
        .stiffness(20.0 * 0.1 * 9.81 / (1e-3 / 19.0))
        .spawn(&mut w)
        .unwrap();
    for _ in 0..300 {
        w.step_physics();
    }
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    let speed = rope
        .nodes
        .iter()
        .map(|&n| common::v(&w, n).length())
        .fold(0.0f32, f32::max);
    println!("hung straight, after 5 s: fastest node {speed:.2e} m/s");
    assert!(speed < 1e-3, "comes to rest: {speed} m/s");
    // A reading from f32 positions resolves the tension to k · ulp(y): 0.044 N at 1 m (the
    // solve carries positions below an ulp, which the reading does not see).
    let k = 20.0 * 0.1 * 9.81 / (1e-3 / 19.0);
    for (i, &s) in rope.springs.iter().enumerate() {
        let r = w.get::<Spring>(s).unwrap().reading(&w).unwrap();
        let below = (19 - i) as f32 * 0.1 * 9.81;
        let floor = k * f32::EPSILON;
        assert!(
            (r.tension - below).abs() < 0.02 * below + floor,
            "spring {i}: {} N vs {below} N",
            r.tension
        );
    }
}

#[test]
fn under_the_warn_policy_the_stiff_rope_stays_explicit_and_the_guard_catches_it() {
    let mut w = default_world();
    w.insert_resource(StabilityPolicy::Warn);
    let rope = stiff_rope().spawn(&mut w).unwrap();
    w.step_physics();
    let told = warnings(&w);
    assert_eq!(told.len(), 1);
    assert_eq!(told[0].rescue, None);
    for _ in 0..4 {
        w.step_physics();
    }
    assert!(
        rope.springs
            .iter()
            .all(|&s| w.get::<ImplicitEuler>(s).is_none())
    );
    assert!(
        rope.nodes
            .iter()
            .any(|&n| w.get::<Quarantined>(n).is_some())
    );
}

#[test]
fn a_spring_marked_implicit_is_solved_so_even_under_the_warn_policy() {
    let mut w = default_world();
    w.insert_resource(StabilityPolicy::Warn);
    let rope = stiff_rope().spawn(&mut w).unwrap();
    for &s in &rope.springs {
        w.entity_mut(s).insert(ImplicitEuler::default());
    }
    for _ in 0..120 {
        w.step_physics();
    }
    assert!(warnings(&w).is_empty(), "an implicit spring has no limit");
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    let bottom = common::x(&w, *rope.nodes.last().unwrap());
    assert!(bottom.is_finite() && bottom.length() < 3.5, "{bottom}");
}

/// A box of `m` kg and half extents `h` at `x`, without a collider.
fn box_body(m: f32, h: Vec3, x: Vec3) -> RigidBodyBundle {
    let i = |a: f32, b: f32| m / 3.0 * (a * a + b * b);
    let inertia = Inertia::diagonal(i(h.y, h.z), i(h.x, h.z), i(h.x, h.y)).unwrap();
    RigidBodyBundle::dynamic(MassProperties::new(m, Vec3::ZERO, inertia).unwrap())
        .unwrap()
        .at(x)
        .unwrap()
}

#[test]
fn a_rigid_box_on_a_stiff_spring_at_its_centre_bobs_about_the_static_stretch() {
    // 10 kg box on a 1 m spring of 3.6e6 N/m from a pin: ω = 600 rad/s, ωh = 2.5 at 240 Hz
    // (explicitly unstable). Static stretch g / ω² = 2.725e-5 m.
    let mut w = default_world();
    let pin = w.spawn(ParticleBundle::pinned(Vec3::ZERO).unwrap()).id();
    let body = w
        .spawn(box_body(10.0, Vec3::splat(0.1), Vec3::new(0.0, -1.0, 0.0)))
        .id();
    Spring::new(pin, body, 1.0, 3.6e6, 0.0)
        .unwrap()
        .spawn(&mut w)
        .unwrap();
    w.step_physics();
    let told = warnings(&w);
    assert_eq!(told.len(), 1);
    // ω = 600 rad/s: 2 local substeps per substep keep it explicit.
    assert_eq!(told[0].rescue, Some(Rescue::LocalSubsteps(2)));
    // Undamped, released at the rest length, it bobs between no stretch and twice the static
    // one: the static stretch is the mean over the last 5 s.
    let (mut farthest, mut mean) = (0.0f32, 0.0f64);
    for step in 0..600 {
        w.step_physics();
        farthest = farthest.max(common::x(&w, body).length());
        if step >= 300 {
            mean += f64::from(-common::x(&w, body).y - 1.0) / 300.0;
        }
    }
    let x = common::x(&w, body);
    let stretch = mean as f32;
    println!(
        "box: swung to {farthest:.5} m from the pin; at {x} after 10 s, mean stretch {stretch:.3e} m (closed 2.725e-5)"
    );
    assert!(
        farthest < 1.001,
        "the spring never stretched past 1 mm: {farthest}"
    );
    assert!(x.x.abs() < 0.01, "{x}");
    assert!((stretch / 2.725e-5 - 1.0).abs() < 0.03, "{stretch}");
}

#[test]
fn a_box_hung_off_centre_by_a_stiff_spring_swings_without_gaining_energy() {
    // The spring holds a corner, 0.41 m from the centre: the box's angular response matters
    // (the corner moves 2.6 times as far under a force as the centre would). Released at
    // the spring's rest length, 37 degrees off the vertical.
    let mut w = default_world();
    let pin = w
        .spawn(ParticleBundle::pinned(Vec3::new(0.0, 5.0, 0.0)).unwrap())
        .id();
    let body = w
        .spawn(box_body(
            10.0,
            Vec3::new(0.4, 0.1, 0.1),
            Vec3::new(0.2, 4.1, 0.0),
        ))
        .id();
    let corner = Vec3::new(0.4, 0.1, 0.0);
    let spring = Spring::new(pin, body, 1.0, 1e6, 50.0)
        .unwrap()
        .with_anchors(Vec3::ZERO, corner)
        .unwrap()
        .spawn(&mut w)
        .unwrap();
    w.step_physics();
    let e0 = total_energy(&w);
    let told = warnings(&w);
    assert_eq!(told.len(), 1, "the lever arm lowers the limit: {told:?}");
    // Anchored off the centre: the body is stepped whole, 4 times per substep.
    assert_eq!(told[0].rescue, Some(Rescue::LocalSubsteps(4)));
    let (mut most, mut strain) = (f64::NEG_INFINITY, 0.0f32);
    for _ in 0..1200 {
        w.step_physics();
        most = most.max(total_energy(&w) - e0);
        let r = w.get::<Spring>(spring).unwrap().reading(&w).unwrap();
        strain = strain.max(r.strain.abs());
    }
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    let e = total_energy(&w) - e0;
    println!(
        "off-centre box, 20 s: energy gain at most {most:.3} J, at the end {e:.2} J; largest strain {strain:.2e}"
    );
    // 0.5 J is the f32 rounding of a 400 J total. Stepped whole at a finer step, the box
    // keeps its swing: only the spring's own damping (along it, where the motion is tiny)
    // takes anything (backward Euler, the rescue before, took over 10 J).
    assert!(most < 0.5, "{most} J gained");
    assert!(e.abs() < 1.0, "the swing is kept: {e} J");
    assert!(strain < 2e-3, "{strain}");
}

#[test]
fn leaving_the_implicit_dial_takes_the_dials_solver_off_the_meshes() {
    let mut w = scenes::world_with(1.0 / 60.0, 1, Integrator::ImplicitEuler, Vec3::ZERO).unwrap();
    let mut nodes = Nodes::new();
    nodes.push_pinned(Vec3::ZERO).unwrap();
    nodes.push(Vec3::X, Vec3::ZERO, 1.0).unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 1, 0.0, 10.0, 0.0).unwrap();
    let mesh = w.spawn((nodes, net)).id();
    w.step_physics();
    assert!(w.get::<ImplicitEuler>(mesh).is_some());
    *w.resource_mut::<Integrator>() = Integrator::SymplecticEuler;
    w.step_physics();
    assert!(w.get::<ImplicitEuler>(mesh).is_none());
    let _ = w.resource::<PhysicsTime>();
}

/// 10 links of 1 kg holding 10,000 kg, k = 1e6 N/m and c = 2e5 N·s/m per link, hung
/// straight down from (0, 5, 0).
fn loaded_chain(w: &mut World) -> hooke::springs::Chain {
    ChainBuilder::rope(Vec3::new(0.0, 5.0, 0.0), Vec3::new(0.0, 4.0, 0.0), 11)
        .node_mass(1.0)
        .stiffness(1e6)
        .damping(2e5)
        .end_load(1e4)
        .spawn(w)
        .unwrap()
}

/// 30 nodes of 1 g over 1 m between two pins, pre-stretched 5 %, k = 1e5 N/m.
fn taut_string(w: &mut World) -> hooke::springs::Chain {
    ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), 30)
        .node_mass(0.001)
        .stiffness(1e5)
        .damping(0.05)
        .pin_end(true)
        .rest_scale(0.95)
        .spawn(w)
        .unwrap()
}

/// 1 g beads on springs of 1e6 N/m (ω = 3e4 rad/s, 130 times the substep's limit): a 0.5 m
/// rope from a pin at (0, 1, 0), released horizontal.
fn stiff_beads(w: &mut World) -> hooke::springs::Chain {
    ChainBuilder::rope(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.5, 1.0, 0.0), 6)
        .node_mass(0.001)
        .stiffness(1e6)
        .damping(0.1)
        .spawn(w)
        .unwrap()
}

/// The hard-case catalogue at the defaults (60 Hz, 4 substeps, the default policy): each
/// stays finite and bounded, never quarantined, and comes to rest.
fn settles(name: &str, w: &mut World, nodes: &[Entity], seconds: f32, bound: f32) {
    let steps = (seconds * 60.0) as usize;
    let mut farthest = 0.0f32;
    for _ in 0..steps {
        w.step_physics();
        for &n in nodes {
            farthest = farthest.max(common::x(w, n).length());
        }
    }
    let speed = nodes
        .iter()
        .map(|&n| common::v(w, n).length())
        .fold(0.0f32, f32::max);
    let d = w.resource::<PhysicsDiagnostics>();
    println!(
        "{name}: farthest node {farthest:.3} m, fastest after {seconds} s {speed:.2e} m/s, quarantined {}",
        d.quarantined_total
    );
    assert_eq!(d.quarantined_total, 0, "{name}");
    assert!(farthest < bound, "{name}: {farthest} m");
    assert!(speed < 0.01, "{name}: still moving at {speed} m/s");
}

#[test]
fn a_light_chain_holding_a_thousand_times_its_link_mass_settles() {
    // 10 links of 1 kg, 10,000 kg at the end, k = 1e6 N/m and c = 2e5 N·s/m per link, hung
    // straight down: the load drops about 1 m onto the chain (its bounce, 3.2 rad/s, is
    // damped in about a second; it is the springs' 1e4 rad/s modes that need the implicit
    // solve).
    let mut w = default_world();
    let chain = loaded_chain(&mut w);
    settles("1:1000 chain", &mut w, &chain.nodes, 10.0, 6.0);
    let top = w
        .get::<Spring>(chain.springs[0])
        .unwrap()
        .reading(&w)
        .unwrap();
    let below = (9.0 + 1.0 + 1e4) * 9.81;
    println!(
        "top link tension {:.0} N (weight below {below:.0} N)",
        top.tension
    );
    assert!((top.tension / below - 1.0).abs() < 0.01);
}

#[test]
fn a_taut_string_of_light_masses_pinned_at_both_ends_moves_as_the_fine_explicit_reference() {
    // 30 nodes of 1 g over 1 m, pre-stretched 5 % between two pins, k = 1e5 N/m: explicitly
    // it needs about 170 substeps. Its dampers act along the springs only, so it does not
    // settle in 5 s (an implicit rescue made it, by numerical damping); at the defaults it
    // rings as the same string stepped explicitly at 256 substeps does.
    let mut w = default_world();
    let string = taut_string(&mut w);
    let mut reference = default_world();
    reference.insert_resource(StabilityPolicy::Warn);
    reference.insert_resource(PhysicsTime::new(1.0 / 60.0, 256).unwrap());
    let fine = taut_string(&mut reference);
    let (mut gap, mut farthest) = (0.0f32, 0.0f32);
    for _ in 0..300 {
        w.step_physics();
        reference.step_physics();
        for (&a, &b) in string.nodes.iter().zip(&fine.nodes) {
            gap = gap.max((common::x(&w, a) - common::x(&reference, b)).length());
            farthest = farthest.max(common::x(&w, a).length());
        }
    }
    let d = w.resource::<PhysicsDiagnostics>();
    let mid = common::x(&w, string.nodes[15]);
    println!(
        "taut string, 5 s at the defaults: largest gap to explicit x256 {gap:.2e} m, middle at {mid}"
    );
    assert_eq!(d.quarantined_total, 0);
    assert_eq!(d.rescued_by_substeps, 1);
    assert!(farthest < 3.0, "{farthest}");
    assert!(gap < 1e-4, "{gap}");
    assert!((mid.y - 2.0).abs() < 1e-3, "barely sags: {mid}");
}

/// The farthest any of `nodes` gets from the origin over `steps` steps, asserting that
/// nothing is quarantined.
fn bounded(name: &str, w: &mut World, nodes: &[Entity], steps: usize) -> f32 {
    let mut farthest = 0.0f32;
    for _ in 0..steps {
        w.step_physics();
        for &n in nodes {
            farthest = farthest.max(common::x(w, n).length());
        }
    }
    let quarantined = w.resource::<PhysicsDiagnostics>().quarantined_total;
    println!("{name}: farthest node {farthest:.3} m, quarantined {quarantined}");
    assert_eq!(quarantined, 0, "{name}");
    farthest
}

#[test]
fn a_rope_whose_end_is_yanked_at_50_m_s_stays_finite_and_bounded() {
    let mut w = default_world();
    let rope = stiff_rope().spawn(&mut w).unwrap();
    let end = *rope.nodes.last().unwrap();
    w.step_physics();
    w.get_mut::<LinearVelocity>(end).unwrap().0 = glam::Vec3A::new(0.0, 50.0, 50.0);
    let farthest = bounded("yanked rope", &mut w, &rope.nodes, 600);
    // The rope is 1 m long from a pin at (0, 2, 0): no node gets past 3.1 m from the origin.
    assert!(farthest < 3.1, "{farthest}");
}

#[test]
fn very_stiff_springs_on_light_masses_stay_finite_and_bounded() {
    // 1 g beads on springs of 1e6 N/m (ω = 3e4 rad/s, 130 times the substep's limit), swinging
    // down from the horizontal: a 0.5 m rope from a pin at (0, 1, 0).
    let mut w = default_world();
    let beads = stiff_beads(&mut w);
    let farthest = bounded("stiff beads", &mut w, &beads.nodes, 600);
    assert!(farthest < 1.6, "{farthest}");
}

#[test]
fn under_explicit_integration_each_hard_case_is_caught_in_the_step_it_diverges() {
    // The same catalogue with the springs kept explicit (`StabilityPolicy::Warn`) at the
    // default 60 Hz × 4: each is told, and what diverges is quarantined before any live node
    // passes 100 m.
    type Build = fn(&mut World) -> Vec<Entity>;
    let cases: [(&str, Build); 4] = [
        ("stiff rope", |w| stiff_rope().spawn(w).unwrap().nodes),
        ("1:1000 chain", |w| loaded_chain(w).nodes),
        ("taut string", |w| taut_string(w).nodes),
        ("stiff beads", |w| stiff_beads(w).nodes),
    ];
    for (name, build) in cases {
        let mut w = default_world();
        w.insert_resource(StabilityPolicy::Warn);
        let nodes = build(&mut w);
        let mut caught = None;
        for step in 1..=20 {
            w.step_physics();
            if step == 1 {
                assert_eq!(warnings(&w).len(), 1, "{name}: told");
            }
            let farthest = nodes
                .iter()
                .filter(|&&n| w.get::<Quarantined>(n).is_none())
                .map(|&n| common::x(&w, n).length())
                .fold(0.0f32, f32::max);
            assert!(
                farthest < 100.0,
                "{name}, step {step}: a live node at {farthest} m"
            );
            if caught.is_none() && nodes.iter().any(|&n| w.get::<Quarantined>(n).is_some()) {
                caught = Some(step);
            }
        }
        println!("{name}: explicit, caught at step {caught:?}");
        assert!(caught.is_some(), "{name}: never caught");
    }
}

#[test]
fn without_springs_the_implicit_dial_is_symplectic_euler_bit_for_bit() {
    // Backward Euler on forces that do not depend on the state is symplectic Euler's step:
    // a pile of boxes (gravity, contacts, rotation) runs identically under both dials.
    let run = |integrator: Integrator| {
        let mut w =
            scenes::world_with(1.0 / 60.0, 4, integrator, Vec3::new(0.0, -9.81, 0.0)).unwrap();
        scenes::ground(&mut w).unwrap();
        let boxes: Vec<Entity> = (0..6)
            .map(|i| {
                w.spawn((
                    RigidBody::Dynamic,
                    Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
                    Position::from(Vec3::new(0.05 * i as f32, 0.3 + 0.45 * i as f32, 0.0)),
                    AngularVelocity::from(Vec3::new(0.0, 0.0, 0.5 * i as f32)),
                ))
                .id()
            })
            .collect();
        for _ in 0..120 {
            w.step_physics();
        }
        boxes
            .iter()
            .map(|&b| {
                (
                    w.get::<Position>(b).unwrap().0,
                    w.get::<hooke::rigid::Rotation>(b).unwrap().0,
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(
        run(Integrator::SymplecticEuler),
        run(Integrator::ImplicitEuler)
    );
}
