//! Particles and tracers against closed forms.

use crate::common;

use common::*;
use hooke::prelude::*;
use hooke::tools::scenes;

const G: f32 = 9.81;

#[test]
fn symplectic_free_fall_error_is_exactly_g_h_t_over_2() {
    let h = 1.0f32 / 60.0;
    let mut world =
        scenes::world_with(h, 1, Integrator::SymplecticEuler, Vec3::new(0.0, -G, 0.0)).unwrap();
    let ball = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap())
        .id();
    for _ in 0..120 {
        world.step_physics();
    }
    let t = 2.0f64;
    let (g, h) = (f64::from(G), f64::from(h));
    let exact = -0.5 * g * t * t;
    let err = f64::from(x(&world, ball).y) - exact;
    println!(
        "free fall after 2 s: error {err:.6} m, g h t / 2 = {:.6} m",
        g * h * t / 2.0
    );
    assert!((err + g * h * t / 2.0).abs() < 1e-4, "error {err}");
    assert!((f64::from(v(&world, ball).y) + g * t).abs() < 1e-4);
}

#[test]
fn projectile_range_flight_time_and_apex() {
    // v0 = 10 m/s at 45°: range v0²/g = 10.194 m, time 2 v0 sin45/g = 1.4416 s,
    // apex (v0 sin45)²/(2g) = 2.548 m. Velocity Verlet is exact for constant acceleration.
    let h = 1.0f32 / 1000.0;
    let mut world =
        scenes::world_with(h, 1, Integrator::VelocityVerlet, Vec3::new(0.0, -G, 0.0)).unwrap();
    let s = std::f32::consts::FRAC_1_SQRT_2 * 10.0;
    let ball = world
        .spawn(ParticleBundle::new(Vec3::ZERO, Vec3::new(s, s, 0.0), 0.2).unwrap())
        .id();
    let (mut apex, mut prev, mut t) = (0.0f32, Vec3::ZERO, 0.0f32);
    loop {
        world.step_physics();
        t += h;
        let now = x(&world, ball);
        apex = apex.max(now.y);
        if now.y < 0.0 {
            // Linear interpolation of the crossing.
            let f = prev.y / (prev.y - now.y);
            let t_land = t - h + f * h;
            let range = prev.x + f * (now.x - prev.x);
            println!("projectile: range {range:.4} m, flight {t_land:.4} s, apex {apex:.4} m");
            assert!((range - 10.194).abs() < 2e-3, "range {range}");
            assert!((t_land - 1.4416).abs() < 2e-4, "time {t_land}");
            assert!((apex - 2.548).abs() < 1e-3, "apex {apex}");
            break;
        }
        prev = now;
        assert!(t < 2.0);
    }
}

fn vortex_radius_after(advection: Advection, steps: usize) -> f32 {
    let mut world =
        scenes::world_with(1.0 / 60.0, 1, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    world.insert_resource(advection);
    world.spawn(VelocityField::vortex(Vec3::ZERO, Vec3::Z, 2.0).unwrap());
    let tracer = world
        .spawn((Position::from(Vec3::new(1.0, 0.0, 0.0)), Tracer))
        .id();
    for _ in 0..steps {
        world.step_physics();
    }
    x(&world, tracer).truncate().length()
}

#[test]
fn vortex_tracer_keeps_radius_with_rk4_and_spirals_out_with_euler() {
    let steps = 600;
    let euler = vortex_radius_after(Advection::Euler, steps);
    let midpoint = vortex_radius_after(Advection::Midpoint, steps);
    let rk4 = vortex_radius_after(Advection::Rk4, steps);
    // Euler multiplies the radius by √(1 + (ωh)²) per step.
    let wh = 2.0f64 / 60.0;
    let expected = (1.0 + wh * wh).powf(steps as f64 / 2.0) as f32;
    println!(
        "vortex r after 10 s: euler {euler:.5} (closed form {expected:.5}), midpoint {midpoint:.6}, rk4 {rk4:.7}"
    );
    assert!(
        (euler / expected - 1.0).abs() < 1e-4,
        "{euler} vs {expected}"
    );
    assert!((rk4 - 1.0).abs() < 1e-5, "rk4 radius {rk4}");
    assert!((midpoint - 1.0).abs() < 1e-3 && (midpoint - 1.0).abs() > (rk4 - 1.0).abs());
}

#[test]
fn tracers_feel_the_sum_of_fields_and_custom_fields_see_time() {
    let mut world = scenes::world_with(0.1, 1, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    world.spawn(VelocityField::uniform(Vec3::X).unwrap());
    world.spawn(VelocityField::custom(|_, t| Vec3::new(0.0, t, 0.0)));
    let tracer = world.spawn((Position::from(Vec3::ZERO), Tracer)).id();
    world.insert_resource(Advection::Rk4);
    for _ in 0..10 {
        world.step_physics();
    }
    // x = t, y = t²/2 at t = 1 (RK4 is exact for these polynomials).
    let p = x(&world, tracer);
    assert!((p.x - 1.0).abs() < 1e-5 && (p.y - 0.5).abs() < 1e-5, "{p}");
}

#[test]
fn external_force_persists_and_is_never_wiped() {
    let mut world = scenes::world_with(0.01, 1, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    let e = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 2.0).unwrap(),
            ExternalForce(Vec3::new(10.0, 0.0, 0.0)),
        ))
        .id();
    for _ in 0..100 {
        world.step_physics();
    }
    // a = F/m = 5 m/s² for 1 s.
    assert!((v(&world, e).x - 5.0).abs() < 1e-4);
    assert_eq!(
        world.get::<ExternalForce>(e).unwrap().0,
        Vec3::new(10.0, 0.0, 0.0)
    );
    assert_eq!(world.get::<Force>(e).unwrap().0, Vec3A::new(10.0, 0.0, 0.0));
}

