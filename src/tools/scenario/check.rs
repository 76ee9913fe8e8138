//! Checking expectations: each reads the world at the steps of its window, keeps its first
//! failure, or else the reading closest to failing, and is finished into an [`Outcome`].

use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};

use super::Expectation;
use super::format::{Check, Quantity};
use super::report::Outcome;
use super::select::{Names, group};
use crate::collision::Contacts;
use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::quarantine::Quarantined;
use crate::core::rest::Sleeping;
use crate::particles::LinearVelocity;
use crate::particles::Mass;
use crate::particles::Nodes;
use crate::particles::Position;
use crate::rigid::AngularVelocity;

/// Position, velocity and angular velocity of one entity (m, m/s, rad/s), in f64.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Kin {
    pub x: DVec3,
    pub v: DVec3,
    pub w: DVec3,
}

type KinData = (
    Option<&'static Nodes>,
    Option<&'static Position>,
    Option<&'static LinearVelocity>,
    Option<&'static AngularVelocity>,
);

/// Reads entities' motion through one cached query: the checks read every member of a
/// group at every step, and a query's lookup is a few times cheaper than `World::get` per
/// component.
pub(super) struct Probe(QueryState<KinData>);

impl Probe {
    pub(super) fn new(world: &mut World) -> Self {
        Self(world.query::<KinData>())
    }

    /// Sees archetypes created since (spawns, inserted components).
    pub(super) fn refresh(&mut self, world: &World) {
        self.0.update_archetypes(world);
    }

    /// An entity's motion: its own, or for a mesh the mean of its nodes.
    pub(super) fn get(&self, world: &World, e: Entity) -> Option<Kin> {
        let (nodes, x, v, w) = self.0.get_manual(world, e).ok()?;
        if let Some(nodes) = nodes {
            let n = nodes.len();
            if n == 0 {
                return None;
            }
            let mean = |s: &[glam::Vec3A]| {
                s.iter().map(|p| Vec3::from(*p).as_dvec3()).sum::<DVec3>() / n as f64
            };
            return Some(Kin {
                x: mean(nodes.positions()),
                v: mean(nodes.velocities()),
                w: DVec3::ZERO,
            });
        }
        Some(Kin {
            x: x?.get().as_dvec3(),
            v: v.map_or(DVec3::ZERO, |v| v.get().as_dvec3()),
            w: w.map_or(DVec3::ZERO, |w| w.get().as_dvec3()),
        })
    }
}

fn quantity(k: &Kin, q: Quantity) -> f64 {
    match q {
        Quantity::X => k.x.x,
        Quantity::Y => k.x.y,
        Quantity::Z => k.x.z,
        Quantity::Speed => k.v.length(),
        Quantity::Vx => k.v.x,
        Quantity::Vy => k.v.y,
        Quantity::Vz => k.v.z,
        Quantity::AngularSpeed => k.w.length(),
    }
}

fn unit(q: Quantity) -> &'static str {
    match q {
        Quantity::X | Quantity::Y | Quantity::Z => "m",
        Quantity::Speed | Quantity::Vx | Quantity::Vy | Quantity::Vz => "m/s",
        Quantity::AngularSpeed => "rad/s",
    }
}

fn name(q: Quantity) -> &'static str {
    match q {
        Quantity::X => "x",
        Quantity::Y => "y",
        Quantity::Z => "z",
        Quantity::Speed => "speed",
        Quantity::Vx => "vx",
        Quantity::Vy => "vy",
        Quantity::Vz => "vz",
        Quantity::AngularSpeed => "angular speed",
    }
}

/// One reading: held or not, how close to failing (larger is closer), and what to print.
#[derive(Debug, Clone)]
struct Sample {
    ok: bool,
    closeness: f64,
    text: Reading,
}

