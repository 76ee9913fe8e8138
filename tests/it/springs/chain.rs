//! Ropes a game can build (`ChainBuilder`): a load hung at the end, both ends pinned,
//! pre-tension; springs read out their length, strain and tension (`Spring::reading`,
//! `SpringNetwork::reading`), against closed forms.

use crate::common;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::particles::LinearDamping;
use hooke::prelude::*;
use hooke::springs::ChainBuilder;
use hooke::springs::Spring;

fn world() -> World {
    common::default_world()
}

#[test]
fn a_hanging_chain_with_a_load_has_each_spring_carry_the_weight_below_it() {
    let mut w = world();
    let (count, load) = (11usize, 1.0f32);
    let chain = ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 1.0, 0.0), count)
        .stiffness(2000.0)
        .end_load(load)
        .spawn(&mut w)
        .unwrap();
    for &n in &chain.nodes[1..] {
        w.entity_mut(n).insert(LinearDamping(3.0));
    }
    assert_eq!(
        w.get::<Mass>(chain.nodes[count - 1]).unwrap().value(),
        0.1 + load
    );
    for _ in 0..600 {
        w.step_physics();
    }
    let mut worst = 0.0f32;
    for (i, &s) in chain.springs.iter().enumerate() {
        let reading = w.get::<Spring>(s).unwrap().reading(&w).unwrap();
        // Spring i holds nodes i+1 .. count−1: (count − 2 − i) plain nodes and the loaded end.
        let below = ((count - 2 - i) as f32 * 0.1 + 0.1 + load) * 9.81;
        worst = worst.max((reading.tension / below - 1.0).abs());
        assert!((reading.strain - reading.tension / (2000.0 * 0.1)).abs() < 1e-3);
    }
    let top = w
        .get::<Spring>(chain.springs[0])
        .unwrap()
        .reading(&w)
        .unwrap();
    println!(
        "top spring {:.2} N (closed form {:.2} N), stretched to {:.4} m; worst tension error {:.3}%",
        top.tension,
        (0.1 * 9.0 + 0.1 + load) * 9.81,
        top.length,
        100.0 * worst
    );
    assert!(worst < 0.01, "{worst}");
}

#[test]
fn a_rope_pinned_at_both_ends_and_pre_tensioned_holds_its_tension() {
    let mut w = world();
    w.insert_resource(hooke::particles::Gravity::new(Vec3::ZERO).unwrap());
    let (k, scale) = (500.0f32, 0.9f32);
    let chain = ChainBuilder::rope(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), 9)
        .stiffness(k)
        .pin_end(true)
        .rest_scale(scale)
        .spawn(&mut w)
        .unwrap();
    assert!(w.get::<Mass>(chain.nodes[8]).unwrap().is_pinned());
    for _ in 0..120 {
        w.step_physics();
    }
    // Each segment is 0.25 m long with rest 0.225 m: tension k · 0.025 = 12.5 N.
    for &s in &chain.springs {
        let r = w.get::<Spring>(s).unwrap().reading(&w).unwrap();
        assert!((r.tension - k * 0.25 * (1.0 - scale)).abs() < 1e-2, "{r:?}");
        assert!((r.strain - (1.0 / scale - 1.0)).abs() < 1e-4, "{r:?}");
    }
    assert!(matches!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 3)
            .rest_scale(0.0)
            .spawn(&mut w),
        Err(hooke::Error::NotPositive { .. })
    ));
    assert!(matches!(
        ChainBuilder::rope(Vec3::ZERO, Vec3::X, 3)
            .end_load(-1.0)
            .spawn(&mut w),
        Err(hooke::Error::Negative { .. })
    ));
}

