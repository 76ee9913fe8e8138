//! The integrator dial against closed forms (DESIGN.md, "Validation cases").

use crate::common;

use common::*;
use hooke::prelude::*;

/// Max and final energy ratio over 10 periods at h = 1/60.
fn energy_over_ten_periods(integrator: Integrator) -> (f64, f64, f64) {
    let (mut world, body) = oscillator(1.0 / 60.0, integrator, 0.0);
    let e0 = oscillator_energy(&world, body);
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    for _ in 0..600 {
        world.step_physics();
        let r = oscillator_energy(&world, body) / e0;
        lo = lo.min(r);
        hi = hi.max(r);
    }
    (lo, hi, oscillator_energy(&world, body) / e0)
}

#[test]
fn explicit_euler_energy_grows_by_the_closed_form_factor() {
    let (_, _, end) = energy_over_ten_periods(Integrator::ExplicitEuler);
    // Each step multiplies the energy by exactly 1 + ω²h²: 600 steps give ×695.
    let w_h = std::f64::consts::TAU / 60.0;
    let expected = (1.0 + w_h * w_h).powi(600);
    println!("explicit Euler: energy ×{end:.1} after 10 periods (closed form ×{expected:.1})");
    assert!((end / expected - 1.0).abs() < 0.01, "{end} vs {expected}");
    assert!((expected - 695.0).abs() < 1.0);
}

#[test]
fn symplectic_euler_energy_stays_bounded() {
    let (lo, hi, _) = energy_over_ten_periods(Integrator::SymplecticEuler);
    let dev = (1.0 - lo).max(hi - 1.0);
    println!("symplectic Euler: max energy deviation {:.2}%", 100.0 * dev);
    // DESIGN.md: bounded, max deviation 5.5% (about ωh/2 = 5.2%).
    assert!(dev > 0.04 && dev < 0.06, "deviation {dev}");
}

#[test]
fn velocity_verlet_energy_stays_bounded_at_second_order() {
    let (lo, hi, _) = energy_over_ten_periods(Integrator::VelocityVerlet);
    let dev = (1.0 - lo).max(hi - 1.0);
    println!("velocity Verlet: max energy deviation {:.3}%", 100.0 * dev);
    // DESIGN.md: 0.27% ((ωh)²/4 = 0.27%).
    assert!(dev > 0.002 && dev < 0.0035, "deviation {dev}");
}

#[test]
fn rk4_loses_energy_slowly() {
    let (_, hi, end) = energy_over_ten_periods(Integrator::Rk4);
    println!("RK4: energy change {:.2e} after 10 periods", end - 1.0);
    // DESIGN.md: −1.1e-5. Closed form per step: 1 − (ωh)⁶/72 → 600 steps: −1.1e-5.
    let w_h = std::f64::consts::TAU / 60.0;
    let expected = (1.0 - w_h.powi(6) / 72.0).powi(600) - 1.0;
    assert!(
        end - 1.0 < 0.0,
        "RK4 must lose energy, changed by {}",
        end - 1.0
    );
    assert!(
        (end - 1.0 - expected).abs() < 3e-6,
        "{} vs {expected}",
        end - 1.0
    );
    assert!(hi < 1.0 + 2e-6);
}

#[test]
fn four_substeps_equal_four_steps_bit_for_bit() {
    // 1 step of dt with 4 substeps is the same arithmetic as 4 steps of dt/4.
    let (mut a, ea) = oscillator(1.0 / 60.0, Integrator::SymplecticEuler, 0.0);
    a.insert_resource(PhysicsTime::new(1.0 / 15.0, 4).unwrap());
    let (mut b, eb) = oscillator(1.0 / 60.0, Integrator::SymplecticEuler, 0.0);
    for _ in 0..30 {
        a.step_physics();
    }
    for _ in 0..120 {
        b.step_physics();
    }
    assert_eq!(x(&a, ea), x(&b, eb));
}

/// Error in x at t = 0.3 s (not a multiple of the 1 s period) for n steps.
fn error_at_03(integrator: Integrator, n: u32) -> f64 {
    let (mut world, body) = oscillator(0.3 / n as f32, integrator, 0.0);
    for _ in 0..n {
        world.step_physics();
    }
    let exact = (std::f64::consts::TAU * 0.3).cos();
    (f64::from(x(&world, body).x) - exact).abs()
}

