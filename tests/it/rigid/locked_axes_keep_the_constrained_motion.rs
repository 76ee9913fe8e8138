//! `LockedAxes`: a locked axis takes no force, impulse, contact or joint, to the bit, and
//! what is left free moves as the closed form of the constrained body says: about a free
//! axis that is not a principal axis, a torque turns the body at τ / (e·I e) (the inverse of
//! the inertia restricted to the free axes, not the projected inverse e·I⁻¹e rapier and
//! avian use), for every integrator and substep count.

use crate::common;
use bevy_ecs::prelude::*;
use hooke::core::rest::SleepingDisabled;
use hooke::prelude::*;
use hooke::rigid::ExternalTorque;

const G: f32 = 9.81;

/// The world's tensor of an inertia diag(1, 2, 3) kg·m² whose principal frame is tilted, so
/// that world y is not one of its principal axes.
fn tilted_inertia() -> (Inertia, glam::Mat3) {
    let frame = Quat::from_rotation_x(0.6) * Quat::from_rotation_z(0.4);
    let inertia = Inertia::new(Vec3::new(1.0, 2.0, 3.0), frame).unwrap();
    (inertia, inertia.tensor())
}

fn spinner(world: &mut World, torque: Vec3) -> Entity {
    let (inertia, _) = tilted_inertia();
    world
        .spawn((
            RigidBody::Dynamic,
            Mass::new(2.0).unwrap(),
            inertia,
            Position::from(Vec3::ZERO),
            LockedAxes::new().lock_rotation_x().lock_rotation_z(),
            ExternalTorque(torque.into()),
        ))
        .id()
}

#[test]
fn locked_translations_take_no_gravity_force_or_impulse() {
    let mut w = common::default_world();
    let body = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Mass::new(1.0).unwrap(),
            Position::from(Vec3::new(0.0, 3.0, 0.0)),
            LockedAxes::new().lock_translation_y(),
            ExternalForce(Vec3::new(4.0, 7.0, 0.0)),
            ExternalImpulse(Vec3::new(0.0, 5.0, 3.0)),
        ))
        .id();
    let m = w.get::<Mass>(body).unwrap().value();
    for _ in 0..60 {
        w.step_physics();
    }
    let (x, v) = (common::x(&w, body), common::v(&w, body));
    assert_eq!(
        x.y, 3.0,
        "gravity, the force and the impulse move nothing along y"
    );
    assert_eq!(v.y, 0.0);
    assert!(
        (v.z - 3.0 / m).abs() < 1e-6,
        "the impulse's z share lands: {v}"
    );
    assert!(
        (v.x - 4.0 / m).abs() < 1e-5,
        "the force's x share: 1 s of 4 N: {v}"
    );
}

#[test]
fn a_torque_about_the_free_axis_turns_at_the_restricted_inertia() {
    let (_, tensor) = tilted_inertia();
    let i_yy = tensor.y_axis.y;
    let projected = tensor.inverse().y_axis.y;
    // Only the torque's y share acts; the reaction takes the rest.
    let torque = Vec3::new(2.0, 1.0, -3.0);
    let alpha = torque.y / i_yy;
    assert!(
        (alpha - torque.y * projected).abs() > 0.1 * alpha,
        "the two models differ here: {alpha} vs {}",
        torque.y * projected
    );
    for integrator in [
        Integrator::SymplecticEuler,
        Integrator::ExplicitEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
        Integrator::ImplicitEuler,
    ] {
        for substeps in [1, 4] {
            let dt = 1.0 / 60.0;
            let mut w = common::awake_world(dt, substeps, Vec3::ZERO);
            w.insert_resource(integrator);
            let body = spinner(&mut w, torque);
            for _ in 0..60 {
                w.step_physics();
            }
            let omega = w.get::<AngularVelocity>(body).unwrap().get();
            let label = format!("{integrator:?} × {substeps}");
            assert_eq!((omega.x, omega.z), (0.0, 0.0), "{label}: no spin off y");
            assert!(
                (omega.y - alpha).abs() < 1e-4 * alpha,
                "{label}: ω = {} after 1 s, closed form {alpha}",
                omega.y
            );
            // θ = ½ α t², within the integrators' first-order lag of ½ α h t.
            let q = w.get::<Rotation>(body).unwrap().0;
            let (axis, angle) = q.to_axis_angle();
            let h = dt / substeps as f32;
            assert!(
                (angle - 0.5 * alpha).abs() <= 0.5 * alpha * h + 1e-5,
                "{label}: turned {angle} rad, closed form {}",
                0.5 * alpha
            );
            assert!(axis.abs_diff_eq(Vec3::Y, 1e-6), "{label}: about y: {axis}");
        }
    }
}

