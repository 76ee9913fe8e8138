//! The problems with known answers, each swept over every integrator × substeps.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec2, DVec3, Quat, Vec3};
use hooke::collision::Collider;
use hooke::collision::Friction;
use hooke::collision::Restitution;
use hooke::core::schedule::{ForceSystems, add_force_systems};
use hooke::integrator::{ImplicitScheme, StabilityPolicy};
use hooke::prelude::*;
use hooke::rigid::Inertia;
use hooke::rigid::MassProperties;
use hooke::rigid::OrientationUpdate;
use hooke::rigid::RigidBodyBundle;
use hooke::rigid::Rotation;
use hooke::tools::accuracy::{
    Measurement, Reference, Setting, Sweep, SweepReport, sweep, timed_run,
};
use hooke::tools::scenes;

/// One problem's sweep, with how its error is measured.
pub struct Problem {
    pub name: &'static str,
    /// What the error is, in words (it is divided by `scale` to be relative).
    pub measure: &'static str,
    pub reference: &'static str,
    /// The relative error is the sweep's error divided by this (in the observed units).
    pub scale: f64,
    pub report: SweepReport,
    /// Series and label per measurement, when they are not the integrator and substeps
    /// (the FEM cantilever: strain model and mesh).
    pub names: Option<Vec<(String, String)>>,
    /// With `names`: which measurement is hooke's default setting, if any is.
    pub default: Option<usize>,
}

impl Problem {
    pub fn new(
        name: &'static str,
        measure: &'static str,
        reference: &'static str,
        scale: f64,
        report: SweepReport,
    ) -> Self {
        Self {
            name,
            measure,
            reference,
            scale,
            report,
            names: None,
            default: None,
        }
    }

    /// The series (marker) and the point's label of measurement `i`.
    pub fn naming(&self, i: usize) -> (String, String) {
        match &self.names {
            Some(n) => n[i].clone(),
            None => {
                let s = self.report.measurements[i].setting;
                (s.series(), format!("×{}", s.substeps))
            }
        }
    }

    /// The error of `m` relative to the problem's scale.
    pub fn relative(&self, m: &Measurement) -> f64 {
        m.error / self.scale
    }

    /// The cheapest measurement within a relative tolerance, by the sweep API.
    pub fn cheapest_within(&self, relative: f64) -> Option<usize> {
        let m = self.report.cheapest_within(relative * self.scale)?;
        self.report.measurements.iter().position(|x| x == m)
    }
}

pub const G: f32 = 9.81;
const TAU: f64 = std::f64::consts::TAU;

#[derive(Component)]
struct Observed;

/// Every integrator × {1, 2, 4, 8} substeps, each system on the integrator asked for, and
/// hooke's defaults (symplectic Euler ×4 under the default stability policy).
pub fn settings() -> Vec<Setting> {
    let mut s = Setting::grid(&Integrator::ALL, &[1, 2, 4, 8]);
    s.push(Setting::DEFAULT);
    s
}

/// [`settings`] and, for scenes with systems past their explicit limit, every stability
/// policy at every substep count: the default's own choice (local substeps or BDF2), BDF2
/// and backward Euler.
pub fn stiff_settings() -> Vec<Setting> {
    let mut s = Setting::grid(&Integrator::ALL, &[1, 2, 4, 8]);
    for substeps in [1, 2, 4, 8] {
        s.push(
            Setting::new(Integrator::SymplecticEuler, substeps)
                .with_policy(StabilityPolicy::Automatic),
        );
    }
    for scheme in [ImplicitScheme::Bdf2, ImplicitScheme::BackwardEuler] {
        for substeps in [1, 2, 4, 8] {
            s.push(Setting::new(Integrator::SymplecticEuler, substeps).with_rescue(scheme));
        }
    }
    s
}

pub fn runs(quick: bool) -> u32 {
    if quick { 1 } else { 7 }
}

/// The world every problem starts from: gravity `g`, sleeping off (a resting body would stop
/// being measured). The setting says whether the stability policy may switch a stiff system
/// (see `Setting::policy`).
fn base(world: &mut World, g: Vec3) -> hooke::Result<()> {
    world.insert_resource(Gravity::new(g)?);
    world.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    Ok(())
}

