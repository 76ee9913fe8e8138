//! Reading a scenario file: RON through serde, then every name, time and value checked
//! before anything runs, each error with its line.
//!
//! The top level is read with each entity, action and expectation kept as raw RON text
//! (`ron::value::RawValue` borrows it from the file), so each is then parsed on its own and
//! its errors carry the line where it stands in the file.

use std::collections::HashMap;

use ron::value::RawValue;
use serde::Deserialize;

use super::expr::Expr;
use super::format::{
    Action, Check, EntityEntry, ExpectEntry, JointKind, PluginName, Settings, Spawn, TimelineEntry,
};
use super::{Expectation, Scenario, ScenarioError, ScenarioErrorKind, Selector, Timed, Window};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile<'a> {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default, borrow)]
    settings: Option<&'a RawValue>,
    #[serde(default)]
    duration: Option<f64>,
    #[serde(borrow)]
    entities: Vec<&'a RawValue>,
    #[serde(default, borrow)]
    timeline: Vec<&'a RawValue>,
    #[serde(default, borrow)]
    expect: Vec<&'a RawValue>,
    #[serde(default)]
    trace: Vec<String>,
    #[serde(default)]
    hash: Option<String>,
}

fn options() -> ron::Options {
    // `hash: "…"` rather than `hash: Some("…")`, and `Field(Vortex(..))` without a second
    // pair of parentheses.
    ron::Options::default().with_default_extension(
        ron::extensions::Extensions::IMPLICIT_SOME
            | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
    )
}

struct Reader<'a> {
    src: &'a str,
    file: String,
    /// The byte offset of every line's start, so that finding a piece's line is a binary
    /// search (a scan from the top for each entry made reading quadratic in the file).
    line_starts: Vec<usize>,
}

impl<'a> Reader<'a> {
    fn error(&self, line: usize, column: usize, kind: ScenarioErrorKind) -> ScenarioError {
        ScenarioError {
            file: self.file.clone(),
            line,
            column,
            kind,
        }
    }

    /// Where a piece of the file starts: 1-based line and column (in bytes).
    fn locate(&self, piece: &str) -> (usize, usize) {
        let offset = (piece.as_ptr() as usize)
            .saturating_sub(self.src.as_ptr() as usize)
            .min(self.src.len());
        let line = self.line_starts.partition_point(|&start| start <= offset);
        let start = self.line_starts[line.saturating_sub(1)];
        (line, offset - start + 1)
    }

    /// Parses one raw piece; a syntax error's position is moved from the piece to the file.
    fn parse<T: for<'de> Deserialize<'de>>(
        &self,
        raw: &RawValue,
    ) -> Result<(T, usize), ScenarioError> {
        let text = raw.get_ron();
        let (line, column) = self.locate(text);
        let trimmed = text.trim_start();
        let (item_line, _) = self.locate(trimmed);
        options()
            .from_str::<T>(text)
            .map(|v| (v, item_line))
            .map_err(|e| {
                let (l, c) = (e.span.start.line, e.span.start.col);
                let (l, c) = if l <= 1 {
                    (line, column + c.saturating_sub(1))
                } else {
                    (line + l - 1, c)
                };
                self.error(l, c, ScenarioErrorKind::Syntax(e.code.to_string()))
            })
    }
}

/// How many entities an entry spawns, known before anything runs.
pub(super) fn members(spawn: &Spawn) -> usize {
    match spawn {
        Spawn::Rope { nodes, .. } => *nodes,
        Spawn::Column { n } => *n,
        Spawn::Pyramid { layers } => layers.saturating_mul(layers.saturating_add(1)) / 2,
        _ => 1,
    }
}

/// A name's life: spawned at `born` (a step), despawned at `died` (a step) if ever.
#[derive(Clone, Copy)]
struct Life {
    members: usize,
    born: u64,
    died: Option<u64>,
    line: usize,
    moves: bool,
    /// A hinge or a slider: it takes a motor.
    motor: bool,
}