/// What to print, formatted only when it is kept.
#[derive(Debug, Clone)]
enum Reading {
    Value(&'static str, f64, &'static str),
    Axes([Option<f64>; 3]),
    Energy(f64, f64),
    Momentum(f64, f64),
    Closed(Quantity, f64, f64),
    Missing(String),
    Text(String),
    Fixed(&'static str),
    Asleep(usize, usize),
}

impl Reading {
    fn show(&self) -> String {
        match self {
            Reading::Value(what, v, unit) => format!("{what} = {v:.6} {unit}"),
            Reading::Axes(a) => {
                let parts: Vec<String> = ["x", "y", "z"]
                    .iter()
                    .zip(a)
                    .filter_map(|(n, v)| v.map(|v| format!("{n} = {v:.6}")))
                    .collect();
                format!("{} m", parts.join(", "))
            }
            Reading::Energy(dev, e0) => format!("E - E0 = {dev:+.6} J (E0 = {e0:.6} J)"),
            Reading::Momentum(dev, p0) => format!("|P - P0| = {dev:.6} kg m/s (|P0| = {p0:.6})"),
            Reading::Closed(q, v, want) => format!(
                "{} = {v:.6} {u}, closed form {want:.6} {u} (off by {:+.2e})",
                name(*q),
                v - want,
                u = unit(*q)
            ),
            Reading::Missing(who) => format!("{who} is gone"),
            Reading::Text(t) => t.clone(),
            Reading::Fixed(t) => (*t).to_owned(),
            Reading::Asleep(n, of) => format!("{n} of {of} asleep"),
        }
    }
}

/// What an expectation has seen so far.
#[derive(Debug, Default)]
pub(super) struct Track {
    failed: Option<(f64, Reading)>,
    closest: Option<(f64, f64, Reading)>,
    base: Option<DVec3>,
    peak: Option<(f64, f64)>,
    seen: Option<(f64, String)>,
}

impl Track {
    fn record(&mut self, t: f64, s: Sample) {
        if self.failed.is_some() {
            return;
        }
        if !s.ok {
            self.failed = Some((t, s.text));
        } else if self.closest.as_ref().is_none_or(|c| s.closeness >= c.0) {
            self.closest = Some((s.closeness, t, s.text));
        }
    }
}

/// How close `v` is to leaving `[min, max]`: minus the margin to the nearer bound.
fn bounded(v: f64, min: Option<f64>, max: Option<f64>) -> (bool, f64) {
    let lo = min.map_or(f64::INFINITY, |m| v - m);
    let hi = max.map_or(f64::INFINITY, |m| m - v);
    let margin = lo.min(hi);
    (margin >= 0.0, -margin)
}

/// A value against optional bounds (given in f32, as the file's fields are).
fn sample(
    v: f64,
    min: Option<f32>,
    max: Option<f32>,
    what: &'static str,
    unit: &'static str,
) -> Sample {
    let (ok, closeness) = bounded(v, min.map(f64::from), max.map(f64::from));
    Sample {
        ok,
        closeness,
        text: Reading::Value(what, v, unit),
    }
}

/// Reads each member; keeps the one closest to failing. An empty group is a failure.
fn each(
    world: &World,
    probe: &Probe,
    group: &[Entity],
    who: &str,
    mut read: impl FnMut(&Kin) -> Sample,
) -> Sample {
    let mut worst: Option<Sample> = None;
    for &e in group {
        let s = match probe.get(world, e) {
            Some(k) => read(&k),
            None => Sample {
                ok: false,
                closeness: f64::INFINITY,
                text: Reading::Missing(format!("{who} ({e})")),
            },
        };
        let replace = worst
            .as_ref()
            .is_none_or(|w| (w.ok && !s.ok) || (w.ok == s.ok && s.closeness > w.closeness));
        if replace {
            worst = Some(s);
        }
    }
    worst.unwrap_or(Sample {
        ok: false,
        closeness: f64::INFINITY,
        text: Reading::Missing(who.to_owned()),
    })
}

fn touching(world: &World, names: &Names, a: &str, b: &str) -> bool {
    let Some(contacts) = world.get_resource::<Contacts>() else {
        return false;
    };
    let (ga, gb) = (group(names, a), group(names, b));
    ga.iter()
        .any(|&x| gb.iter().any(|&y| x != y && contacts.are_touching(x, y)))
}

/// The world at one step, as the checks read it.
pub(super) struct Moment<'a> {
    pub world: &'a World,
    pub probe: &'a Probe,
    pub names: &'a Names,
    /// Time since the start (s).
    pub t: f64,
    /// |gravity| at the start (m/s²), for closed forms.
    pub g: f64,
    /// The bodies quarantined in the step just taken, and why.
    pub quarantined: &'a [(Entity, String)],
}

