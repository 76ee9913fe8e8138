//! Regression: a body hitting a sleeping one woke it only at the next step, so for the step
//! of impact the sleeper stood like a static wall. A ball fired at a sleeping box stopped
//! dead and the box never moved: the momentum was lost.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::rest::Sleeping;
use hooke::prelude::*;
use hooke::tools::scenes;

use crate::common;

#[test]
fn a_ball_fired_at_a_sleeping_box_hands_over_its_momentum_in_the_step_of_impact() {
    let mut w = common::gravity_world(4);
    let ground = scenes::ground(&mut w).unwrap();
    let target = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    let ball = scenes::dynamic_ball(&mut w, 0.5, Vec3::new(-3.0, 0.5, 0.0)).unwrap();
    // Frictionless, perfectly inelastic: the closed form is one common velocity.
    for e in [ground, target, ball] {
        w.entity_mut(e).insert((Friction(0.0), Restitution(0.0)));
    }
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(w.get::<Sleeping>(target).is_some(), "the box never slept");
    let mass = |w: &World, e: Entity| 1.0 / w.get::<Mass>(e).unwrap().inverse();
    let (m_ball, m_box) = (mass(&w, ball), mass(&w, target));
    let v0 = 5.0;
    w.get_mut::<LinearVelocity>(ball).unwrap().0 = glam::Vec3A::new(v0, 0.0, 0.0);
    let p0 = m_ball * v0;
    let momentum = |w: &World| {
        m_ball * w.get::<LinearVelocity>(ball).unwrap().get().x
            + m_box * w.get::<LinearVelocity>(target).unwrap().get().x
    };
    let mut impact = None;
    for step in 0..60 {
        w.step_physics();
        let v_ball = w.get::<LinearVelocity>(ball).unwrap().get().x;
        if impact.is_none() && v_ball < 0.99 * v0 {
            impact = Some(step);
            let p = momentum(&w);
            println!("impact step {step}: momentum {p:.2} of {p0:.2} N·s");
            assert!(
                (p - p0).abs() < 0.02 * p0,
                "momentum lost in the step of impact: {p} of {p0}"
            );
        }
    }
    assert!(impact.is_some(), "the ball never reached the box");
    // v = m_ball v0 / (m_ball + m_box) for both.
    let v = p0 / (m_ball + m_box);
    let v_box = w.get::<LinearVelocity>(target).unwrap().get().x;
    println!("box leaves at {v_box:.4} m/s (closed form {v:.4})");
    assert!((v_box - v).abs() < 0.03 * v, "{v_box} vs {v}");
}

#[test]
fn the_whole_island_wakes_in_the_step_of_impact_and_keeps_its_support() {
    let mut w = common::gravity_world(4);
    scenes::ground(&mut w).unwrap();
    let bottom = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    let top = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 1.5, 0.0)).unwrap();
    let ball = scenes::dynamic_ball(&mut w, 0.25, Vec3::new(-3.0, 0.25, 0.0)).unwrap();
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(w.get::<Sleeping>(top).is_some() && w.get::<Sleeping>(bottom).is_some());
    let top_y = w.get::<Position>(top).unwrap().get().y;
    w.get_mut::<LinearVelocity>(ball).unwrap().0 = glam::Vec3A::new(6.0, 0.0, 0.0);
    let mut hit = false;
    let mut lowest = top_y;
    for _ in 0..40 {
        w.step_physics();
        let moved = w.get::<LinearVelocity>(bottom).unwrap().get().length() > 0.0;
        if moved && !hit {
            hit = true;
            assert!(
                w.get::<Sleeping>(top).is_none(),
                "the top box slept on while the box under it was hit"
            );
            // The woken pair's contact holds from the first step: without it the top box
            // would fall freely for a step, at g·dt = 0.16 m/s.
            let vy = w.get::<LinearVelocity>(top).unwrap().get().y;
            println!("top box vertical velocity in the step of impact: {vy:.4} m/s");
            assert!(
                vy > -0.02,
                "the top box fell through its woken support: {vy}"
            );
        }
        lowest = lowest.min(w.get::<Position>(top).unwrap().get().y);
    }
    assert!(hit, "the ball never reached the stack");
    println!(
        "top box moved down {:.2} mm after the hit",
        (top_y - lowest) * 1e3
    );
    assert!(
        top_y - lowest < 0.01,
        "top box sank to {lowest} from {top_y}"
    );
}