pub(super) fn load(src: &str, file: &str) -> Result<Scenario, ScenarioError> {
    let r = Reader {
        src,
        file: file.to_owned(),
        line_starts: std::iter::once(0)
            .chain(src.match_indices('\n').map(|(i, _)| i + 1))
            .collect(),
    };
    let raw: RawFile = options().from_str(src).map_err(|e| {
        r.error(
            e.span.start.line,
            e.span.start.col,
            ScenarioErrorKind::Syntax(e.code.to_string()),
        )
    })?;
    let settings = match raw.settings {
        Some(s) => r.parse::<Settings>(s)?.0,
        None => Settings::default(),
    };
    let bad = |line: usize, msg: String| r.error(line, 1, ScenarioErrorKind::BadValue(msg));
    if !(settings.dt.is_finite() && settings.dt > 0.0) {
        return Err(bad(
            1,
            format!(
                "settings.dt must be positive and finite (s), got {}",
                settings.dt
            ),
        ));
    }
    if settings.substeps == 0 || settings.substeps > crate::core::time::PhysicsTime::MAX_SUBSTEPS {
        return Err(bad(
            1,
            format!(
                "settings.substeps must be 1 to {}, got {}",
                crate::core::time::PhysicsTime::MAX_SUBSTEPS,
                settings.substeps
            ),
        ));
    }
    if !settings.gravity.is_finite() {
        return Err(bad(
            1,
            format!("settings.gravity must be finite, got {}", settings.gravity),
        ));
    }
    let dt = f64::from(settings.dt);
    // A time becomes a step once: round(t / dt).
    let to_step = |t: f64, line: usize, what: &str| -> Result<u64, ScenarioError> {
        if !t.is_finite() || t < 0.0 {
            return Err(r.error(
                line,
                1,
                ScenarioErrorKind::BadTime(format!(
                    "{what} must be a finite time >= 0 (s), got {t}"
                )),
            ));
        }
        let steps = (t / dt).round();
        if steps > f64::from(u32::MAX) {
            return Err(r.error(
                line,
                1,
                ScenarioErrorKind::BadTime(format!("{what} {t} s is past 2^32 - 1 steps")),
            ));
        }
        Ok(steps as u64)
    };

    let mut lives: HashMap<String, Life> = HashMap::new();
    let mut entities = Vec::new();
    for raw_entity in &raw.entities {
        let (entry, line) = r.parse::<EntityEntry>(raw_entity)?;
        check_name(&r, &lives, &entry.name, line)?;
        ends(&r, &lives, &entry.spawn, line, 0)?;
        lives.insert(entry.name.clone(), life(&entry.spawn, 0, line));
        entities.push(Timed {
            step: 0,
            line,
            item: entry,
        });
    }

    let mut timeline = Vec::new();
    for raw_action in &raw.timeline {
        let (entry, line) = r.parse::<TimelineEntry>(raw_action)?;
        let step = match (entry.at, entry.step) {
            (Some(t), None) => to_step(t, line, "at")?,
            (None, Some(s)) => s,
            _ => {
                return Err(r.error(
                    line,
                    1,
                    ScenarioErrorKind::BadTime(
                        "an action needs exactly one of `at` (s) and `step`".into(),
                    ),
                ));
            }
        };
        timeline.push(Timed {
            step,
            line,
            item: entry.action,
        });
    }
    // Actions at the same step keep the file's order.
    timeline.sort_by_key(|a| a.step);

    // Walk the timeline once: spawns and despawns give every name its life.
    for a in &timeline {
        match &a.item {
            Action::Spawn { name, spawn } => {
                check_name(&r, &lives, name, a.line)?;
                lives.insert(name.clone(), life(spawn, a.step, a.line));
            }
            Action::Despawn { entity } => {
                let sel = selector_at(&r, &lives, entity, a.line, (a.step, a.step), true)?;
                if sel.index.is_none()
                    && let Some(l) = lives.get_mut(&sel.name).filter(|l| l.died.is_none())
                {
                    l.died = Some(a.step);
                }
            }
            _ => {}
        }
    }

    let mut expects = Vec::new();
    for raw_expect in &raw.expect {
        let (entry, line) = r.parse::<ExpectEntry>(raw_expect)?;
        let window = match (entry.at, entry.step, entry.during) {
            (Some(t), None, None) => {
                let s = to_step(t, line, "at")?;
                Window {
                    first: s,
                    last: s,
                    whole: false,
                }
            }
            (None, Some(s), None) => Window {
                first: s,
                last: s,
                whole: false,
            },
            (None, None, Some((a, b))) => {
                let (first, last) = (
                    to_step(a, line, "window start")?,
                    to_step(b, line, "window end")?,
                );
                if last < first {
                    return Err(r.error(
                        line,
                        1,
                        ScenarioErrorKind::BadTime(format!(
                            "window ends ({b} s) before it starts ({a} s)"
                        )),
                    ));
                }
                Window {
                    first,
                    last,
                    whole: false,
                }
            }
            (None, None, None) => Window {
                first: 0,
                last: u64::MAX,
                whole: true,
            },
            _ => {
                return Err(r.error(
                    line,
                    1,
                    ScenarioErrorKind::BadTime(
                        "an expectation takes at most one of `at`, `step` and `during`".into(),
                    ),
                ));
            }
        };
        expects.push((line, window, entry.check));
    }

    // The run lasts `duration`, or up to the last moment the file names.
    let latest = timeline
        .iter()
        .map(|a| a.step)
        .chain(expects.iter().filter(|e| !e.1.whole).map(|e| e.1.last))
        .max()
        .unwrap_or(0);
    let steps = match raw.duration {
        Some(t) => to_step(t, 1, "duration")?,
        None if latest == 0 && !expects.is_empty() => {
            return Err(r.error(
                1,
                1,
                ScenarioErrorKind::BadTime(
                    "say how long to run: `duration: …` (s); no moment in the file gives it".into(),
                ),
            ));
        }
        None => latest,
    };
    if latest > steps {
        let line = timeline
            .iter()
            .filter(|a| a.step > steps)
            .map(|a| a.line)
            .chain(
                expects
                    .iter()
                    .filter(|e| !e.1.whole && e.1.last > steps)
                    .map(|e| e.0),
            )
            .min()
            .unwrap_or(1);
        return Err(r.error(
            line,
            1,
            ScenarioErrorKind::BadTime(format!(
                "this moment is past the scenario's duration ({} s)",
                steps as f64 * dt
            )),
        ));
    }

    // Every name an action uses must be alive then.
    let mut resolved_timeline = Vec::new();
    for a in timeline {
        check_action(&r, &lives, &a)?;
        resolved_timeline.push(a);
    }

    let mut expectations = Vec::new();
    for (line, mut window, check) in expects {
        if window.whole {
            window.last = steps;
        }
        let expr = check_expectation(&r, &lives, &check, line, &window)?;
        expectations.push(Expectation {
            line,
            window,
            check,
            expr,
        });
    }

    let mut trace = Vec::new();
    for name in &raw.trace {
        // A trace follows a name from whenever it is spawned.
        let born = lives
            .get(name.split('[').next().unwrap_or(""))
            .map_or(0, |l| l.born);
        let sel = selector(&r, &lives, name, 1, born, born).map_err(|e| ScenarioError {
            line: trace_line(src),
            ..e
        })?;
        trace.push(sel);
    }

    let rows = (trace.len() as u64).saturating_mul(steps.saturating_add(1));
    if rows > super::MAX_TRACE_ROWS {
        return Err(bad(
            trace_line(src),
            format!(
                "tracing {} names over {} steps is {rows} rows, more than {} (shorten the \
                 duration or trace fewer names)",
                trace.len(),
                steps + 1,
                super::MAX_TRACE_ROWS
            ),
        ));
    }

    let hash = match &raw.hash {
        Some(h) => Some(
            u64::from_str_radix(h.trim_start_matches("0x"), 16).map_err(|_| {
                bad(
                    hash_line(src),
                    format!("hash must be 16 hex digits, got \"{h}\""),
                )
            })?,
        ),
        None => None,
    };

    if let Some(list) = &settings.plugins {
        for a in &resolved_timeline {
            if let Action::Enable(p) | Action::Disable(p) = a.item
                && !list.contains(&p)
            {
                return Err(bad(
                    a.line,
                    format!("{p:?} is not among settings.plugins, so it cannot be switched"),
                ));
            }
        }
    }

    Ok(Scenario {
        name: raw.name.unwrap_or_else(|| file.to_owned()),
        description: raw.description.unwrap_or_default(),
        file: file.to_owned(),
        settings,
        steps,
        entities,
        timeline: resolved_timeline,
        expectations,
        trace,
        hash,
        hash_line: hash_line(src),
    })
}