fn observed_positions(world: &mut World) -> Vec<f32> {
    let mut q = world.query_filtered::<&Position, With<Observed>>();
    q.iter(world).flat_map(|p| p.get().to_array()).collect()
}

fn unit_oscillator(world: &mut World, c: f32) -> hooke::Result<()> {
    base(world, Vec3::ZERO)?;
    let body = scenes::oscillator(world, 1.0, (TAU * TAU) as f32, c, 1.0)?;
    world.entity_mut(body).insert(Observed);
    Ok(())
}

fn x_only(world: &mut World) -> Vec<f32> {
    vec![observed_positions(world)[0]]
}

pub fn oscillator(quick: bool) -> hooke::Result<Problem> {
    let report = sweep(
        |w: &mut World| unit_oscillator(w, 0.0),
        x_only,
        &settings(),
        Reference::exact(|t| vec![(TAU * t).cos()]),
        Sweep::seconds(10.3).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "undamped oscillator",
        "max |x − cos 2πt| over 10.3 s, per 1 m amplitude",
        "closed form",
        1.0,
        report,
    ))
}

pub fn damped_oscillator(quick: bool) -> hooke::Result<Problem> {
    let zeta = 0.1f64;
    let c = 2.0 * zeta * TAU;
    let report = sweep(
        |w: &mut World| unit_oscillator(w, c as f32),
        x_only,
        &settings(),
        Reference::exact(move |t| {
            let wd = TAU * (1.0 - zeta * zeta).sqrt();
            let x = (-zeta * TAU * t).exp() * ((wd * t).cos() + zeta * TAU / wd * (wd * t).sin());
            vec![x]
        }),
        Sweep::seconds(5.3).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "damped oscillator (ζ = 0.1)",
        "max |x − x(t)| over 5.3 s, per 1 m amplitude",
        "closed form",
        1.0,
        report,
    ))
}

/// The elastic pendulum's f64 trajectory by RK4 at 1e5 steps per second (converged).
fn pendulum_reference(k: f64, l: f64, dt: f64, steps: u32) -> Vec<Vec<f64>> {
    let acc = |x: DVec2| {
        let r = x.length();
        -k * (r - l) * x / r + DVec2::new(0.0, -f64::from(G))
    };
    let (mut x, mut v) = (DVec2::new(l, 0.0), DVec2::ZERO);
    let per = 1000u32;
    let h = dt / f64::from(per);
    let mut out = Vec::new();
    for _ in 0..steps {
        for _ in 0..per {
            let (k1x, k1v) = (v, acc(x));
            let (k2x, k2v) = (v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x));
            let (k3x, k3v) = (v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x));
            let (k4x, k4v) = (v + h * k3v, acc(x + h * k3x));
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
        out.push(vec![x.x, x.y, 0.0]);
    }
    out
}