#[test]
fn a_spring_network_reads_out_each_spring() {
    let mut nodes = Nodes::new();
    nodes.push(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap();
    nodes
        .push(Vec3::new(1.5, 0.0, 0.0), Vec3::ZERO, 1.0)
        .unwrap();
    nodes
        .push(Vec3::new(1.5, 0.0, 0.0), Vec3::ZERO, 1.0)
        .unwrap();
    let mut net = SpringNetwork::new();
    net.push(0, 1, 1.0, 10.0, 0.0).unwrap();
    net.push(1, 2, 0.0, 10.0, 0.0).unwrap();
    let r = net.reading(0, &nodes).unwrap();
    assert_eq!((r.length, r.strain, r.tension), (1.5, 0.5, 5.0));
    // A zero-length spring whose ends coincide: no strain, no tension, no NaN.
    let r = net.reading(1, &nodes).unwrap();
    assert_eq!((r.length, r.strain, r.tension), (0.0, 0.0, 0.0));
    assert!(net.reading(2, &nodes).is_none());
}

/// A rope of rest length L = 2.5 m strung between pins 2 m apart hangs on the catenary
/// y = a cosh(x/a), with L = 2a sinh(S/2a): sag a (cosh(S/2a) − 1) and support tension
/// w a cosh(S/2a) (w the weight per length). Springs stiff enough to stretch < 0.5 %, at the
/// substeps the stability warning asks for.
#[test]
fn a_rope_between_two_pins_hangs_on_the_catenary() {
    let (span, length, count, node_kg, k) = (2.0f32, 2.5f32, 41usize, 0.05f32, 1e5f32);
    let build = || {
        ChainBuilder::rope(Vec3::new(-1.0, 3.0, 0.0), Vec3::new(1.0, 3.0, 0.0), count)
            .node_mass(node_kg)
            .stiffness(k)
            .damping(0.0)
            .pin_end(true)
            .rest_scale(length / span)
    };
    // Ask for the substeps.
    let mut probe = world();
    build().spawn(&mut probe).unwrap();
    probe.step_physics();
    let needed = {
        let m =
            probe.resource::<bevy_ecs::message::Messages<hooke::integrator::StabilityWarning>>();
        m.get_cursor().read(m).next().unwrap().substeps_needed
    };
    let mut w = hooke::tools::scenes::world_with(
        1.0 / 60.0,
        needed,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap();
    let chain = build().spawn(&mut w).unwrap();
    for &n in &chain.nodes {
        w.entity_mut(n).insert(LinearDamping(2.0));
    }
    for _ in 0..900 {
        w.step_physics();
    }
    let lowest = chain
        .nodes
        .iter()
        .map(|&n| w.get::<Position>(n).unwrap().0.y)
        .fold(f32::INFINITY, f32::min);
    let sag = 3.0 - lowest;
    let a = hooke::tools::scenes::catenary_parameter(f64::from(span), f64::from(length));
    let c = (f64::from(span) / (2.0 * a)).cosh();
    let closed_sag = (a * (c - 1.0)) as f32;
    // The pinned ends carry half a node's weight each less than the rope's: w per rest length.
    let w_per_m = f64::from(node_kg) * 9.81 * (count - 2) as f64 / f64::from(length);
    let closed_tension = (w_per_m * a * c) as f32;
    let support = w
        .get::<Spring>(chain.springs[0])
        .unwrap()
        .reading(&w)
        .unwrap();
    let strain = chain
        .springs
        .iter()
        .map(|&s| w.get::<Spring>(s).unwrap().reading(&w).unwrap().strain)
        .fold(0.0f32, f32::max);
    println!(
        "{needed} substeps; sag {sag:.4} m (catenary {closed_sag:.4}), support tension {:.2} N (catenary {closed_tension:.2}), largest strain {:.2}%",
        support.tension,
        100.0 * strain
    );
    assert!(strain < 5e-3);
    assert!(
        (sag / closed_sag - 1.0).abs() < 0.02,
        "{sag} vs {closed_sag}"
    );
    assert!(
        (support.tension / closed_tension - 1.0).abs() < 0.03,
        "{} vs {closed_tension}",
        support.tension
    );
}

/// A taut string (tension T, mass per length μ) carries transverse waves at c = √(T/μ): a
/// Gaussian pulse launched rightwards travels at c within 2 %.
#[test]
fn a_taut_strings_transverse_waves_travel_at_the_square_root_of_tension_over_density() {
    let (count, seg, node_kg, k) = (401usize, 0.01f32, 0.001f32, 2000.0f32);
    let rest = 0.9 * seg;
    let tension = k * (seg - rest); // 2 N
    let mu = node_kg / seg; // 0.1 kg/m
    let c = (tension / mu).sqrt(); // 4.47 m/s
    let pulse = |x: f32| 0.01 * (-((x - 1.0) / 0.1).powi(2)).exp();
    let slope = |x: f32| pulse(x) * (-2.0 * (x - 1.0) / 0.01);
    let mut nodes = Nodes::new();
    for i in 0..count {
        let x = seg * i as f32;
        if i == 0 || i + 1 == count {
            nodes.push_pinned(Vec3::new(x, 0.0, 0.0)).unwrap();
        } else {
            // Moving right: y(x − c t), so ẏ = −c y'.
            nodes
                .push(
                    Vec3::new(x, pulse(x), 0.0),
                    Vec3::new(0.0, -c * slope(x), 0.0),
                    node_kg,
                )
                .unwrap();
        }
    }
    let mut net = SpringNetwork::new();
    for i in 0..count - 1 {
        net.push(i, i + 1, rest, k, 0.0).unwrap();
    }
    let limit = net.critical_step(&nodes);
    let substeps = ((1.0 / 60.0) / (0.5 * limit)).ceil() as u32;
    let mut w = hooke::tools::scenes::world_with(
        1.0 / 60.0,
        substeps,
        Integrator::SymplecticEuler,
        Vec3::ZERO,
    )
    .unwrap();
    let e = w.spawn((nodes, net)).id();
    let peak_x = |w: &World| {
        let n = w.get::<Nodes>(e).unwrap();
        let (i, _) = n
            .positions()
            .iter()
            .enumerate()
            .fold(
                (0, f32::MIN),
                |(bi, by), (i, p)| if p.y > by { (i, p.y) } else { (bi, by) },
            );
        n.positions()[i].x
    };
    let x0 = peak_x(&w);
    let steps = 30; // 0.5 s: the pulse moves about 2.2 m, short of the far end at 4 m
    for _ in 0..steps {
        w.step_physics();
    }
    let speed = (peak_x(&w) - x0) / (steps as f32 / 60.0);
    println!("pulse speed {speed:.3} m/s, √(T/μ) = {c:.3} m/s ({substeps} substeps)");
    assert!((speed / c - 1.0).abs() < 0.02, "{speed} vs {c}");
}

/// A slack rope with `node_radius` drapes over a bar instead of sagging through it: pinned
/// at both ends 0.3 m above a static bar, its nodes over the bar rest on the bar's top;
/// without a radius they sag through; a radius of half the spacing is a typed error.
#[test]
fn a_rope_with_a_node_radius_drapes_over_a_bar() {
    let mut w = world();
    let bar = w
        .spawn((
            RigidBody::Static,
            Collider::cuboid(0.1, 0.1, 1.0).unwrap(),
            Position::from(Vec3::new(0.0, 0.0, 0.0)),
        ))
        .id();
    let build = |r: f32| {
        ChainBuilder::rope(Vec3::new(-1.0, 0.3, 0.0), Vec3::new(1.0, 0.3, 0.0), 21)
            .stiffness(500.0)
            .pin_end(true)
            .rest_scale(1.3)
            .node_radius(r)
    };
    let rope = build(0.04).spawn(&mut w).unwrap();
    for _ in 0..300 {
        w.step_physics();
    }
    let top = 0.1;
    for &n in &rope.nodes {
        let x = w.get::<Position>(n).unwrap().get();
        assert!(x.is_finite());
        if x.x.abs() < 0.1 {
            assert!(x.y > top + 0.03, "node over the bar sank to {x}");
        }
    }
    let _ = bar;
    let without = ChainBuilder::rope(Vec3::new(-1.0, 0.3, 5.0), Vec3::new(1.0, 0.3, 5.0), 21)
        .stiffness(500.0)
        .pin_end(true)
        .rest_scale(1.3)
        .spawn(&mut w)
        .unwrap();
    for _ in 0..300 {
        w.step_physics();
    }
    let lowest_over_bar = without
        .nodes
        .iter()
        .map(|&n| w.get::<Position>(n).unwrap().get())
        .filter(|x| x.x.abs() < 0.1)
        .map(|x| x.y)
        .fold(f32::MAX, f32::min);
    assert!(
        lowest_over_bar < top - 0.1,
        "without a radius it sags through: {lowest_over_bar}"
    );
    assert!(matches!(
        build(0.05).spawn(&mut w),
        Err(Error::OutOfRange {
            what: "chain node radius",
            ..
        })
    ));
}