fn trace_line(src: &str) -> usize {
    src.lines()
        .position(|l| l.trim_start().starts_with("trace"))
        .map_or(1, |i| i + 1)
}

fn hash_line(src: &str) -> usize {
    src.lines()
        .position(|l| l.trim_start().starts_with("hash"))
        .map_or(1, |i| i + 1)
}

fn life(spawn: &Spawn, born: u64, line: usize) -> Life {
    Life {
        members: members(spawn),
        born,
        died: None,
        line,
        moves: !matches!(
            spawn,
            Spawn::Ground | Spawn::Field(_) | Spawn::Spring { .. } | Spawn::Joint { .. }
        ),
        motor: matches!(
            spawn,
            Spawn::Joint {
                kind: JointKind::Hinge { .. } | JointKind::Slider { .. },
                ..
            }
        ),
    }
}

/// Checks that the ends a spring or a joint names are one live entity each.
fn ends(
    r: &Reader,
    lives: &HashMap<String, Life>,
    spawn: &Spawn,
    line: usize,
    step: u64,
) -> Result<(), ScenarioError> {
    match spawn {
        Spawn::Spring { a, b, .. } => {
            spring_end(r, lives, a, line, step)?;
            spring_end(r, lives, b, line, step)?;
        }
        Spawn::Joint { a, b, .. } => {
            if let Some(a) = a {
                spring_end(r, lives, a, line, step)?;
            }
            spring_end(r, lives, b, line, step)?;
        }
        _ => {}
    }
    Ok(())
}