#[test]
fn impulse_applies_once_then_resets() {
    let mut world = scenes::world_with(0.01, 2, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    let e = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 2.0).unwrap(),
            ExternalImpulse(Vec3::new(2.0, 0.0, 0.0)),
        ))
        .id();
    world.step_physics();
    assert_eq!(v(&world, e).x, 1.0);
    assert_eq!(world.get::<ExternalImpulse>(e).unwrap().0, Vec3::ZERO);
    world.step_physics();
    assert_eq!(v(&world, e).x, 1.0);
    world.get_mut::<ExternalImpulse>(e).unwrap().0 = Vec3::new(-2.0, 0.0, 0.0);
    world.step_physics();
    assert_eq!(v(&world, e).x, 0.0);
}

#[test]
fn gravity_scale_and_pinned_bodies() {
    let mut world = scenes::world_with(
        0.01,
        1,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -G, 0.0),
    )
    .unwrap();
    let floating = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap(),
            GravityScale(0.0),
        ))
        .id();
    let double = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap(),
            GravityScale(2.0),
        ))
        .id();
    let pinned = world.spawn(ParticleBundle::pinned(Vec3::ONE).unwrap()).id();
    let kinematic = world
        .spawn((
            ParticleBundle::pinned(Vec3::ZERO).unwrap(),
            ExternalForce(Vec3::X),
        ))
        .id();
    world.get_mut::<LinearVelocity>(kinematic).unwrap().0 = Vec3::X.into();
    for _ in 0..100 {
        world.step_physics();
    }
    assert_eq!(x(&world, floating), Vec3::ZERO);
    assert!((v(&world, double).y + 2.0 * G).abs() < 1e-3);
    assert_eq!(x(&world, pinned), Vec3::ONE);
    // A pinned body keeps the velocity it was given, whatever the forces.
    assert_eq!(v(&world, kinematic), Vec3::X);
    assert!((x(&world, kinematic).x - 1.0).abs() < 1e-5);
}

#[test]
fn linear_damping_decays_velocity_exponentially() {
    let mut world = scenes::world_with(1.0 / 1000.0, 1, Integrator::Rk4, Vec3::ZERO).unwrap();
    let e = world
        .spawn((
            ParticleBundle::new(Vec3::ZERO, Vec3::X, 3.0).unwrap(),
            LinearDamping(0.5),
        ))
        .id();
    for _ in 0..2000 {
        world.step_physics();
    }
    let expected = (-1.0f32).exp(); // e^(−c t), c = 0.5, t = 2
    assert!(
        (v(&world, e).x - expected).abs() < 1e-5,
        "{}",
        v(&world, e).x
    );
}

#[test]
fn advance_runs_whole_steps_and_caps_slow_frames() {
    let mut world = scenes::world_with(0.01, 1, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    let r = world.advance_physics(0.035).unwrap();
    assert_eq!(r.steps, 3);
    assert_eq!(world.resource::<PhysicsTime>().steps(), 3);
    let r = world.advance_physics(10.0).unwrap();
    assert_eq!(r.steps, 4);
    assert!(r.dropped > 9.9);
    assert!(world.advance_physics(f32::NAN).is_err());
    assert!(world.advance_physics(-1.0).is_err());
    assert_eq!(world.resource::<PhysicsTime>().steps(), 7);
}