#[test]
fn a_spin_about_the_free_axis_is_kept_and_a_spin_about_a_locked_one_dropped() {
    let mut w = common::awake_world(1.0 / 60.0, 4, Vec3::ZERO);
    let body = spinner(&mut w, Vec3::ZERO);
    w.entity_mut(body)
        .insert(AngularVelocity(Vec3A::new(0.5, 4.0, -0.3)));
    w.step_physics();
    let omega = w.get::<AngularVelocity>(body).unwrap().get();
    assert_eq!((omega.x, omega.z), (0.0, 0.0));
    assert!(
        (omega.y - 4.0).abs() < 1e-5,
        "the spin about y is kept: {omega}"
    );
    for _ in 0..599 {
        w.step_physics();
    }
    let omega = w.get::<AngularVelocity>(body).unwrap().get();
    assert!(
        (omega.y - 4.0).abs() < 1e-4,
        "10 s later, unchanged: {omega}"
    );
    let q = w.get::<Rotation>(body).unwrap().0;
    let expected = Quat::from_rotation_y(40.0);
    assert!(
        q.dot(expected).abs() > 1.0 - 1e-6,
        "turned 40 rad about y: {q} vs {expected}"
    );
}

/// A planar pile: the `pile_scene`'s boxes and balls (tilted, jittered, on a ramp) in three
/// rows along z, each body held to its xy-plane by `LockedAxes::XY_PLANE`, pushed along z by
/// a force the lock must cancel, spawned in `order`. The tilted boxes of neighbouring rows
/// overlap in depth, where the locks forbid the only way apart.
/// Returns each body with its plane's z and, for a ball, its radius.
fn planar_pile(order: usize) -> (World, Vec<(Entity, f32, Option<f32>)>) {
    let mut w = common::default_world();
    let (boxes, balls) = hooke::tools::scenes::pile_scene(&mut w, 24, 8).unwrap();
    let mut bodies: Vec<(Entity, Option<f32>)> = boxes
        .into_iter()
        .map(|e| (e, None))
        .chain(balls.into_iter().map(|e| (e, Some(0.3))))
        .collect();
    // Spawn order: the bodies are despawned and spawned again in another order.
    match order {
        1 => bodies.reverse(),
        2 => {
            let (even, odd): (Vec<_>, Vec<_>) =
                bodies.iter().enumerate().partition(|(i, _)| i % 2 == 0);
            bodies = odd.into_iter().chain(even).map(|(_, &b)| b).collect();
        }
        _ => {}
    }
    let mut out = Vec::new();
    for (e, ball) in bodies {
        let (x, q, c) = (
            w.get::<Position>(e).unwrap().get(),
            w.get::<Rotation>(e).unwrap().0,
            w.get::<Collider>(e).unwrap().clone(),
        );
        w.despawn(e);
        let e = w
            .spawn((
                RigidBody::Dynamic,
                c,
                Position::from(x),
                Rotation(q),
                LockedAxes::XY_PLANE,
                ExternalForce(Vec3::new(0.0, 0.0, 20.0)),
                LinearVelocity::from(Vec3::new(0.0, 0.0, -1.0)),
            ))
            .id();
        out.push((e, x.z, ball));
    }
    (w, out)
}

#[test]
fn a_planar_pile_stays_in_its_plane_and_settles_in_every_spawn_order() {
    for order in 0..3 {
        let (mut w, bodies) = planar_pile(order);
        let tilt: Vec<Quat> = bodies
            .iter()
            .map(|&(e, ..)| w.get::<Rotation>(e).unwrap().0)
            .collect();
        for _ in 0..600 {
            w.step_physics();
        }
        let mut fastest = 0.0f32;
        let mut slowest = None;
        for (&(e, z, ball), q0) in bodies.iter().zip(&tilt) {
            let r = w.entity(e);
            assert!(
                !r.contains::<Quarantined>(),
                "order {order}: {e} quarantined: {:?}",
                r.get::<Quarantined>()
            );
            let x = r.get::<Position>().unwrap().get();
            let v = r.get::<LinearVelocity>().unwrap().get();
            let omega = r.get::<AngularVelocity>().unwrap().get();
            assert_eq!(x.z, z, "order {order}: {e} left its plane");
            assert_eq!(v.z, 0.0, "order {order}: {e}");
            assert_eq!((omega.x, omega.y), (0.0, 0.0), "order {order}: {e} tips");
            // It turned about z alone: q q₀⁻¹ is a turn about z.
            let turn = r.get::<Rotation>().unwrap().0 * q0.inverse();
            assert!(
                turn.x.abs() < 1e-5 && turn.y.abs() < 1e-5,
                "order {order}: {e} turned {turn}"
            );
            assert!(x.is_finite() && x.y > -1.0, "order {order}: {e} at {x}");
            match ball {
                // A ball may still roll (nothing resists it), but without slipping.
                Some(r) => assert!(
                    (v.x + omega.z * r).abs() < 0.05 && v.y.abs() < 0.05,
                    "order {order}: ball {e} slips: v {v}, ω {omega}"
                ),
                None if v.length() > fastest => {
                    fastest = v.length();
                    slowest = Some((e, x, v, omega));
                }
                None => {}
            }
        }
        assert!(
            fastest < 0.05,
            "order {order}: the boxes settled, fastest {fastest} m/s ({slowest:?})"
        );
    }
}