/// The complete elliptic integral of the first kind K(m), m = k², by the AGM.
pub fn elliptic_k(m: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

pub fn pendulum(quick: bool) -> hooke::Result<Problem> {
    // A 1 kg bob on a 1 m spring of 1e4 N/m, released horizontally (90°).
    let (k, l) = (1.0e4f64, 1.0f64);
    let sweep_cfg = Sweep::seconds(4.0).with_timing_runs(runs(quick));
    let reference = pendulum_reference(k, l, f64::from(sweep_cfg.dt), sweep_cfg.steps);
    // The reference's period (between its first two downward zero crossings of x) beside
    // the rigid pendulum's, 4 √(L/g) K(sin²(θ₀/2)).
    let crossings: Vec<f64> = reference
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0][0] > 0.0 && w[1][0] <= 0.0)
        .map(|(i, w)| {
            let f = w[0][0] / (w[0][0] - w[1][0]);
            (i as f64 + 1.0 + f) / 60.0
        })
        .collect();
    let rigid = 4.0 * (l / f64::from(G)).sqrt() * elliptic_k(0.5);
    let elastic = crossings
        .get(1)
        .zip(crossings.first())
        .map_or(f64::NAN, |(b, a)| b - a);
    let measure: &'static str = Box::leak(
        format!(
            "max bob position error over 4 s, per 1 m length (period: rigid {rigid:.4} s by the elliptic integral, this elastic rod {elastic:.4} s)"
        )
        .into_boxed_str(),
    );
    let report = sweep(
        move |w: &mut World| {
            base(w, Vec3::new(0.0, -G, 0.0))?;
            let anchor = w.spawn(ParticleBundle::pinned(Vec3::ZERO)?).id();
            let bob = w
                .spawn((
                    ParticleBundle::new(Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO, 1.0)?,
                    Observed,
                ))
                .id();
            Spring::new(anchor, bob, l as f32, k as f32, 0.0)?.spawn(w)?;
            Ok(())
        },
        observed_positions,
        &settings(),
        Reference::exact(move |t| {
            let i = ((t / f64::from(1.0f32 / 60.0)).round() as usize).clamp(1, reference.len());
            reference[i - 1].clone()
        }),
        sweep_cfg,
    )?;
    Ok(Problem::new(
        "large-angle pendulum (90°)",
        measure,
        "converged f64 RK4 of the same elastic pendulum",
        l,
        report,
    ))
}

#[derive(Component)]
struct Orbiting;

/// GM = 4π² m³/s²: a 1 m orbit takes 1 s.
const GM: f32 = (std::f64::consts::TAU * std::f64::consts::TAU) as f32;

fn attract(mut q: Query<(&Position, &mut hooke::particles::Force), With<Orbiting>>) {
    for (x, mut f) in &mut q {
        let r = x.0;
        let d = r.length();
        f.0 -= GM * r / (d * d * d);
    }
}

/// The orbit from perihelion (0.5 m, e = 0.5, a = 1 m: T = 1 s).
fn orbit(w: &mut World) -> hooke::Result<()> {
    base(w, Vec3::ZERO)?;
    let vp = TAU * 3f64.sqrt();
    w.spawn((
        ParticleBundle::new(
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, vp as f32, 0.0),
            1.0,
        )?,
        Observed,
        Orbiting,
    ));
    add_force_systems(w, || attract.in_set(ForceSystems::User));
    Ok(())
}

pub fn kepler(quick: bool) -> hooke::Result<Problem> {
    let e = 0.5f64;
    let report = sweep(
        orbit,
        observed_positions,
        &settings(),
        Reference::exact(move |t| {
            // Kepler's equation M = E − e sin E, by Newton's method.
            let m = TAU * t;
            let mut big_e = m;
            for _ in 0..50 {
                big_e -= (big_e - e * big_e.sin() - m) / (1.0 - e * big_e.cos());
            }
            let b = (1.0 - e * e).sqrt();
            vec![big_e.cos() - e, b * big_e.sin(), 0.0]
        }),
        Sweep::seconds(2.3).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "Kepler orbit (e = 0.5)",
        "max position error over 2.3 orbits (phase, shape and precession), per 1 m semi-major axis",
        "closed form (Kepler's equation)",
        1.0,
        report,
    ))
}

/// The same orbit's specific energy v²/2 − GM/r against −GM/(2a).
pub fn kepler_energy(quick: bool) -> hooke::Result<Problem> {
    let energy = -f64::from(GM) / 2.0;
    let report = sweep(
        orbit,
        |w: &mut World| {
            let mut q = w.query_filtered::<(&Position, &LinearVelocity), With<Observed>>();
            q.iter(w)
                .map(|(x, v)| {
                    let (x, v) = (x.get().as_dvec3(), v.get().as_dvec3());
                    (0.5 * v.length_squared() - f64::from(GM) / x.length()) as f32
                })
                .collect()
        },
        &settings(),
        Reference::exact(move |_| vec![energy]),
        Sweep::seconds(2.3).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "Kepler orbit: energy",
        "max |E − E₀| over 2.3 orbits, per |E₀| = 2π² J/kg",
        "closed form (E₀ = −GM/2a)",
        -energy,
        report,
    ))
}