/// Checks `x` at moment `m`.
pub(super) fn evaluate(m: &Moment, x: &Expectation, track: &mut Track) {
    let Moment {
        world,
        probe,
        names,
        t,
        g,
        quarantined,
    } = *m;
    let group = |who: &str| group(names, who);
    match &x.check {
        Check::Position {
            entity,
            x: rx,
            y: ry,
            z: rz,
        } => {
            let s = each(world, probe, group(entity), entity, |k| {
                let (mut ok, mut closeness, mut axes) = (true, f64::NEG_INFINITY, [None; 3]);
                for (i, (r, v)) in [(rx, k.x.x), (ry, k.x.y), (rz, k.x.z)]
                    .into_iter()
                    .enumerate()
                {
                    if let Some((lo, hi)) = r {
                        let (held, c) = bounded(v, Some(f64::from(*lo)), Some(f64::from(*hi)));
                        ok &= held;
                        closeness = closeness.max(c);
                        axes[i] = Some(v);
                    }
                }
                Sample {
                    ok,
                    closeness,
                    text: Reading::Axes(axes),
                }
            });
            track.record(t, s);
        }
        Check::Near {
            entity,
            point,
            within,
        } => {
            let p = point.as_dvec3();
            let s = each(world, probe, group(entity), entity, |k| {
                sample(k.x.distance(p), None, Some(*within), "distance", "m")
            });
            track.record(t, s);
        }
        Check::Speed { entity, min, max } => {
            let s = each(world, probe, group(entity), entity, |k| {
                sample(k.v.length(), *min, *max, "speed", "m/s")
            });
            track.record(t, s);
        }
        Check::AngularSpeed { entity, min, max } => {
            let s = each(world, probe, group(entity), entity, |k| {
                sample(k.w.length(), *min, *max, "angular speed", "rad/s")
            });
            track.record(t, s);
        }
        Check::Peak {
            entity,
            quantity: q,
            ..
        } => {
            for &e in group(entity) {
                if let Some(k) = probe.get(world, e) {
                    let v = quantity(&k, *q);
                    if track.peak.is_none_or(|(p, _)| v > p) {
                        track.peak = Some((v, t));
                    }
                }
            }
        }
        // The world's energy and momentum are measured by a step (a spin given at spawn
        // becomes angular momentum in the first one), so they start after step 1.
        Check::Energy { .. } | Check::Momentum { entity: None, .. } if t == 0.0 => {}
        Check::Energy { relative, absolute } => {
            let e = world
                .get_resource::<PhysicsDiagnostics>()
                .map_or(f64::NAN, PhysicsDiagnostics::total_energy);
            let e0 = track.base.get_or_insert(DVec3::splat(e)).x;
            let dev = e - e0;
            let (ok, c) = bounded(dev.abs(), None, Some(relative * e0.abs() + absolute));
            track.record(
                t,
                Sample {
                    ok,
                    closeness: c,
                    text: Reading::Energy(dev, e0),
                },
            );
        }
        Check::Momentum {
            entity,
            relative,
            absolute,
        } => {
            let p = match entity {
                Some(who) => momentum(world, group(who)),
                None => world
                    .get_resource::<PhysicsDiagnostics>()
                    .map_or(DVec3::NAN, |d| d.linear_momentum.as_dvec3()),
            };
            let p0 = *track.base.get_or_insert(p);
            let dev = (p - p0).length();
            let (ok, c) = bounded(dev, None, Some(relative * p0.length() + absolute));
            track.record(
                t,
                Sample {
                    ok,
                    closeness: c,
                    text: Reading::Momentum(dev, p0.length()),
                },
            );
        }
        Check::Contact { a, b } => {
            if track.seen.is_none() && touching(world, names, a, b) {
                track.seen = Some((t, format!("touching at {t:.3} s")));
            }
        }
        Check::NoContact { a, b } => {
            let hit = touching(world, names, a, b);
            track.record(
                t,
                Sample {
                    ok: !hit,
                    closeness: 0.0,
                    text: Reading::Fixed(if hit { "touching" } else { "apart" }),
                },
            );
        }
        Check::NoQuarantine => {
            // Only a failure is formatted; a quiet step allocates nothing.
            let text = match quarantined.first() {
                Some((e, why)) => Reading::Text(format!("{e} quarantined: {why}")),
                None => Reading::Fixed("none quarantined"),
            };
            track.record(
                t,
                Sample {
                    ok: quarantined.is_empty(),
                    closeness: 0.0,
                    text,
                },
            );
        }
        Check::Quarantined { entity } => {
            if track.seen.is_none()
                && let Some(q) = group(entity)
                    .iter()
                    .find_map(|e| world.get::<Quarantined>(*e))
            {
                track.seen = Some((t, format!("quarantined: {}", q.reason)));
            }
        }
        Check::Asleep { entity } | Check::Awake { entity } => {
            let want = matches!(x.check, Check::Asleep { .. });
            let members = group(entity);
            let asleep = members
                .iter()
                .filter(|e| world.get::<Sleeping>(**e).is_some())
                .count();
            let ok = !members.is_empty()
                && if want {
                    asleep == members.len()
                } else {
                    asleep == 0
                };
            track.record(
                t,
                Sample {
                    ok,
                    closeness: 0.0,
                    text: Reading::Asleep(asleep, members.len()),
                },
            );
        }
        Check::ClosedForm {
            entity,
            quantity: q,
            tolerance,
            ..
        } => {
            let Some(expr) = &x.expr else { return };
            let want = expr.eval(t, g);
            let s = each(world, probe, group(entity), entity, |k| {
                let v = quantity(k, *q);
                let err = v - want;
                let (ok, c) = bounded(err.abs(), None, Some(*tolerance));
                Sample {
                    ok,
                    closeness: c,
                    text: Reading::Closed(*q, v, want),
                }
            });
            track.record(t, s);
        }
    }
}