#[test]
fn a_ball_locked_along_x_stops_a_head_on_hit_like_a_wall() {
    for locked_first in [true, false] {
        let mut w = common::awake_world(1.0 / 60.0, 4, Vec3::ZERO);
        let locked = |w: &mut World| {
            w.spawn((
                RigidBody::Dynamic,
                Collider::ball(0.5).unwrap(),
                Position::from(Vec3::ZERO),
                LockedAxes::new().lock_translation_x(),
            ))
            .id()
        };
        let moving = |w: &mut World| {
            w.spawn((
                RigidBody::Dynamic,
                Collider::ball(0.5).unwrap(),
                Position::from(Vec3::new(3.0, 0.0, 0.0)),
                LinearVelocity::from(Vec3::new(-2.0, 0.0, 0.0)),
            ))
            .id()
        };
        let (a, b) = if locked_first {
            let a = locked(&mut w);
            (a, moving(&mut w))
        } else {
            let b = moving(&mut w);
            (locked(&mut w), b)
        };
        for _ in 0..120 {
            w.step_physics();
        }
        let (xa, va, vb) = (common::x(&w, a), common::v(&w, a), common::v(&w, b));
        assert_eq!(xa.x, 0.0, "the locked ball never moved along x");
        assert!(
            va.length() < 1e-6,
            "nor any other way (the push is along x): {va}"
        );
        // Restitution 0: the mover stops at the wall, as against a static body.
        assert!(vb.length() < 1e-3, "locked first {locked_first}: {vb}");
        assert!(common::x(&w, b).x > 0.99, "and rests against it");
    }
}

#[test]
fn an_oblique_hit_moves_a_locked_ball_as_the_closed_form_says() {
    // Frictionless equal balls (r = 0.5 m), e = 1: B at 2 m/s along −x meets A, locked
    // along x, with its centre 0.6 m higher, so at contact n = (0.8, 0.6, 0) from A to B.
    // B starts a millimetre short of the touch, so that the contact's normal is the one of
    // the closed form (a normal found a step before the touch leans by up to a step's travel).
    // A takes the impulse only along y: J = (1 + e) u / (1/m + n_y²/m), u = 1.6 m/s, and
    // the kinetic energy is kept.
    for locked_first in [true, false] {
        let mut w = common::awake_world(1.0 / 60.0, 4, Vec3::ZERO);
        let ball = |w: &mut World, x: Vec3, v: Vec3, locks: LockedAxes| {
            w.spawn((
                RigidBody::Dynamic,
                Collider::ball(0.5).unwrap(),
                Position::from(x),
                LinearVelocity::from(v),
                Restitution(1.0),
                Friction(0.0),
                locks,
            ))
            .id()
        };
        let locked = LockedAxes::new().lock_translation_x();
        let (a, b) = if locked_first {
            let a = ball(&mut w, Vec3::ZERO, Vec3::ZERO, locked);
            (
                a,
                ball(
                    &mut w,
                    Vec3::new(0.8008, 0.6006, 0.0),
                    Vec3::new(-2.0, 0.0, 0.0),
                    LockedAxes::NONE,
                ),
            )
        } else {
            let b = ball(
                &mut w,
                Vec3::new(0.8008, 0.6006, 0.0),
                Vec3::new(-2.0, 0.0, 0.0),
                LockedAxes::NONE,
            );
            (ball(&mut w, Vec3::ZERO, Vec3::ZERO, locked), b)
        };
        for _ in 0..120 {
            w.step_physics();
        }
        let (n, u) = (Vec3::new(0.8, 0.6, 0.0), 1.6f32);
        let j = 2.0 * u / (1.0 + n.y * n.y); // per unit mass
        let (va, vb) = (common::v(&w, a), common::v(&w, b));
        let (want_a, want_b) = (
            Vec3::new(0.0, -j * n.y, 0.0),
            Vec3::new(-2.0, 0.0, 0.0) + j * n,
        );
        assert_eq!(
            (common::x(&w, a).x, va.x),
            (0.0, 0.0),
            "locked first {locked_first}"
        );
        assert!(
            (va - want_a).length() < 0.02 * 2.0 && (vb - want_b).length() < 0.02 * 2.0,
            "locked first {locked_first}: A {va} (closed form {want_a}), B {vb} ({want_b})"
        );
        let energy = va.length_squared() + vb.length_squared();
        assert!(
            energy <= 4.0 * (1.0 + 1e-4) && energy > 4.0 * 0.98,
            "locked first {locked_first}: 2 v² = {energy}, was 4"
        );
    }
}

