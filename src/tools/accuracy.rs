//! What accuracy costs in time, measured on your own scene.
//!
//! [`sweep`] builds a scene once per [`Setting`] (an integrator and a substep count), steps it
//! for a fixed number of steps, records what `observe` reads after every step, and compares
//! that trace with a reference: a closed form ([`Reference::Exact`]) or the same scene run at
//! a setting fine enough to be taken as converged ([`Reference::Converged`]). Each setting
//! gets
//!
//! ```text
//! error = max over steps k, over observed values i, of |observed_i(t_k) − reference_i(t_k)|
//! ```
//!
//! in the units of what `observe` returns, and its wall-clock time per step (the median of
//! [`Sweep::timing_runs`] runs; `observe` is not timed). [`SweepReport::cheapest_within`]
//! then answers "what is the cheapest setting that stays within my tolerance?".
//!
//! ```no_run
//! use bevy_ecs::prelude::*;
//! use hooke::tools::accuracy::{sweep, Reference, Setting, Sweep};
//! use hooke::prelude::*;
//!
//! # fn main() -> hooke::Result<()> {
//! // How many substeps does my rope need to stay within 1 cm of the converged answer?
//! let build = |world: &mut World| -> hooke::Result<()> {
//!     world.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0))?);
//!     ChainBuilder::rope(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), 21).spawn(world)?;
//!     Ok(())
//! };
//! let tip = |world: &mut World| -> Vec<f32> {
//!     let mut q = world.query::<&Position>();
//!     q.iter(world).flat_map(|p| p.get().to_array()).collect()
//! };
//! let settings = Setting::grid(&Integrator::ALL, &[1, 2, 4, 8]);
//! let report = sweep(
//!     build,
//!     tip,
//!     &settings,
//!     Reference::Converged(Setting::new(Integrator::Rk4, 64)),
//!     Sweep::seconds(2.0),
//! )?;
//! if let Some(best) = report.cheapest_within(0.01) {
//!     println!("{}: {:.2e} m, {:.1} µs per step", best.setting, best.error, best.seconds_per_step * 1e6);
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Every setting's world is a fresh `World` with [`crate::plugins::PhysicsPlugins`], a
//! [`PhysicsTime`] of [`Sweep::dt`] split into the setting's substeps, and the setting's
//! [`Integrator`] resource; `build` adds the scene (and may change any resource, gravity
//! included). A run that turns non-finite, or whose bodies are quarantined, reports
//! `error = ∞` and says which.

use std::time::{Duration, Instant};

use bevy_ecs::prelude::*;

use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::error::{Error, Result};
use crate::core::time::PhysicsTime;
use crate::integrator::{ImplicitScheme, Integrator, StabilityPolicy};
use crate::plugins::PhysicsPlugins;
use crate::plugins::PhysicsWorldExt;

/// One point on the dial: an integrator and the substeps per fixed step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Setting {
    /// The [`Integrator`] resource of the run.
    pub integrator: Integrator,
    /// Substeps per fixed step (≥ 1).
    pub substeps: u32,
    /// The [`StabilityPolicy`] of the run: [`StabilityPolicy::Warn`] keeps every system on
    /// `integrator` (the dial as it is); the default policy is
    /// [`StabilityPolicy::Automatic`].
    pub policy: StabilityPolicy,
}

impl Setting {
    /// hooke's defaults: symplectic Euler with 4 substeps ([`PhysicsTime::default`]), and the
    /// default [`StabilityPolicy`] ([`StabilityPolicy::Automatic`]: local substeps or BDF2 for
    /// what is past its limit).
    pub const DEFAULT: Setting =
        Setting::new(Integrator::SymplecticEuler, 4).with_policy(StabilityPolicy::Automatic);

    /// A setting of the dial: every system stays on `integrator`.
    #[must_use]
    pub const fn new(integrator: Integrator, substeps: u32) -> Self {
        Self {
            integrator,
            substeps,
            policy: StabilityPolicy::Warn,
        }
    }

    /// The same setting under stability policy `policy`.
    #[must_use]
    pub const fn with_policy(mut self, policy: StabilityPolicy) -> Self {
        self.policy = policy;
        self
    }

    /// The same setting with the stability policy switching what is past its limit to
    /// `scheme` ([`StabilityPolicy::SwitchToImplicit`]).
    #[must_use]
    pub const fn with_rescue(self, scheme: ImplicitScheme) -> Self {
        self.with_policy(StabilityPolicy::SwitchToImplicit(scheme))
    }