#[test]
fn measured_orders_of_convergence() {
    // Steps chosen so the error is far above f32 rounding yet in the asymptotic range.
    let cases = [
        (Integrator::ExplicitEuler, 40, 1.0),
        (Integrator::SymplecticEuler, 40, 1.0),
        (Integrator::VelocityVerlet, 20, 2.0),
        (Integrator::Rk4, 4, 4.0),
    ];
    for (integrator, n, expected) in cases {
        let e1 = error_at_03(integrator, n);
        let e2 = error_at_03(integrator, 2 * n);
        let e3 = error_at_03(integrator, 4 * n);
        let p1 = (e1 / e2).log2();
        let p2 = (e2 / e3).log2();
        println!(
            "{:>16}: errors {e1:.2e} {e2:.2e} {e3:.2e}, orders {p1:.3} {p2:.3}",
            integrator.name()
        );
        assert!((p2 - expected).abs() < 0.15, "{integrator:?}: order {p2}");
    }
}

#[test]
fn damped_oscillator_matches_amplitude_ratio_and_period() {
    // ω = 2π, ζ = 0.1 → c = 2ζω m. Closed forms: ratio e^(−2πζ/√(1−ζ²)) = 0.5318 per period,
    // damped period 1/√(1−ζ²) = 1.00504 s.
    let zeta = 0.1f32;
    let c = 2.0 * zeta * TWO_PI;
    let dt = 1.0 / 2000.0;
    let (mut world, body) = oscillator(dt, Integrator::Rk4, c);
    // Track successive positive maxima of x(t).
    let mut peaks: Vec<(f64, f64)> = Vec::new();
    let (mut prev2, mut prev1) = (f64::NAN, 1.0f64);
    for step in 1..=9000 {
        world.step_physics();
        let now = f64::from(x(&world, body).x);
        if prev1 > prev2 && prev1 > now && prev1 > 0.0 {
            // Parabolic refinement of the peak time and height.
            let denom = prev2 - 2.0 * prev1 + now;
            let off = 0.5 * (prev2 - now) / denom;
            let t = (f64::from(step - 1) + off) * f64::from(dt);
            peaks.push((t, prev1 - 0.25 * (prev2 - now) * off));
        }
        (prev2, prev1) = (prev1, now);
    }
    assert!(peaks.len() >= 3, "peaks {peaks:?}");
    let ratio = peaks[1].1 / peaks[0].1;
    let period = peaks[1].0 - peaks[0].0;
    let z = f64::from(zeta);
    let expected_ratio = (-std::f64::consts::TAU * z / (1.0 - z * z).sqrt()).exp();
    println!("damped: ratio {ratio:.4} (closed form {expected_ratio:.4}), period {period:.5} s");
    assert!((ratio - 0.5318).abs() < 0.002, "ratio {ratio}");
    assert!((period - 1.00504).abs() < 0.001, "period {period}");
}

#[test]
fn per_body_override_matches_a_world_using_that_integrator() {
    // Two independent oscillators in one world: the global integrator for one, an override
    // for the other. Each must match, bit for bit, a world that uses its integrator globally.
    let run_alone = |integrator| {
        let (mut world, body) = oscillator(1.0 / 60.0, integrator, 0.0);
        for _ in 0..90 {
            world.step_physics();
        }
        x(&world, body)
    };
    let (mut world, plain) = oscillator(1.0 / 60.0, Integrator::SymplecticEuler, 0.0);
    let special =
        hooke::tools::scenes::oscillator(&mut world, 1.0, TWO_PI * TWO_PI, 0.0, 1.0).unwrap();
    world
        .entity_mut(special)
        .insert(IntegratorOverride(Integrator::Rk4));
    for _ in 0..90 {
        world.step_physics();
    }
    assert_eq!(x(&world, plain), run_alone(Integrator::SymplecticEuler));
    assert_eq!(x(&world, special), run_alone(Integrator::Rk4));
    assert_ne!(x(&world, plain), x(&world, special));
}