/// The moment(s) an expectation covers, in words.
fn when(x: &Expectation, dt: f64) -> String {
    let (a, b) = (x.window.first as f64 * dt, x.window.last as f64 * dt);
    if x.window.whole {
        "always".into()
    } else if x.window.first == x.window.last {
        format!("at {a:.3} s")
    } else {
        format!("from {a:.3} to {b:.3} s")
    }
}

fn range(r: Option<(f32, f32)>, what: &str) -> Option<String> {
    r.map(|(a, b)| format!("{what} in [{a}, {b}]"))
}

fn bounds_text<T: std::fmt::Display>(min: Option<T>, max: Option<T>) -> String {
    match (min, max) {
        (Some(a), Some(b)) => format!("in [{a}, {b}]"),
        (Some(a), None) => format!(">= {a}"),
        (None, Some(b)) => format!("<= {b}"),
        (None, None) => String::new(),
    }
}

/// What `x` expects, in words.
fn describe(x: &Expectation, dt: f64) -> String {
    let what = match &x.check {
        Check::Position {
            entity,
            x: rx,
            y,
            z,
        } => {
            let parts: Vec<String> = [range(*rx, "x"), range(*y, "y"), range(*z, "z")]
                .into_iter()
                .flatten()
                .collect();
            format!("{entity} {} (m)", parts.join(", "))
        }
        Check::Near {
            entity,
            point,
            within,
        } => format!("{entity} within {within} m of {point}"),
        Check::Speed { entity, min, max } => {
            format!("{entity} speed {} m/s", bounds_text(*min, *max))
        }
        Check::AngularSpeed { entity, min, max } => {
            format!("{entity} angular speed {} rad/s", bounds_text(*min, *max))
        }
        Check::Peak {
            entity,
            quantity: q,
            min,
            max,
        } => format!(
            "{entity} peak {} {} {}",
            name(*q),
            bounds_text(*min, *max),
            unit(*q)
        ),
        Check::Energy { relative, absolute } => {
            format!("energy within {relative} of E0 + {absolute} J")
        }
        Check::Momentum {
            entity,
            relative,
            absolute,
        } => format!(
            "momentum of {} within {relative} of P0 + {absolute} kg m/s",
            entity.as_deref().unwrap_or("everything")
        ),
        Check::Contact { a, b } => format!("{a} touches {b}"),
        Check::NoContact { a, b } => format!("{a} never touches {b}"),
        Check::NoQuarantine => "no body quarantined".into(),
        Check::Quarantined { entity } => format!("{entity} quarantined"),
        Check::Asleep { entity } => format!("{entity} asleep"),
        Check::Awake { entity } => format!("{entity} awake"),
        Check::ClosedForm {
            entity,
            quantity: q,
            value,
            tolerance,
        } => {
            format!(
                "{entity} {} = {value} within {tolerance} {}",
                name(*q),
                unit(*q)
            )
        }
    };
    format!("{}: {what}", when(x, dt))
}

/// The expectation's outcome once its window has passed.
pub(super) fn finish(x: &Expectation, track: Track, dt: f64) -> Outcome {
    let expected = describe(x, dt);
    let end = x.window.last as f64 * dt;
    let (passed, time, measured) = match &x.check {
        Check::Peak {
            min,
            max,
            quantity: q,
            ..
        } => match track.peak {
            Some((v, t)) => (
                bounded(v, *min, *max).0,
                t,
                format!("peak {} = {v:.6} {}", name(*q), unit(*q)),
            ),
            None => (false, end, "never read".into()),
        },
        Check::Contact { .. } | Check::Quarantined { .. } => match track.seen {
            Some((t, text)) => (true, t, text),
            None => (false, end, "never".into()),
        },
        _ => match (track.failed, track.closest) {
            (Some((t, r)), _) => (false, t, r.show()),
            (None, Some((_, t, r))) => (true, t, r.show()),
            (None, None) => (false, end, "never checked".into()),
        },
    };
    Outcome {
        line: x.line,
        expected,
        passed,
        time,
        measured,
    }
}

/// Σ m v over a group's movable bodies and nodes (kg·m/s).
fn momentum(world: &World, group: &[Entity]) -> DVec3 {
    let mut p = DVec3::ZERO;
    for &e in group {
        if let Some(nodes) = world.get::<Nodes>(e) {
            for i in 0..nodes.len() {
                if let Some(m) = nodes.mass(i).filter(|m| m.is_finite()) {
                    p += f64::from(m) * Vec3::from(nodes.velocities()[i]).as_dvec3();
                }
            }
        } else if let (Some(m), Some(v)) = (world.get::<Mass>(e), world.get::<LinearVelocity>(e))
            && !m.is_pinned()
            && m.value().is_finite()
        {
            p += f64::from(m.value()) * v.get().as_dvec3();
        }
    }
    p
}