#[test]
fn a_ball_jointed_planar_pendulum_swings_at_the_closed_form_period() {
    // A rod (0.1 × 1.0 × 0.1 m) on a ball joint at its top: a 3D pendulum that `XY_PLANE`
    // holds to a planar one. The joint's z row is one the lock makes vacuous.
    let mut w = common::default_world();
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let swing = 0.1f32;
    let turn = Quat::from_rotation_z(swing);
    let rod = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.05, 0.5, 0.05).unwrap(),
            Position::from(pivot + turn * Vec3::new(0.0, -0.5, 0.0)),
            Rotation(turn),
            LockedAxes::XY_PLANE,
            SleepingDisabled,
        ))
        .id();
    w.spawn(SphericalJoint::to_world(rod).with_anchors(pivot, Vec3::new(0.0, 0.5, 0.0)));
    // T = 2π √(I_pivot / (m g d)), I_pivot = m (a² + b²)/12 + m d², d = 0.5 m; the amplitude
    // lengthens it by θ₀²/16.
    let (a, b, d) = (0.1f32, 1.0f32, 0.5f32);
    let i_over_m = (a * a + b * b) / 12.0 + d * d;
    let period = std::f32::consts::TAU * (i_over_m / (G * d)).sqrt() * (1.0 + swing * swing / 16.0);
    let angle = |w: &World| {
        let down = w.get::<Rotation>(rod).unwrap().0 * Vec3::NEG_Y;
        down.x.atan2(-down.y)
    };
    let dt = 1.0 / 60.0;
    let (mut last, mut crossings) = (angle(&w), Vec::new());
    for step in 1..=600 {
        w.step_physics();
        let now = angle(&w);
        if last > 0.0 && now <= 0.0 {
            // Linear interpolation of the downward zero crossing.
            crossings.push(dt * (step as f32 - 1.0 + last / (last - now)));
        }
        last = now;
        assert_eq!(common::x(&w, rod).z, 0.0, "step {step}: out of the plane");
    }
    assert!(crossings.len() >= 5, "{crossings:?}");
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32;
    assert!(
        (measured - period).abs() < 0.01 * period,
        "period {measured} s, closed form {period} s"
    );
    // Still swinging at nearly its amplitude after 10 s: no damping bought the stability.
    let peak = (0..60)
        .map(|_| {
            w.step_physics();
            angle(&w).abs()
        })
        .fold(0.0f32, f32::max);
    assert!(
        peak > 0.95 * swing,
        "amplitude after 10 s: {peak} rad of {swing}"
    );
}

#[test]
fn removing_the_locks_frees_the_body() {
    let mut w = common::default_world();
    let body = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Position::from(Vec3::new(0.0, 5.0, 0.0)),
            LockedAxes::ALL_LOCKED,
            ExternalTorque(Vec3A::new(100.0, 100.0, 100.0)),
        ))
        .id();
    for _ in 0..30 {
        w.step_physics();
    }
    assert_eq!(common::x(&w, body), Vec3::new(0.0, 5.0, 0.0));
    assert_eq!(w.get::<Rotation>(body).unwrap().0, Quat::IDENTITY);
    w.entity_mut(body).remove::<LockedAxes>();
    for _ in 0..30 {
        w.step_physics();
    }
    let v = common::v(&w, body);
    assert!(
        (v.y + G * 0.5).abs() < 0.05,
        "falls freely once unlocked: {v}"
    );
    assert!(w.get::<AngularVelocity>(body).unwrap().get().length() > 0.01);
}