    /// The series name of the setting: the integrator, then the policy's rescue
    /// (`symplectic_euler+bdf2`, `symplectic_euler+automatic`).
    #[must_use]
    pub fn series(&self) -> String {
        match self.policy {
            StabilityPolicy::Warn => self.integrator.name().to_string(),
            StabilityPolicy::SwitchToImplicit(s) => {
                format!("{}+{}", self.integrator.name(), s.name())
            }
            StabilityPolicy::Automatic => format!("{}+automatic", self.integrator.name()),
        }
    }

    /// Every integrator with every substep count, integrator by integrator.
    #[must_use]
    pub fn grid(integrators: &[Integrator], substeps: &[u32]) -> Vec<Setting> {
        integrators
            .iter()
            .flat_map(|&i| substeps.iter().map(move |&s| Setting::new(i, s)))
            .collect()
    }
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ×{}", self.series(), self.substeps)
    }
}

/// What a sweep's errors are measured against.
pub enum Reference {
    /// A closed form: the values `observe` should read at time t (s) after the start.
    Exact(Box<dyn Fn(f64) -> Vec<f64>>),
    /// The same scene run at this setting, taken as converged (f32, like every run).
    Converged(Setting),
}

impl Reference {
    /// [`Reference::Exact`] from a closure.
    #[must_use]
    pub fn exact(f: impl Fn(f64) -> Vec<f64> + 'static) -> Self {
        Self::Exact(Box::new(f))
    }
}

/// How long each run lasts and how it is timed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// The fixed step (s; default 1/60).
    pub dt: f32,
    /// Steps per run.
    pub steps: u32,
    /// Runs per setting whose median time is reported (default 3; the first run also gives
    /// the error, and every run gives the same trace).
    pub timing_runs: u32,
}

impl Sweep {
    /// `seconds` of simulated time at 60 Hz, three timing runs.
    #[must_use]
    pub fn seconds(seconds: f32) -> Self {
        let dt = 1.0 / 60.0;
        Self {
            dt,
            steps: (seconds / dt).round().max(1.0) as u32,
            timing_runs: 3,
        }
    }

    /// `steps` steps of `dt` seconds, three timing runs.
    #[must_use]
    pub fn steps(dt: f32, steps: u32) -> Self {
        Self {
            dt,
            steps,
            timing_runs: 3,
        }
    }

    /// The same, with `runs` timing runs (at least one).
    #[must_use]
    pub fn with_timing_runs(self, runs: u32) -> Self {
        Self {
            timing_runs: runs.max(1),
            ..self
        }
    }
}

/// One setting's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// The setting.
    pub setting: Setting,
    /// Largest deviation from the reference over the run, in `observe`'s units (∞ when the
    /// run turned non-finite or was quarantined).
    pub error: f64,
    /// Wall-clock time per fixed step (s), the median over the timing runs.
    pub seconds_per_step: f64,
    /// Bodies were quarantined during the run (their state went non-finite or exploded).
    pub quarantined: bool,
}

impl Measurement {
    /// The run stayed finite and nothing was quarantined.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.error.is_finite()
    }
}

/// Every setting's error and time.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepReport {
    /// In the order the settings were given.
    pub measurements: Vec<Measurement>,
    /// The converged reference's own time per step, when the reference was a run.
    pub reference_seconds_per_step: Option<f64>,
}

impl SweepReport {
    /// The fastest setting whose error is at most `tolerance` (ties: the first given).
    #[must_use]
    pub fn cheapest_within(&self, tolerance: f64) -> Option<&Measurement> {
        self.measurements
            .iter()
            .filter(|m| m.error <= tolerance)
            .fold(None, |best: Option<&Measurement>, m| match best {
                Some(b) if b.seconds_per_step <= m.seconds_per_step => Some(b),
                _ => Some(m),
            })
    }

    /// The measurement of `setting`, if it was swept.
    #[must_use]
    pub fn get(&self, setting: Setting) -> Option<&Measurement> {
        self.measurements.iter().find(|m| m.setting == setting)
    }

    /// The Pareto front: the finite settings that no other setting beats on both error and
    /// time, fastest first.
    #[must_use]
    pub fn pareto(&self) -> Vec<&Measurement> {
        let mut finite: Vec<&Measurement> =
            self.measurements.iter().filter(|m| m.is_finite()).collect();
        finite.sort_by(|a, b| {
            a.seconds_per_step
                .total_cmp(&b.seconds_per_step)
                .then(a.error.total_cmp(&b.error))
        });
        let mut front: Vec<&Measurement> = Vec::new();
        for m in finite {
            if front.last().is_none_or(|last| m.error < last.error) {
                front.push(m);
            }
        }
        front
    }
}

