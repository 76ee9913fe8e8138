//! A plank bridge on hinges, a loop through the ground (each hinge locks the planks'
//! out-of-plane motion, so the two ends lock it twice): spawned in its equilibrium (the
//! discrete catenary) it stays there carrying the closed form's tension, kicked it swings
//! without running away, and a crate pushed across it reaches the far side.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{ChainBridge, ChainBridgeParts};

use crate::common::default_world;

/// The widest any hinge's anchors stood apart (m) and the fastest any plank moved (m/s)
/// over `seconds`, calling `each` before every step.
fn run(
    world: &mut World,
    parts: &ChainBridgeParts,
    seconds: f32,
    mut each: impl FnMut(&mut World),
) -> (f32, f32) {
    let (mut gap, mut fastest) = (0.0_f32, 0.0_f32);
    for _ in 0..(seconds * 60.0).round() as usize {
        each(world);
        world.step_physics();
        gap = gap.max(world.resource::<JointDiagnostics>().largest_gap);
        for &p in &parts.planks {
            assert!(
                world.get::<Quarantined>(p).is_none(),
                "a plank was quarantined"
            );
            fastest = fastest.max(world.get::<LinearVelocity>(p).unwrap().0.length());
        }
    }
    (gap, fastest)
}

#[test]
fn a_bridge_spawned_in_its_equilibrium_stays_there_with_the_closed_forms_tension() {
    // 16 planks (one system of 85 rows), 20 (105) and 24 (125), each sagging like the
    // default. The hinge at each end carries H horizontally and n W / 2 vertically.
    // And the 20-plank bridge at 30 Hz × 4 and 120 Hz × 2.
    let rates = super::frame_rates();
    let cases = [16, 20, 24]
        .map(|n| (n, rates[0]))
        .into_iter()
        .chain(rates[1..].iter().map(|&s| (20, s)));
    for (planks, (name, make)) in cases {
        println!("{name}:");
        let bridge = ChainBridge {
            planks,
            span: 0.49 * planks as f32,
        };
        let mut world = make();
        let parts = bridge.spawn(&mut world).unwrap();
        let (gap, fastest) = run(&mut world, &parts, 3.0, |_| {});
        let points = bridge.hinge_points();
        let lowest = world.get::<Position>(parts.planks[planks / 2]).unwrap().0;
        let expected = 0.5 * (points[planks / 2] + points[planks / 2 + 1]);
        let (h, v) = bridge.end_force();
        for end in [0, planks] {
            let f = world
                .get::<JointImpulse>(parts.hinges[end])
                .unwrap()
                .force();
            let (fx, fy) = (f.x.abs(), f.y.abs());
            println!("{planks}: end {end} force ({fx:.1}, {fy:.1}) against ({h:.1}, {v:.1})");
            assert!((fx - h).abs() < 0.01 * h && (fy - v).abs() < 0.01 * v);
        }
        println!(
            "{planks}: middle plank {:.2} mm off, gap {:.3} mm, fastest {:.2} mm/s",
            1e3 * (Vec3::from(lowest) - expected).length(),
            1e3 * gap,
            1e3 * fastest
        );
        assert!((Vec3::from(lowest) - expected).length() < 1e-3);
        assert!(gap < 1e-3, "anchors {gap} m apart");
        assert!(fastest < 1e-3, "a plank moved at {fastest} m/s");
    }
}

#[test]
fn a_kicked_bridge_swings_without_running_away() {
    // Before a row that repeats another (the second end's out-of-plane lock) was left out of
    // the joints' systems, a kick of 1 m/s ran away to planks at 20-70 m/s and joint forces
    // of meganewtons within seconds.
    for (planks, kick) in [(16, 1.0), (20, 1.0), (20, 5.0), (30, 1.0)] {
        let bridge = ChainBridge {
            planks,
            span: 0.49 * planks as f32,
        };
        let mut world = default_world();
        let parts = bridge.spawn(&mut world).unwrap();
        world
            .get_mut::<LinearVelocity>(parts.planks[planks / 4])
            .unwrap()
            .0
            .y = -kick;
        world
            .get_mut::<AngularVelocity>(parts.planks[planks / 4 + 1])
            .unwrap()
            .0
            .x = kick;
        let (gap, fastest) = run(&mut world, &parts, 8.0, |_| {});
        let (h, v) = bridge.end_force();
        let f = world.get::<JointImpulse>(parts.hinges[0]).unwrap().force();
        println!(
            "{planks} planks kicked at {kick}: gap {:.2} mm, fastest {fastest:.2} m/s, end force {:.0} N (rest: {:.0} N)",
            1e3 * gap,
            f.length(),
            h.hypot(v)
        );
        assert!(fastest < 1.5 * kick, "a plank ran at {fastest} m/s");
        assert!(gap < 0.01, "anchors {gap} m apart");
        assert!(f.length() < 2.0 * h.hypot(v), "the end hinge carries {f}");
    }
}

#[test]
fn a_crate_pushed_across_the_bridge_reaches_the_far_side() {
    let bridge = ChainBridge::default();
    let mut world = default_world();
    let parts = bridge.spawn(&mut world).unwrap();
    let crate_box = parts.crate_box;
    let far = 0.5 * bridge.span + 0.5;
    let mut lowest = f32::INFINITY;
    let mut arrived = None;
    let mut t = 0.0;
    let (gap, fastest) = run(&mut world, &parts, 18.0, |w| {
        let x = w.get::<Position>(crate_box).unwrap().0;
        // Walked across at 1 m/s, then held where it arrived.
        let speed = if arrived.is_none() { 1.0 } else { 0.0 };
        ChainBridge::push(w, crate_box, speed);
        lowest = lowest.min(x.y);
        if x.x > far && arrived.is_none() {
            arrived = Some(t);
        }
        t += 1.0 / 60.0;
    });
    let x = world.get::<Position>(crate_box).unwrap().0;
    println!(
        "crate at {x:?}, arrived at {arrived:?} s, lowest {lowest:.3} m (sag {:.3}), gap {:.2} mm, fastest plank {fastest:.2} m/s",
        bridge.sag(),
        1e3 * gap
    );
    assert!(arrived.is_some_and(|t| t < 16.0), "the crate got to {x}");
    assert!(x.x > far && x.y > 0.0, "the crate ended at {x}");
    assert!(lowest > -bridge.sag() - 0.5, "the crate fell to {lowest} m");
    assert!(gap < 0.01, "anchors {gap} m apart");
}
