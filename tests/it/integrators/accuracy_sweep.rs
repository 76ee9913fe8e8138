//! The accuracy dial's API (`hooke::tools::accuracy`) against the oscillator's exact discrete
//! solutions and the integrators' orders.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::tools::accuracy::{Measurement, Reference, Setting, Sweep, SweepReport, order, sweep};
use hooke::tools::scenes;

const OMEGA: f64 = std::f64::consts::TAU;

/// The unit oscillator (m = 1, k = 4π², period 1 s) from x = 1 at rest, without gravity.
fn oscillator(world: &mut World) -> hooke::Result<()> {
    world.insert_resource(Gravity::new(Vec3::ZERO)?);
    let body = scenes::oscillator(world, 1.0, (OMEGA * OMEGA) as f32, 0.0, 1.0)?;
    world.entity_mut(body).insert(Observed);
    Ok(())
}

#[derive(Component)]
struct Observed;

fn x(world: &mut World) -> Vec<f32> {
    let mut q = world.query_filtered::<&Position, With<Observed>>();
    q.iter(world).map(|p| p.get().x).collect()
}

fn exact_x() -> Reference {
    Reference::exact(|t| vec![(OMEGA * t).cos()])
}

/// The largest |x_n − cos ωt_n| of the integrator's exact discrete map, in f64: explicit
/// Euler (x, v) ← (x + h v, v − ω² h x); symplectic Euler v ← v − ω² h x, then x ← x + h v.
fn discrete_error(integrator: Integrator, dt: f64, substeps: u32, steps: u32) -> f64 {
    let h = dt / f64::from(substeps);
    let (mut x, mut v, mut worst) = (1.0f64, 0.0f64, 0.0f64);
    for k in 1..=steps {
        for _ in 0..substeps {
            match integrator {
                Integrator::ExplicitEuler => (x, v) = (x + h * v, v - OMEGA * OMEGA * h * x),
                Integrator::SymplecticEuler => {
                    v -= OMEGA * OMEGA * h * x;
                    x += h * v;
                }
                _ => unreachable!("only the two Euler maps are written out"),
            }
        }
        worst = worst.max((x - (OMEGA * dt * f64::from(k)).cos()).abs());
    }
    worst
}

#[test]
fn sweep_errors_equal_the_exact_discrete_solutions() {
    // 10.3 s: away from whole periods, where the phase error would hide.
    let steps = 618;
    let settings = [
        Setting::new(Integrator::ExplicitEuler, 1),
        Setting::new(Integrator::ExplicitEuler, 4),
        Setting::new(Integrator::SymplecticEuler, 1),
        Setting::new(Integrator::SymplecticEuler, 4),
    ];
    let report = sweep(
        oscillator,
        x,
        &settings,
        exact_x(),
        Sweep::steps(1.0 / 60.0, steps).with_timing_runs(1),
    )
    .unwrap();
    for m in &report.measurements {
        let want = discrete_error(m.setting.integrator, 1.0 / 60.0, m.setting.substeps, steps);
        println!("{}: sweep {:.6e}, exact map {want:.6e}", m.setting, m.error);
        // f32 state against the f64 map: a relative 1e-3 is far above f32 rounding's share
        // of these errors (all above 1e-3) and far below any other integrator's.
        assert!(
            (m.error / want - 1.0).abs() < 1e-3,
            "{}: {} vs {want}",
            m.setting,
            m.error
        );
        assert!(!m.quarantined && m.seconds_per_step > 0.0);
    }
    // Explicit Euler grows the amplitude by (1 + ω²h²)^(n/2): ×26 at one substep.
    assert!(report.measurements[0].error > 20.0);
}

#[test]
fn measured_orders_are_1_1_2_4_and_1() {
    // A coarse step (0.1 s) and a horizon of 1.3 s keep every integrator's error above the
    // f32 floor and away from a whole period.
    let substeps = [1, 2, 4, 8, 16, 32, 64];
    let settings = Setting::grid(&Integrator::ALL, &substeps);
    let report = sweep(
        oscillator,
        x,
        &settings,
        exact_x(),
        Sweep::steps(0.1, 13).with_timing_runs(1),
    )
    .unwrap();
    for integrator in Integrator::ALL {
        let errors: Vec<(u32, f64)> = substeps
            .iter()
            .map(|&s| (s, report.get(Setting::new(integrator, s)).unwrap().error))
            .collect();
        // The finest pair still in the asymptotic range (error below 10%, above 1e-4).
        let pair = errors
            .windows(2)
            .rev()
            .find(|w| w.iter().all(|&(_, e)| (1e-4..0.1).contains(&e)))
            .unwrap_or_else(|| panic!("{}: no pair in range: {errors:?}", integrator.name()));
        let p = order(pair[0], pair[1]);
        println!(
            "{}: order {p:.2} between ×{} and ×{} ({:.2e} → {:.2e})",
            integrator.name(),
            pair[0].0,
            pair[1].0,
            pair[0].1,
            pair[1].1
        );
        let expected = f64::from(integrator.order());
        assert!((p - expected).abs() < 0.25, "{}: {p}", integrator.name());
    }
}