/// The torque-free body's body axes in the world, by f64 RK4 of q̇ = ½ ω q with
/// ω = R I⁻¹ Rᵀ L (L fixed), 1,000 substeps per step.
fn tumbler_reference(i: DVec3, omega0: DVec3, dt: f64, steps: u32) -> Vec<Vec<f64>> {
    let l = i * omega0; // body frame = world frame at t = 0
    let rate = |q: DQuat| {
        let wb = (q.inverse() * l) / i;
        let w = q * wb;
        DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * q * 0.5
    };
    let mut q = DQuat::IDENTITY;
    let per = 1000u32;
    let h = dt / f64::from(per);
    let mut out = Vec::new();
    for _ in 0..steps {
        for _ in 0..per {
            let k1 = rate(q);
            let k2 = rate(q + k1 * (0.5 * h));
            let k3 = rate(q + k2 * (0.5 * h));
            let k4 = rate(q + k3 * h);
            q = (q + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)).normalize();
        }
        out.push(axes(q.x, q.y, q.z, q.w));
    }
    out
}

fn axes(x: f64, y: f64, z: f64, w: f64) -> Vec<f64> {
    let q = DQuat::from_xyzw(x, y, z, w);
    [DVec3::X, DVec3::Y]
        .iter()
        .flat_map(|&a| (q * a).to_array())
        .collect()
}

/// The torque-free body swept at `settings` with orientation update `update`.
fn tumbler_sweep(
    update: OrientationUpdate,
    settings: &[Setting],
    quick: bool,
) -> hooke::Result<SweepReport> {
    // I = diag(1, 2, 3), spun mostly about the major axis: a stable, nutating tumble.
    let omega0 = DVec3::new(0.4, 0.2, 3.0);
    let sweep_cfg = Sweep::seconds(5.0).with_timing_runs(runs(quick));
    let reference = tumbler_reference(
        DVec3::new(1.0, 2.0, 3.0),
        omega0,
        f64::from(sweep_cfg.dt),
        sweep_cfg.steps,
    );
    sweep(
        move |w: &mut World| {
            base(w, Vec3::ZERO)?;
            w.insert_resource(update);
            let props = MassProperties::new(1.0, Vec3::ZERO, Inertia::diagonal(1.0, 2.0, 3.0)?)?;
            w.spawn((
                RigidBodyBundle::dynamic(props)?.with_angular_velocity(omega0.as_vec3())?,
                Observed,
            ));
            Ok(())
        },
        |w: &mut World| {
            let mut q = w.query_filtered::<&Rotation, With<Observed>>();
            let r = q.single(w).map(|r| r.0).unwrap_or(Quat::NAN);
            let v = axes(
                f64::from(r.x),
                f64::from(r.y),
                f64::from(r.z),
                f64::from(r.w),
            );
            v.into_iter().map(|x| x as f32).collect()
        },
        settings,
        Reference::exact(move |t| {
            let i = ((t * 60.0).round() as usize).clamp(1, reference.len());
            reference[i - 1].clone()
        }),
        sweep_cfg,
    )
}

const TUMBLER: &str = "max error of the body's x and y axes over 5 s (unit vectors: about radians)";
const TUMBLER_REFERENCE: &str = "converged f64 RK4 of the quaternion ODE";

pub fn torque_free(quick: bool) -> hooke::Result<Problem> {
    let report = tumbler_sweep(OrientationUpdate::default(), &settings(), quick)?;
    Ok(Problem::new(
        "torque-free body, I = diag(1, 2, 3)",
        TUMBLER,
        TUMBLER_REFERENCE,
        1.0,
        report,
    ))
}