fn check_name(
    r: &Reader,
    lives: &HashMap<String, Life>,
    name: &str,
    line: usize,
) -> Result<(), ScenarioError> {
    if name.is_empty() || name.contains(['[', ']']) {
        return Err(r.error(
            line,
            1,
            ScenarioErrorKind::BadValue(format!(
                "\"{name}\" is not a usable name (empty, or with brackets)"
            )),
        ));
    }
    if let Some(other) = lives.get(name) {
        return Err(r.error(
            line,
            1,
            ScenarioErrorKind::DuplicateName {
                name: name.to_owned(),
                first_line: other.line,
            },
        ));
    }
    Ok(())
}

/// Resolves `name` or `name[i]` and checks it is alive over steps `first..=last`.
fn selector(
    r: &Reader,
    lives: &HashMap<String, Life>,
    text: &str,
    line: usize,
    first: u64,
    last: u64,
) -> Result<Selector, ScenarioError> {
    selector_at(r, lives, text, line, (first, last), false)
}

/// [`selector`]; `despawning` allows the name to die at `last` (the despawn itself).
fn selector_at(
    r: &Reader,
    lives: &HashMap<String, Life>,
    text: &str,
    line: usize,
    (first, last): (u64, u64),
    despawning: bool,
) -> Result<Selector, ScenarioError> {
    let (name, index) = super::split_selector(text);
    let index = index.map_err(|()| {
        r.error(
            line,
            1,
            ScenarioErrorKind::BadValue(format!("\"{text}\": the index must be a whole number")),
        )
    })?;
    let Some(life) = lives.get(name) else {
        return Err(r.error(line, 1, ScenarioErrorKind::UnknownEntity(name.to_owned())));
    };
    let index = match index {
        None => None,
        Some(i) => {
            let n = i64::try_from(life.members).unwrap_or(i64::MAX);
            let k = if i < 0 { n.saturating_add(i) } else { i };
            if k < 0 || k >= n {
                return Err(r.error(
                    line,
                    1,
                    ScenarioErrorKind::BadValue(format!("\"{text}\": {name} has {n} entities")),
                ));
            }
            Some(k as usize)
        }
    };
    let dead = life
        .died
        .is_some_and(|d| last > d || (last == d && !despawning));
    if first < life.born || dead {
        return Err(r.error(
            line,
            1,
            ScenarioErrorKind::MissingEntity {
                name: text.to_owned(),
                born: life.born,
                died: life.died,
            },
        ));
    }
    Ok(Selector {
        name: name.to_owned(),
        index,
        text: text.to_owned(),
    })
}