/// A fresh world for `setting`: [`PhysicsPlugins`], the step split into the setting's
/// substeps, the setting's integrator.
///
/// # Errors
/// [`Error::InvalidTimeStep`] for a bad `dt`, [`Error::ZeroSubsteps`] for zero substeps.
pub fn world_for(setting: Setting, dt: f32) -> Result<World> {
    let mut world = World::new();
    world.insert_resource(PhysicsTime::new(dt, setting.substeps)?);
    world.add_physics(PhysicsPlugins);
    world.insert_resource(setting.integrator);
    world.insert_resource(setting.policy);
    Ok(world)
}

/// Builds the scene at `setting`, runs `steps` steps of `dt` and calls `record` after each
/// (not timed). Returns the time spent stepping and whether anything was quarantined.
///
/// # Errors
/// As [`world_for`] and `build`.
pub fn timed_run(
    setting: Setting,
    dt: f32,
    steps: u32,
    build: &impl Fn(&mut World) -> Result<()>,
    mut record: impl FnMut(&mut World, u32),
) -> Result<(Duration, bool)> {
    let mut world = world_for(setting, dt)?;
    build(&mut world)?;
    let mut spent = Duration::ZERO;
    for k in 1..=steps {
        let t0 = Instant::now();
        world.step_physics();
        spent += t0.elapsed();
        record(&mut world, k);
    }
    let quarantined = world
        .get_resource::<PhysicsDiagnostics>()
        .is_some_and(|d| d.quarantined_total > 0);
    Ok((spent, quarantined))
}

/// Runs the scene at every setting and measures each against `reference` (see the module
/// docs).
///
/// # Errors
/// [`Error::TooFew`] for no settings or zero steps; [`Error::InvalidTimeStep`] for a bad
/// `dt`, [`Error::ZeroSubsteps`] for a setting with zero substeps; whatever `build` returns.
pub fn sweep(
    build: impl Fn(&mut World) -> Result<()>,
    observe: impl Fn(&mut World) -> Vec<f32>,
    settings: &[Setting],
    reference: Reference,
    sweep: Sweep,
) -> Result<SweepReport> {
    if settings.is_empty() || sweep.steps == 0 {
        return Err(Error::TooFew {
            what: "settings and steps in an accuracy sweep",
            min: 1,
            got: settings.len().min(sweep.steps as usize),
        });
    }
    let (dt, steps) = (sweep.dt, sweep.steps);
    let mut reference_seconds_per_step = None;
    let expected: Box<dyn Fn(u32) -> Vec<f64>> = match reference {
        Reference::Exact(f) => Box::new(move |k| f(f64::from(k) * f64::from(dt))),
        Reference::Converged(setting) => {
            let mut trace = Vec::with_capacity(steps as usize);
            let (spent, _) = timed_run(setting, dt, steps, &build, |w, _| {
                trace.push(observe(w).into_iter().map(f64::from).collect::<Vec<_>>());
            })?;
            reference_seconds_per_step = Some(spent.as_secs_f64() / f64::from(steps));
            Box::new(move |k| trace[(k - 1) as usize].clone())
        }
    };
    let mut measurements = Vec::with_capacity(settings.len());
    for &setting in settings {
        let mut error = 0.0f64;
        let (first, quarantined) = timed_run(setting, dt, steps, &build, |w, k| {
            let seen = observe(w);
            let want = expected(k);
            let worst = seen
                .iter()
                .zip(&want)
                .map(|(&s, &e)| (f64::from(s) - e).abs())
                .fold(
                    0.0f64,
                    |a, b| if b.is_nan() { f64::INFINITY } else { a.max(b) },
                );
            let worst = if seen.len() == want.len() {
                worst
            } else {
                f64::INFINITY
            };
            error = error.max(worst);
        })?;
        let mut times = vec![first];
        for _ in 1..sweep.timing_runs {
            times.push(timed_run(setting, dt, steps, &build, |_, _| {})?.0);
        }
        times.sort();
        let median = times[times.len() / 2];
        measurements.push(Measurement {
            setting,
            error: if quarantined { f64::INFINITY } else { error },
            seconds_per_step: median.as_secs_f64() / f64::from(steps),
            quarantined,
        });
    }
    Ok(SweepReport {
        measurements,
        reference_seconds_per_step,
    })
}

/// The order p of convergence between two errors at substep counts `coarse` < `fine`:
/// error ∝ hᵖ gives p = log(e_coarse / e_fine) / log(fine / coarse).
#[must_use]
pub fn order(coarse: (u32, f64), fine: (u32, f64)) -> f64 {
    (coarse.1 / fine.1).ln() / (f64::from(fine.0) / f64::from(coarse.0)).ln()
}