#[test]
fn a_run_against_itself_has_zero_error() {
    // Determinism: the converged reference at the same setting is bit-identical.
    let s = Setting::new(Integrator::VelocityVerlet, 2);
    let report = sweep(
        oscillator,
        x,
        &[s],
        Reference::Converged(s),
        Sweep::seconds(1.0).with_timing_runs(1),
    )
    .unwrap();
    assert_eq!(report.measurements[0].error, 0.0);
    assert!(report.reference_seconds_per_step.is_some());
}

#[test]
fn a_diverging_setting_reports_infinite_error_and_quarantine() {
    // A 1e6 N/m spring on 1 kg: ωh = 16.7 at 60 Hz, far past explicit Euler's limit.
    let stiff = |world: &mut World| -> hooke::Result<()> {
        world.insert_resource(Gravity::new(Vec3::ZERO)?);
        let body = scenes::oscillator(world, 1.0, 1.0e6, 0.0, 1.0)?;
        world.entity_mut(body).insert(Observed);
        Ok(())
    };
    let report = sweep(
        stiff,
        x,
        &[
            Setting::new(Integrator::ExplicitEuler, 1),
            Setting::new(Integrator::ImplicitEuler, 1),
        ],
        Reference::exact(|t| vec![(1000.0 * t).cos()]),
        Sweep::seconds(1.0).with_timing_runs(1),
    )
    .unwrap();
    let (explicit, implicit) = (report.measurements[0], report.measurements[1]);
    println!("explicit {explicit:?}\nimplicit {implicit:?}");
    assert!(explicit.quarantined && explicit.error == f64::INFINITY);
    assert!(!explicit.is_finite());
    // Backward Euler stays finite (and damps the oscillation away: the error is about 1).
    assert!(implicit.is_finite() && implicit.error <= 1.0 + 1e-3);
}

#[test]
fn bad_sweeps_are_typed_errors() {
    assert!(matches!(
        sweep(oscillator, x, &[], exact_x(), Sweep::seconds(1.0)),
        Err(hooke::Error::TooFew { .. })
    ));
    assert!(matches!(
        sweep(
            oscillator,
            x,
            &[Setting::new(Integrator::Rk4, 0)],
            exact_x(),
            Sweep::seconds(1.0)
        ),
        Err(hooke::Error::ZeroSubsteps)
    ));
    assert!(
        sweep(
            oscillator,
            x,
            &[Setting::DEFAULT],
            exact_x(),
            Sweep::steps(f32::NAN, 10)
        )
        .is_err()
    );
}

fn measured(integrator: Integrator, substeps: u32, error: f64, micros: f64) -> Measurement {
    Measurement {
        setting: Setting::new(integrator, substeps),
        error,
        seconds_per_step: micros * 1e-6,
        quarantined: !error.is_finite(),
    }
}

#[test]
fn cheapest_within_and_the_pareto_front() {
    let report = SweepReport {
        measurements: vec![
            measured(Integrator::ExplicitEuler, 1, f64::INFINITY, 1.0),
            measured(Integrator::SymplecticEuler, 1, 0.05, 2.0),
            measured(Integrator::SymplecticEuler, 4, 0.012, 6.0),
            measured(Integrator::VelocityVerlet, 1, 0.008, 4.0),
            measured(Integrator::Rk4, 1, 1e-5, 9.0),
            measured(Integrator::Rk4, 2, 1e-6, 18.0),
        ],
        reference_seconds_per_step: None,
    };
    let pick = |tol| report.cheapest_within(tol).map(|m| m.setting);
    assert_eq!(
        pick(0.1),
        Some(Setting::new(Integrator::SymplecticEuler, 1))
    );
    // Verlet ×1 is within 1% and cheaper than symplectic ×4.
    assert_eq!(
        pick(0.01),
        Some(Setting::new(Integrator::VelocityVerlet, 1))
    );
    assert_eq!(pick(1e-4), Some(Setting::new(Integrator::Rk4, 1)));
    assert_eq!(pick(1e-9), None);
    let front: Vec<Setting> = report.pareto().iter().map(|m| m.setting).collect();
    assert_eq!(
        front,
        vec![
            Setting::new(Integrator::SymplecticEuler, 1),
            Setting::new(Integrator::VelocityVerlet, 1),
            Setting::new(Integrator::Rk4, 1),
            Setting::new(Integrator::Rk4, 2),
        ]
    );
}

#[test]
fn cheapest_within_on_a_real_sweep_is_the_fastest_setting_within_tolerance() {
    let report = sweep(
        oscillator,
        x,
        &Setting::grid(&Integrator::ALL, &[1, 2, 4, 8]),
        exact_x(),
        Sweep::seconds(10.3).with_timing_runs(1),
    )
    .unwrap();
    for tol in [0.05, 0.01, 1e-3, 1e-4] {
        let best = report.cheapest_within(tol).unwrap();
        println!("within {tol:e}: {} ({:.2e})", best.setting, best.error);
        assert!(best.error <= tol);
        for m in report.measurements.iter().filter(|m| m.error <= tol) {
            assert!(m.seconds_per_step >= best.seconds_per_step);
        }
    }
    // RK4 is the only integrator within 1e-4 of the closed form at these substeps.
    assert_eq!(
        report.cheapest_within(1e-4).unwrap().setting.integrator,
        Integrator::Rk4
    );
    // Nothing diverged to a finite error: explicit Euler ×1's 25.75 is reported as such.
    assert!(report.measurements.iter().all(|m| !m.quarantined));
}
