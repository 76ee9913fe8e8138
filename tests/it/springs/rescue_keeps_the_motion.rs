//! What the default rescue keeps. A system too stiff for the substep is rescued by
//! `StabilityPolicy::Automatic` (the default): stepped on its own a few times per substep when
//! that suffices, solved by BDF2 (which damps only the motions too fast for the step) when it
//! would take more. At the defaults (`PhysicsPlugins` and nothing else) a pendulum on a stiff
//! rod keeps its period and swing under either, a taut string its tone, and a top on a stiff
//! pivot its spin. Backward Euler, the first rescue, took 40% of the pendulum's swing in 14 s,
//! 72% of the string's amplitude per period and 74% of the top's spin in 10 s.

use crate::common;

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::integrator::{ImplicitScheme, Rescue, StabilityWarning};
use hooke::prelude::*;
use hooke::springs::ChainBuilder;
use hooke::tools::scenes;

fn told(w: &World) -> Vec<StabilityWarning> {
    let m = w.resource::<Messages<StabilityWarning>>();
    m.get_cursor().read(m).cloned().collect()
}

/// K(m), the complete elliptic integral of the first kind, by the arithmetic–geometric mean.
fn elliptic_k(m: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

#[test]
fn a_pendulum_on_a_stiff_rod_keeps_its_period_and_swing_at_the_defaults() {
    // 1 kg on a 1 m spring of 1e6 N/m: the rod's own mode is 1000 rad/s, h_crit = 2 ms, past
    // the default 1/240 s substep: stepped 3 times per substep on its own.
    stiff_rod_pendulum(1e6, Rescue::LocalSubsteps(3));
    // At 1e9 N/m (h_crit = 63 µs) that would take 74: BDF2 is cheaper.
    stiff_rod_pendulum(1e9, Rescue::Implicit(ImplicitScheme::Bdf2));
}

/// A 1 kg bob on a 1 m rod of stiffness `k`, released from rest at 90° at the defaults: the
/// policy chooses `rescue`, and the period and swing hold over 10 periods.
fn stiff_rod_pendulum(k: f32, rescue: Rescue) {
    let mut w = common::default_world();
    let bob = scenes::stiff_rod_pendulum(&mut w, k).unwrap();
    let g = 9.81f64;
    // 4 √(L/g) K(sin²(θ₀/2)) at θ₀ = 90°.
    let period = 4.0 * (1.0 / g).sqrt() * elliptic_k(0.5);
    let steps = (10.0 * period * 60.0).ceil() as usize + 30;
    let (mut crossings, mut last_x, mut t) = (Vec::new(), 1.0f32, 0.0f64);
    let mut swing = Vec::new();
    for step in 0..steps {
        if step == 1 {
            let first = told(&w);
            assert_eq!(first.len(), 1, "{first:?}");
            assert_eq!(first[0].rescue, Some(rescue));
            println!("{}", first[0].advice());
        }
        w.step_physics();
        t += 1.0 / 60.0;
        let x = common::x(&w, bob);
        if last_x < 0.0 && x.x >= 0.0 {
            crossings.push(t - 1.0 / 60.0 * f64::from(x.x / (x.x - last_x)));
        }
        last_x = x.x;
        swing.push((t, x.x.atan2(-x.y).abs()));
    }
    let warning = &told(&w)[..];
    assert_eq!(
        warning.len(),
        0,
        "the warning of the first step has rotated out"
    );
    let d = w.resource::<PhysicsDiagnostics>();
    assert_eq!(d.rescued, 1, "switched once, and the count persists");
    assert_eq!(d.quarantined_total, 0);
    assert!(crossings.len() >= 10, "{crossings:?}");
    let measured = (crossings[9] - crossings[0]) / 9.0;
    // The swing in the tenth period.
    let start = crossings[0] + 8.0 * period;
    let amplitude = swing
        .iter()
        .filter(|(t, _)| *t >= start && *t < start + period)
        .map(|s| s.1)
        .fold(0.0f32, f32::max)
        .to_degrees();
    println!(
        "stiff-rod pendulum of {k:e} N/m at the defaults ({}): period {measured:.4} s (closed {period:.4} s, {:+.2}%), swing in the 10th period {amplitude:.2}° of 90°",
        rescue.name(),
        100.0 * (measured / period - 1.0)
    );
    assert!((measured / period - 1.0).abs() < 0.01, "{measured}");
    assert!(amplitude > 0.95 * 90.0, "{amplitude}");
}

#[test]
fn a_taut_string_keeps_its_tone_at_the_defaults() {
    // A string strung vertically between pins 4 m apart (gravity along it, so no sag): 20
    // beads of 10 g, 19 segments of a = 4/19 m, k = 1e4 N/m, its rest length 1.66% short:
    // T = k a (1 − 0.9834) = 35 N (the beads' weight, 1.8 N, tilts it by ±2.5% along the
    // string; the mean stays T). Its axial modes reach 2 √(k/m) = 2000 rad/s, h_crit = 1 ms.
    // The beaded string's transverse modes are ω_j = 2 √(T/(m a)) sin(jπ/2n).
    let (n, m, k, scale) = (19.0f64, 0.01f64, 1e4f64, 0.9834f64);
    let a = 4.0 / n;
    let tension = k * a * (1.0 - scale);
    let omega = 2.0 * (tension / (m * a)).sqrt() * (std::f64::consts::PI / (2.0 * n)).sin();
    let mut w = common::default_world();
    let string = ChainBuilder::rope(Vec3::new(0.0, 5.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 20)
        .node_mass(m as f32)
        .stiffness(k as f32)
        .damping(0.0)
        .pin_end(true)
        .rest_scale(scale as f32)
        .spawn(&mut w)
        .unwrap();
    // Plucked in its first mode, 1 cm at the middle.
    let amplitude = 0.01f64;
    for (i, &node) in string.nodes.iter().enumerate() {
        let shape = (std::f64::consts::PI * i as f64 / n).sin();
        w.get_mut::<LinearVelocity>(node).unwrap().0 =
            Vec3::new((omega * amplitude * shape) as f32, 0.0, 0.0).into();
    }
    let middle = string.nodes[10];
    let periods = 10.0;
    let steps = (periods * std::f64::consts::TAU / omega * 60.0).ceil() as usize + 20;
    let (mut crossings, mut last, mut t, mut peaks) = (Vec::new(), 0.0f32, 0.0f64, Vec::new());
    let mut peak = 0.0f32;
    for _ in 0..steps {
        w.step_physics();
        t += 1.0 / 60.0;
        let x = common::x(&w, middle).x;
        if last < 0.0 && x >= 0.0 {
            crossings.push(t - 1.0 / 60.0 * f64::from(x / (x - last)));
            peaks.push(peak);
            peak = 0.0;
        }
        peak = peak.max(x.abs());
        last = x;
    }
    let d = w.resource::<PhysicsDiagnostics>();
    assert_eq!(d.rescued, 1);
    assert_eq!(d.quarantined_total, 0);
    let count = crossings.len() - 1;
    let measured = std::f64::consts::TAU * count as f64 / (crossings[count] - crossings[0]);
    // The peak per period, first full period to last.
    let (first, last_peak) = (f64::from(peaks[1]), f64::from(peaks[peaks.len() - 1]));
    let per_period = 1.0 - (last_peak / first).powf(1.0 / (peaks.len() - 2) as f64);
    println!(
        "taut string at the defaults: ω {measured:.3} rad/s (closed {omega:.3}, {:+.2}%), amplitude {:.2} → {:.2} mm over {} periods, {:.2}% lost per period",
        100.0 * (measured / omega - 1.0),
        first * 1e3,
        last_peak * 1e3,
        peaks.len() - 2,
        100.0 * per_period
    );
    assert!(
        (measured / omega - 1.0).abs() < 0.01,
        "{measured} vs {omega}"
    );
    assert!(per_period < 0.05, "{per_period}");
}

/// The stiff-rod pendulum of the first test under a policy, for `seconds`: the energy lost
/// (J, from the diagnostics' total) and the numerical damping the diagnostics report at the
/// end (W).
fn pendulum_price(policy: hooke::integrator::StabilityPolicy, seconds: f32) -> (f64, f64) {
    let mut w = common::default_world();
    w.insert_resource(policy);
    scenes::stiff_rod_pendulum(&mut w, 1e6).unwrap();
    w.step_physics();
    let e0 = w.resource::<PhysicsDiagnostics>().total_energy();
    for _ in 0..(seconds * 60.0) as usize {
        w.step_physics();
    }
    let d = w.resource::<PhysicsDiagnostics>();
    (e0 - d.total_energy(), d.numerical_damping)
}

#[test]
fn the_price_of_the_rescue_is_in_the_diagnostics_and_agrees_with_the_energy_lost() {
    use hooke::integrator::StabilityPolicy::SwitchToImplicit;
    let seconds = 4.0 * 2.3678; // four periods
    let (be_lost, be_rate) =
        pendulum_price(SwitchToImplicit(ImplicitScheme::BackwardEuler), seconds);
    let (bdf2_lost, bdf2_rate) = pendulum_price(SwitchToImplicit(ImplicitScheme::Bdf2), seconds);
    // The pendulum's energy relative to its lowest point is m g L = 9.81 J.
    println!(
        "over 4 periods: backward Euler lost {be_lost:.3} J ({:.3} W on average), reported {be_rate:.3} W; BDF2 lost {bdf2_lost:.2e} J, reported {bdf2_rate:.2e} W",
        be_lost / f64::from(seconds)
    );
    // Backward Euler's loss is real and reported at its size (the report averages over the
    // last second, the loss over four periods: within 50%).
    assert!(be_lost > 0.5, "{be_lost}");
    let mean = be_lost / f64::from(seconds);
    assert!(
        be_rate > 0.5 * mean && be_rate < 1.5 * mean,
        "{be_rate} vs {mean}"
    );
    // BDF2 keeps the swing: a hundredth of backward Euler's price, in the loss and the report.
    assert!(bdf2_lost.abs() < 0.01 * be_lost, "{bdf2_lost}");
    assert!(bdf2_rate.abs() < 0.01 * be_rate, "{bdf2_rate}");
    // The default's local substeps are symplectic Euler at a finer step: nothing to report,
    // and the energy is kept to its O(h) oscillation.
    let (local_lost, local_rate) =
        pendulum_price(hooke::integrator::StabilityPolicy::Automatic, seconds);
    println!("local substeps (the default): lost {local_lost:.2e} J, reported {local_rate:.2e} W");
    assert!(local_lost.abs() < 0.01 * be_lost, "{local_lost}");
    assert_eq!(local_rate, 0.0);
}

/// The spin about the top's own axis (rad/s) and the axis' tilt from the vertical (rad).
fn spin_and_tilt(w: &World, top: Entity) -> (f32, f32) {
    let q = w.get::<Rotation>(top).unwrap().0;
    let axis = q * Vec3::Y;
    let omega = Vec3::from(w.get::<AngularVelocity>(top).unwrap().0);
    (omega.dot(axis), axis.angle_between(Vec3::Y))
}

#[test]
fn a_top_on_a_stiff_pivot_keeps_its_spin_at_the_defaults() {
    // A fast top (L₃² = 4 ≫ 4 I₁' m g l = 1.3): it precesses slowly with a small nutation, and
    // its spin about its own axis is conserved exactly (no torque about a symmetry axis
    // through the pivot). The pivot's mode is about √(k (1/m + l²/I₁)) = 2300 rad/s at 1e6
    // N/m, h_crit ≈ 0.85 ms: past the default substep. The reference is the same top
    // integrated explicitly at h ≈ 0.26 ms (64 substeps at 60 Hz). At the defaults first,
    // then at other frame rates and substep counts.
    top_keeps_its_spin(None);
    for (hz, substeps) in [(30.0f32, 4u32), (60.0, 8), (144.0, 4)] {
        top_keeps_its_spin(Some((hz, substeps)));
    }
}

/// The top of the test above for 10 s at `time` (None: the defaults), against explicit
/// integration at about 3840 substeps a second.
fn top_keeps_its_spin(time: Option<(f32, u32)>) {
    use hooke::core::time::PhysicsTime;
    let (k, spin) = (1e6f32, 200.0f32);
    let (hz, substeps) = time.unwrap_or((60.0, 4));
    let mut w = common::default_world();
    if time.is_some() {
        w.insert_resource(PhysicsTime::new(1.0 / hz, substeps).unwrap());
    }
    let top = scenes::top_on_a_pivot(&mut w, k, spin).unwrap();
    let mut reference = common::default_world();
    reference.insert_resource(hooke::integrator::StabilityPolicy::Warn);
    let fine = (3840.0 / hz).ceil() as u32;
    reference.insert_resource(PhysicsTime::new(1.0 / hz, fine).unwrap());
    let top_ref = scenes::top_on_a_pivot(&mut reference, k, spin).unwrap();
    w.step_physics();
    reference.step_physics();
    let told = told(&w);
    assert_eq!(told.len(), 1, "{told:?}");
    let Some(Rescue::LocalSubsteps(n)) = told[0].rescue else {
        panic!("{told:?}");
    };
    let (spin0, _) = spin_and_tilt(&w, top);
    let mut tilt_gap = 0.0f32;
    for _ in 0..(10.0 * hz) as usize {
        w.step_physics();
        reference.step_physics();
        tilt_gap =
            tilt_gap.max((spin_and_tilt(&w, top).1 - spin_and_tilt(&reference, top_ref).1).abs());
    }
    let (spin1, tilt) = spin_and_tilt(&w, top);
    let (_, tilt_ref) = spin_and_tilt(&reference, top_ref);
    println!(
        "top on a {k:e} N/m pivot, 10 s at {hz} Hz x{substeps} ({n} local substeps): spin {spin0:.3} → {spin1:.3} rad/s ({:+.4}%), tilt {tilt:.3} rad (explicit ×{fine}: {tilt_ref:.3}; largest gap {tilt_gap:.3} rad)",
        100.0 * (spin1 / spin0 - 1.0)
    );
    assert_eq!(w.resource::<PhysicsDiagnostics>().quarantined_total, 0);
    assert!((spin1 / spin0 - 1.0).abs() < 0.01, "{spin1} of {spin0}");
    assert!(tilt_gap < 0.05, "{tilt_gap}");
}