/// The same body under each orientation update, with the two integrators that use them
/// differently (Lie–Trotter for symplectic Euler, Strang for Verlet).
pub fn orientation_updates(quick: bool) -> hooke::Result<Problem> {
    let settings = Setting::grid(
        &[Integrator::SymplecticEuler, Integrator::VelocityVerlet],
        &[1, 2, 4, 8],
    );
    let (mut measurements, mut names) = (Vec::new(), Vec::new());
    for update in [
        OrientationUpdate::Splitting,
        OrientationUpdate::ExpMap,
        OrientationUpdate::FirstOrder,
    ] {
        let report = tumbler_sweep(update, &settings, quick)?;
        for m in report.measurements {
            let short = match m.setting.integrator {
                Integrator::SymplecticEuler => "SE",
                _ => "VV",
            };
            names.push((
                format!("{update:?}"),
                format!("{short}×{}", m.setting.substeps),
            ));
            measurements.push(m);
        }
    }
    let mut p = Problem::new(
        "torque-free body: orientation updates",
        TUMBLER,
        TUMBLER_REFERENCE,
        1.0,
        SweepReport {
            measurements,
            reference_seconds_per_step: None,
        },
    );
    p.default = names
        .iter()
        .position(|(s, l)| s == "Splitting" && l == "SE×4");
    p.names = Some(names);
    Ok(p)
}

fn rope(world: &mut World) -> hooke::Result<()> {
    base(world, Vec3::new(0.0, -G, 0.0))?;
    // 2 m, 21 nodes of 50 g on 5e3 N/m springs, pinned at one end, released level: ω h
    // at the top mode is about 2.6 at 4 substeps, past every explicit integrator's limit.
    let chain = ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(2.0, 2.0, 0.0), 21)
        .node_mass(0.05)
        .stiffness(5.0e3)
        .damping(0.0)
        .spawn(world)?;
    for &n in &chain.nodes {
        world.entity_mut(n).insert(Observed);
    }
    Ok(())
}

pub fn stiff_chain(quick: bool) -> hooke::Result<Problem> {
    let report = sweep(
        rope,
        observed_positions,
        &stiff_settings(),
        Reference::Converged(Setting::new(Integrator::Rk4, 64)),
        Sweep::seconds(1.5).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "stiff chain swinging (5e3 N/m, 50 g nodes)",
        "max node position error over 1.5 s, per 2 m length",
        "the same chain at RK4 ×64 (converged)",
        2.0,
        report,
    ))
}

/// A rope between two pins, damped to rest: the lowest point's sag against the catenary.
pub fn catenary(quick: bool) -> hooke::Result<Problem> {
    let (span, length, count, k) = (2.0f32, 2.5f32, 41usize, 1.0e5f32);
    let build = move |w: &mut World| -> hooke::Result<()> {
        base(w, Vec3::new(0.0, -G, 0.0))?;
        let chain = ChainBuilder::rope(Vec3::new(-1.0, 3.0, 0.0), Vec3::new(1.0, 3.0, 0.0), count)
            .node_mass(0.05)
            .stiffness(k)
            .damping(0.0)
            .pin_end(true)
            .rest_scale(length / span)
            .spawn(w)?;
        for &n in &chain.nodes {
            w.entity_mut(n).insert((Observed, LinearDamping(2.0)));
        }
        Ok(())
    };
    let a = scenes::catenary_parameter(f64::from(span), f64::from(length));
    let sag = a * ((f64::from(span) / (2.0 * a)).cosh() - 1.0);
    let steps = 900;
    let mut measurements = Vec::new();
    for setting in settings() {
        let mut lowest = f32::INFINITY;
        let mut times = Vec::new();
        let mut quarantined = false;
        for run in 0..runs(quick) {
            let (spent, q) = timed_run(setting, 1.0 / 60.0, steps, &build, |w, step| {
                if run == 0 && step == steps {
                    lowest = observed_positions(w).chunks(3).map(|p| p[1]).fold(
                        f32::INFINITY,
                        |a, b| if b.is_nan() { f32::NAN } else { a.min(b) },
                    );
                }
            })?;
            quarantined |= q;
            times.push(spent.as_secs_f64() / f64::from(steps));
        }
        times.sort_by(f64::total_cmp);
        let error = (3.0 - f64::from(lowest) - sag).abs();
        measurements.push(Measurement {
            setting,
            error: if quarantined || !error.is_finite() {
                f64::INFINITY
            } else {
                error
            },
            seconds_per_step: times[times.len() / 2],
            quarantined,
        });
    }
    let measure: &'static str = Box::leak(
        format!("|sag − catenary sag| after 15 s of damped settling, per the sag ({sag:.3} m; 1e5 N/m springs)")
            .into_boxed_str(),
    );
    Ok(Problem::new(
        "hanging rope at rest (catenary)",
        measure,
        "closed form (catenary, L = 2a sinh(S/2a))",
        sag,
        SweepReport {
            measurements,
            reference_seconds_per_step: None,
        },
    ))
}