/// A spring's end: one entity, alive at `step`.
fn spring_end(
    r: &Reader,
    lives: &HashMap<String, Life>,
    text: &str,
    line: usize,
    step: u64,
) -> Result<Selector, ScenarioError> {
    let s = selector(r, lives, text, line, step, step)?;
    if s.index.is_none() && lives.get(&s.name).is_some_and(|l| l.members > 1) {
        return Err(r.error(
            line,
            1,
            ScenarioErrorKind::BadValue(format!(
                "a spring or a joint joins two entities; \"{text}\" is a group (write {text}[i])"
            )),
        ));
    }
    Ok(s)
}

fn check_action(
    r: &Reader,
    lives: &HashMap<String, Life>,
    a: &Timed<Action>,
) -> Result<(), ScenarioError> {
    let s = a.step;
    let bad = |msg: String| r.error(a.line, 1, ScenarioErrorKind::BadValue(msg));
    match &a.item {
        Action::Impulse { entity, .. }
        | Action::Force { entity, .. }
        | Action::Torque { entity, .. }
        | Action::SetVelocity { entity, .. }
        | Action::SetAngularVelocity { entity, .. }
        | Action::Teleport { entity, .. }
        | Action::Despawn { entity }
        | Action::Pin { entity }
        | Action::Release { entity }
        | Action::SetFriction { entity, .. }
        | Action::SetRestitution { entity, .. } => {
            // A despawn at this very step is the action itself.
            let despawning = matches!(a.item, Action::Despawn { .. });
            selector_at(r, lives, entity, a.line, (s, s), despawning)?;
        }
        Action::Spawn { spawn, .. } => ends(r, lives, spawn, a.line, s)?,
        Action::SetMotor { joint, .. } | Action::SetServo { joint, .. } => {
            selector_at(r, lives, joint, a.line, (s, s), false)?;
            let name = joint.split('[').next().unwrap_or(joint);
            if !lives.get(name).is_some_and(|l| l.motor) {
                return Err(bad(format!(
                    "\"{joint}\" is not a hinge or a slider: only they take a motor"
                )));
            }
        }
        Action::Enable(p) | Action::Disable(p) => {
            if !matches!(p, PluginName::Gravity | PluginName::Sleep) {
                return Err(bad(format!(
                    "{p:?} cannot be switched at run time (Gravity and Sleep can); leave it out of settings.plugins instead"
                )));
            }
        }
        Action::SetGravity { .. } => {}
    }
    Ok(())
}

