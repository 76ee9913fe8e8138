//! Every integrator keeps resting contact: a ball resting on a static box and one rolling
//! down an incline, under each integrator of the dial, at 1 and 4 substeps. `Integrator::Rk4`
//! sank a resting ball through the box at one substep and 6 cm into it at four: its stages
//! ran after the contact solve, which had seen the start velocity without this substep's
//! gravity. RK4 bodies now kick and drift around the solve as symplectic Euler, and a body no
//! constraint touched takes RK4's step instead.

use crate::common;
use glam::{Quat, Vec3};
use hooke::prelude::*;

fn world(method: Integrator, substeps: u32) -> bevy_ecs::world::World {
    let mut w = common::awake_world(1.0 / 60.0, substeps, Vec3::new(0.0, -9.81, 0.0));
    *w.resource_mut::<Integrator>() = method;
    w
}

/// A 0.25 m ball set on a static box; its lowest and last height (m) over 3 s.
fn resting(method: Integrator, substeps: u32) -> (f32, f32) {
    let mut w = world(method, substeps);
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(2.0, 0.5, 2.0).unwrap(),
        Position::from(Vec3::new(0.0, -0.5, 0.0)),
    ));
    let ball = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.25).unwrap(),
            Position::from(Vec3::new(0.0, 0.25, 0.0)),
        ))
        .id();
    let mut lowest = f32::INFINITY;
    for _ in 0..180 {
        w.step_physics();
        lowest = lowest.min(common::x(&w, ball).y);
    }
    (lowest, common::x(&w, ball).y)
}

/// The same ball released on a 20° incline (μ = 0.6, rolls without slipping): how far along
/// the slope it went in 1.5 s, and its largest distance off the surface (m).
fn rolling(method: Integrator, substeps: u32) -> (f32, f32) {
    let theta = 20f32.to_radians();
    let normal = Vec3::new(theta.sin(), theta.cos(), 0.0);
    let down = Vec3::new(theta.cos(), -theta.sin(), 0.0);
    let mut w = world(method, substeps);
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(10.0, 0.5, 2.0).unwrap(),
        Friction(0.6),
        Position::from(-0.5 * normal),
        Rotation(Quat::from_rotation_z(-theta)),
    ));
    let ball = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.25).unwrap(),
            Friction(0.6),
            Position::from(0.25 * normal),
        ))
        .id();
    let mut off = 0.0f32;
    for _ in 0..90 {
        w.step_physics();
        off = off.max((common::x(&w, ball).dot(normal) - 0.25).abs());
    }
    (common::x(&w, ball).dot(down), off)
}

#[test]
fn a_ball_rests_on_a_box_under_every_integrator() {
    for method in Integrator::ALL {
        for substeps in [1, 4] {
            let (lowest, end) = resting(method, substeps);
            println!(
                "{:>16} x{substeps}: lowest {lowest:.4} m, after 3 s {end:.4} m (rest 0.25)",
                method.name()
            );
            // The soft contact holds a resting body within about g/(contact stiffness) of
            // the surface: 1.1 mm at one substep, 0.1 mm at four.
            assert!(
                lowest > 0.2485 && (end - 0.25).abs() < 2e-3,
                "{method:?} x{substeps}"
            );
        }
    }
}

#[test]
fn a_ball_rolls_down_an_incline_at_five_sevenths_of_g_sin_theta_under_every_integrator() {
    // Rolling without slip: a = (5/7) g sin θ, s = a t² / 2 = 2.695 m in 1.5 s.
    let closed = 0.5 * 5.0 / 7.0 * 9.81 * 20f32.to_radians().sin() * 1.5 * 1.5;
    for method in Integrator::ALL {
        for substeps in [1, 4] {
            let (s, off) = rolling(method, substeps);
            println!(
                "{:>16} x{substeps}: rolled {s:.4} m ({:+.2}% of {closed:.4}), at most {:.2} mm off the surface",
                method.name(),
                100.0 * (s / closed - 1.0),
                off * 1e3
            );
            assert!(
                (s / closed - 1.0).abs() < 0.02,
                "{method:?} x{substeps}: {s}"
            );
            assert!(off < 5e-3, "{method:?} x{substeps}: {off}");
        }
    }
}