pub fn cloth(quick: bool) -> hooke::Result<Problem> {
    let build = |w: &mut World| -> hooke::Result<()> {
        base(w, Vec3::new(0.0, -G, 0.0))?;
        scenes::cloth(w, 16)?;
        Ok(())
    };
    let nodes = |w: &mut World| -> Vec<f32> {
        let mut q = w.query::<&Nodes>();
        q.iter(w)
            .flat_map(|n| {
                n.positions()
                    .iter()
                    .flat_map(|p| p.to_array())
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let report = sweep(
        build,
        nodes,
        &stiff_settings(),
        Reference::Converged(Setting::new(Integrator::Rk4, 32)),
        Sweep::seconds(1.5).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "hanging cloth 16×16 (ClothBuilder defaults)",
        "max node position error over 1.5 s, per 1 m side",
        "the same cloth at RK4 ×32 (converged)",
        1.0,
        report,
    ))
}

pub fn bouncing_ball(quick: bool) -> hooke::Result<Problem> {
    let (r, h0, e) = (0.1f32, 1.0f64, 0.8f64);
    let build = move |w: &mut World| -> hooke::Result<()> {
        base(w, Vec3::new(0.0, -G, 0.0))?;
        let ground = scenes::ground(w)?;
        w.entity_mut(ground).insert(Restitution(e as f32));
        let ball = scenes::dynamic_ball(w, r, Vec3::new(0.0, h0 as f32 + r, 0.0))?;
        w.entity_mut(ball).insert((Restitution(e as f32), Observed));
        Ok(())
    };
    // The first three apexes against e^(2k) h₀ (0.64, 0.41, 0.26 m); 2.6 s holds them.
    let steps = 156;
    let mut measurements = Vec::new();
    for setting in settings() {
        let mut times = Vec::new();
        let (mut apexes, mut rising, mut top) = (Vec::new(), false, f32::MIN);
        let mut quarantined = false;
        for run in 0..runs(quick) {
            let (spent, q) = timed_run(setting, 1.0 / 60.0, steps, &build, |w, _| {
                if run > 0 {
                    return;
                }
                let mut q = w.query_filtered::<(&Position, &LinearVelocity), With<Observed>>();
                let Ok((x, v)) = q.single(w) else { return };
                let (y, vy) = (x.get().y - r, v.get().y);
                if vy > 0.0 {
                    rising = true;
                    top = top.max(y);
                } else if rising {
                    apexes.push(f64::from(top.max(y)));
                    (rising, top) = (false, f32::MIN);
                }
            })?;
            quarantined |= q;
            times.push(spent.as_secs_f64() / f64::from(steps));
        }
        times.sort_by(f64::total_cmp);
        let error = if apexes.len() < 3 {
            f64::INFINITY
        } else {
            (1..=3)
                .map(|k| (apexes[k - 1] - e.powi(2 * k as i32) * h0).abs())
                .fold(0.0, f64::max)
        };
        measurements.push(Measurement {
            setting,
            error: if quarantined { f64::INFINITY } else { error },
            seconds_per_step: times[times.len() / 2],
            quarantined,
        });
    }
    Ok(Problem::new(
        "bouncing ball (e = 0.8, from 1 m)",
        "max |apex_k − e^(2k) h₀| over the first 3 bounces, per 1 m drop (sampled once per step)",
        "closed form (apexes e^(2k) h₀)",
        h0,
        SweepReport {
            measurements,
            reference_seconds_per_step: None,
        },
    ))
}

pub fn incline(quick: bool) -> hooke::Result<Problem> {
    let angle = 30f32.to_radians();
    let mu = 0.3f32;
    let a = f64::from(G * (angle.sin() - mu * angle.cos()));
    let q = Quat::from_rotation_z(angle);
    let down = q * Vec3::NEG_X;
    let start = q * Vec3::Y * 0.75 + q * Vec3::new(5.0, 0.0, 0.0);
    let seconds = 2.0f64;
    let report = sweep(
        move |w: &mut World| {
            base(w, Vec3::new(0.0, -G, 0.0))?;
            w.spawn((
                RigidBodyBundle::fixed(Vec3::ZERO, q)?,
                Collider::cuboid(20.0, 0.5, 5.0)?,
                Friction(mu),
            ));
            let b = scenes::dynamic_box(w, Vec3::new(0.5, 0.25, 0.5), start)?;
            w.entity_mut(b)
                .insert((Friction(mu), Rotation(q), Observed));
            Ok(())
        },
        move |w: &mut World| {
            let p = observed_positions(w);
            vec![(Vec3::new(p[0], p[1], p[2]) - start).dot(down)]
        },
        &settings(),
        Reference::exact(move |t| vec![0.5 * a * t * t]),
        Sweep::steps(1.0 / 60.0, (seconds * 60.0) as u32).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "box sliding on a 30° incline (μ = 0.3)",
        "max |s − a t²/2| over 2 s, per the 4.71 m slid",
        "closed form, a = g(sin θ − μ cos θ)",
        0.5 * a * seconds * seconds,
        report,
    ))
}

/// The nodes of the soft bar's bottom face.
#[derive(Component)]
struct BottomFace(Vec<usize>);

/// A 1 m soft bar (E = 1e6 Pa, ν = 0, ρ = 1000 kg/m³, 2×20×2 cells) hanging from pins,
/// released unstretched: it swings about its static elongation ρ g L² / (2E) = 4.905 mm at
/// its first axial mode (ω = (π/2) √(E/ρ) / L = 49.7 rad/s, 7.9 Hz). Explicitly it needs 26
/// substeps at 60 Hz (the bound is safe, about 2× the true limit); past it the policy rescues.
pub fn soft_bar(quick: bool) -> hooke::Result<Problem> {
    use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
    let build = |w: &mut World| -> hooke::Result<()> {
        base(w, Vec3::new(0.0, -G, 0.0))?;
        let mesh = TetMesh::cuboid(Vec3::new(0.1, 1.0, 0.1), [2, 20, 2], CellSplit::Six)?;
        let material = Material::new(1e6, 0.0, 1000.0)?;
        let (mut nodes, body) = SoftBody::build(
            &mesh,
            Vec3::new(0.0, -0.5, 0.0),
            material,
            StrainModel::Corotated,
        )?;
        let mut face = Vec::new();
        for i in 0..nodes.len() {
            let y = nodes.positions()[i].y;
            if y.abs() < 1e-5 {
                nodes.pin(i)?;
            }
            if (y + 1.0).abs() < 1e-5 {
                face.push(i);
            }
        }
        w.spawn((nodes, body, BottomFace(face)));
        Ok(())
    };
    // The bottom face's mean height.
    let bottom = |w: &mut World| -> Vec<f32> {
        let mut q = w.query::<(&Nodes, &BottomFace)>();
        let Some((n, face)) = q.iter(w).next() else {
            return vec![f32::NAN];
        };
        let sum: f32 = face.0.iter().map(|&i| n.positions()[i].y).sum();
        vec![sum / face.0.len().max(1) as f32]
    };
    let report = sweep(
        build,
        bottom,
        &stiff_settings(),
        Reference::Converged(Setting::new(Integrator::SymplecticEuler, 128)),
        Sweep::seconds(1.0).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "soft bar hanging (E = 1e6 Pa, 480 tets)",
        "max error of the bottom's height over 1 s, per its 4.9 mm stretch",
        "the same bar, symplectic Euler ×128 (converged)",
        4.905e-3,
        report,
    ))
}