fn check_expectation(
    r: &Reader,
    lives: &HashMap<String, Life>,
    check: &Check,
    line: usize,
    w: &Window,
) -> Result<Option<Expr>, ScenarioError> {
    let sel = |name: &str| selector(r, lives, name, line, w.first, w.last);
    let bad = |msg: String| r.error(line, 1, ScenarioErrorKind::BadValue(msg));
    let moving = |name: &str| -> Result<(), ScenarioError> {
        let s = sel(name)?;
        if lives.get(&s.name).is_some_and(|l| !l.moves) {
            return Err(bad(format!("\"{name}\" has no motion to check")));
        }
        Ok(())
    };
    let bounds = |min: Option<f64>, max: Option<f64>| -> Result<(), ScenarioError> {
        match (min, max) {
            (None, None) => Err(bad("give `min`, `max` or both".into())),
            (Some(a), Some(b)) if a > b => Err(bad(format!("min {a} is above max {b}"))),
            (a, b) if a.is_some_and(f64::is_nan) || b.is_some_and(f64::is_nan) => {
                Err(bad("bounds must not be NaN".into()))
            }
            _ => Ok(()),
        }
    };
    let range = |r: Option<(f32, f32)>| -> Result<(), ScenarioError> {
        match r {
            Some((a, b)) if a.partial_cmp(&b).is_none_or(|o| o.is_gt()) => {
                Err(bad(format!("range ({a}, {b}) is empty")))
            }
            _ => Ok(()),
        }
    };
    let tolerance = |t: f64, what: &str| -> Result<(), ScenarioError> {
        if t.is_finite() && t >= 0.0 {
            Ok(())
        } else {
            Err(bad(format!("{what} must be finite and >= 0, got {t}")))
        }
    };
    match check {
        Check::Position { entity, x, y, z } => {
            moving(entity)?;
            if x.is_none() && y.is_none() && z.is_none() {
                return Err(bad("give at least one of x, y, z".into()));
            }
            range(*x)?;
            range(*y)?;
            range(*z)?;
        }
        Check::Near {
            entity,
            point,
            within,
        } => {
            moving(entity)?;
            if !point.is_finite() {
                return Err(bad("point must be finite".into()));
            }
            tolerance(f64::from(*within), "within")?;
        }
        Check::Speed { entity, min, max } | Check::AngularSpeed { entity, min, max } => {
            moving(entity)?;
            bounds(min.map(f64::from), max.map(f64::from))?;
        }
        Check::Peak {
            entity, min, max, ..
        } => {
            moving(entity)?;
            bounds(*min, *max)?;
        }
        Check::Energy { relative, absolute } => {
            tolerance(*relative, "relative")?;
            tolerance(*absolute, "absolute")?;
        }
        Check::Momentum {
            entity,
            relative,
            absolute,
        } => {
            if let Some(e) = entity {
                moving(e)?;
            }
            tolerance(*relative, "relative")?;
            tolerance(*absolute, "absolute")?;
        }
        Check::Contact { a, b } | Check::NoContact { a, b } => {
            sel(a)?;
            sel(b)?;
        }
        Check::NoQuarantine => {}
        Check::Quarantined { entity } | Check::Asleep { entity } | Check::Awake { entity } => {
            sel(entity)?;
        }
        Check::ClosedForm {
            entity,
            value,
            tolerance: tol,
            ..
        } => {
            moving(entity)?;
            let s = sel(entity)?;
            if s.index.is_none() && lives.get(&s.name).is_some_and(|l| l.members > 1) {
                return Err(bad(format!(
                    "a closed form is of one entity; \"{entity}\" is a group (write {entity}[i])"
                )));
            }
            tolerance(*tol, "tolerance")?;
            return Expr::parse(value)
                .map(Some)
                .map_err(|m| bad(format!("closed form \"{}\": {m}", excerpt(value))));
        }
    }
    Ok(None)
}

/// `text` as an error message quotes it: its first 60 characters, and how long it was.
fn excerpt(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((end, _)) => format!("{}… ({} characters)", &text[..end], text.chars().count()),
        None => text.to_string(),
    }
}
