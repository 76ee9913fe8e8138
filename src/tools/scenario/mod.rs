//! Scripted gameplay scenarios: a RON file that builds a scene, acts on it on a timeline and
//! states what must hold, run headless into a [`Report`] a test can assert on.
//!
//! ```ron
//! // A crate kicked at 1 s slides to a stop on the ground (μ = 0.5).
//! (
//!     name: "kick a crate",
//!     duration: 3.0,
//!     entities: [
//!         (name: "ground", spawn: Ground),
//!         (name: "crate", spawn: Body(shape: Cuboid(0.5, 0.5, 0.5), at: (0, 0.5, 0))),
//!     ],
//!     timeline: [
//!         (at: 1.0, do: Impulse(entity: "crate", impulse: (3000, 0, 0))),
//!     ],
//!     expect: [
//!         (at: 0.9, check: Speed(entity: "crate", max: 0.01)),
//!         (at: 3.0, check: Position(entity: "crate", x: (0.85, 0.99), y: (0.45, 0.55))),
//!         (check: NoQuarantine),
//!     ],
//! )
//! ```
//!
//! - **Time.** A time `t` (s) is the step `round(t / dt)`, counted once, so `at: 3.0` is
//!   exactly step 180 at 60 Hz. At each step the runner steps the world, then applies that
//!   step's actions in file order, then checks that step's expectations: an expectation at
//!   the moment of an action sees the action (a velocity just set; an impulse acts in the
//!   next step). `at: 0.0` checks the scene as spawned.
//! - **Names.** An entry's name stands for every entity it spawns (a rope's nodes, a
//!   pyramid's boxes); `name[i]` is one of them, `name[-1]` the last. Position and speed
//!   checks on a group hold for every member. A cloth or jelly is one entity whose position
//!   is its nodes' mean and whose velocity their mean.
//! - **Errors.** A bad file is a [`ScenarioError`] with the line: bad RON or an unknown
//!   field, an unknown or duplicate name, a negative time, a moment past `duration`, an
//!   action or expectation on an entity not alive then, a bad closed form. A value a
//!   constructor refuses (a negative radius) is found when the scene is built, with the
//!   line of its entry.
//! - **Hash.** [`Report::hash`] is [`crate::snapshot::Snapshot::digest`] of the final state;
//!   `hash: "…"` in the file pins it, and a different result fails the run.
//!
//! The vocabulary is in [`mod@format`]; the command-line runner is `cargo run --release
//! --features cli --bin hooke -- run scenarios/*.ron`.

mod check;
pub mod expr;
pub mod format;
mod load;
mod report;
mod run;
mod select;
mod spawn;

use std::path::Path;

pub use report::{Outcome, Report, Trace};
pub use run::RunOptions;

use expr::Expr;
use format::{Action, Check, EntityEntry, Settings};

/// The most rows a run traces in all (traced names × steps): a trace row is 64 bytes, so
/// this bounds a run's traces at 256 MB. A file whose traces would pass it is refused when
/// read ([`ScenarioErrorKind::BadValue`]), as is a traced run ([`RunOptions::trace_all`])
/// that would.
pub const MAX_TRACE_ROWS: u64 = 1 << 22;

/// Each entry's name and the entities it spawned, sorted by name.
pub type NamedEntities = Vec<(String, Vec<bevy_ecs::entity::Entity>)>;

/// A scenario read and checked, ready to [`Scenario::run`].
#[derive(Debug, Clone)]
pub struct Scenario {
    name: String,
    description: String,
    file: String,
    settings: Settings,
    steps: u64,
    entities: Vec<Timed<EntityEntry>>,
    timeline: Vec<Timed<Action>>,
    expectations: Vec<Expectation>,
    trace: Vec<Selector>,
    hash: Option<u64>,
    hash_line: usize,
}

/// Something at a step, from a line of the file.
#[derive(Debug, Clone)]
struct Timed<T> {
    step: u64,
    line: usize,
    item: T,
}

/// Steps `first..=last`; `whole` when the file gave no moment (the whole run).
#[derive(Debug, Clone, Copy)]
struct Window {
    first: u64,
    last: u64,
    whole: bool,
}

#[derive(Debug, Clone)]
struct Expectation {
    line: usize,
    window: Window,
    check: Check,
    expr: Option<Expr>,
}

/// `name` or `name[i]`.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Selector {
    name: String,
    index: Option<usize>,
    text: String,
}

/// Splits `name[i]` into the name and the index as written (negative counts from the end);
/// a plain name has no index, and an index that is not a whole number is `Err(())`.
fn split_selector(text: &str) -> (&str, Result<Option<i64>, ()>) {
    match text.find('[') {
        Some(open) if text.ends_with(']') => (
            &text[..open],
            text[open + 1..text.len() - 1]
                .trim()
                .parse::<i64>()
                .map(Some)
                .map_err(|_| ()),
        ),
        _ => (text, Ok(None)),
    }
}

/// A bad scenario file: where, and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {kind}")]
pub struct ScenarioError {
    /// The file (or `<string>`).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (1 when the whole entry is meant).
    pub column: usize,
    /// What is wrong.
    pub kind: ScenarioErrorKind,
}

/// What is wrong with a scenario file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScenarioErrorKind {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(String),
    /// Not RON, or not this format: a missing or unknown field, a wrong type.
    #[error("{0}")]
    Syntax(String),
    /// A name no entity entry or spawn action gives.
    #[error("no entity is named \"{0}\"")]
    UnknownEntity(String),
    /// Two entries with one name.
    #[error("the name \"{name}\" is taken (line {first_line})")]
    DuplicateName {
        /// The name.
        name: String,
        /// Where it was first given.
        first_line: usize,
    },
    /// A negative, NaN or out-of-order time, or one past the duration.
    #[error("{0}")]
    BadTime(String),
    /// An action or expectation on an entity that does not exist at that moment.
    #[error("\"{name}\" does not exist then (spawned at step {born}{})", died.map(|d| format!(", despawned at step {d}")).unwrap_or_default())]
    MissingEntity {
        /// The name as written.
        name: String,
        /// The step it is spawned at.
        born: u64,
        /// The step it is despawned at, if it is.
        died: Option<u64>,
    },
    /// A value the format refuses (an empty range, a bad closed form, a bad hash).
    #[error("{0}")]
    BadValue(String),
    /// A constructor refused a value while the scene was built or an action ran.
    #[error("{0}")]
    Build(crate::core::error::Error),
    /// The final state could not be captured for its hash.
    #[error("{0}")]
    Snapshot(crate::snapshot::SnapshotError),
}

impl Scenario {
    /// Reads and checks a scenario from RON text; `file` names it in errors.
    ///
    /// # Errors
    /// A [`ScenarioError`] with the line of the first problem.
    pub fn from_str(text: &str, file: &str) -> Result<Self, ScenarioError> {
        load::load(text, file)
    }

    /// Reads and checks a scenario file.
    ///
    /// # Errors
    /// [`ScenarioErrorKind::Io`] if it cannot be read, else as [`Scenario::from_str`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, ScenarioError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            file: name.clone(),
            line: 0,
            column: 0,
            kind: ScenarioErrorKind::Io(e.to_string()),
        })?;
        load::load(&text, &name)
    }

    /// Its name (the file's `name`, else the file).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its description.
    #[must_use]
    pub fn description(&self) -> &str {
        &self.description
    }

    /// How many steps it runs.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// How many entities its entries and spawn actions make in all (a column of n boxes
    /// counts n): with [`Scenario::steps`] and the substeps, what a run will cost.
    #[must_use]
    pub fn entities_spawned(&self) -> u64 {
        let entries = self.entities.iter().map(|e| &e.item.spawn);
        let actions = self.timeline.iter().filter_map(|a| match &a.item {
            Action::Spawn { spawn, .. } => Some(spawn),
            _ => None,
        });
        entries
            .chain(actions)
            .map(|s| load::members(s) as u64)
            .fold(0, u64::saturating_add)
    }

    /// The world settings.
    #[must_use]
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Builds the scene, runs it and checks every expectation.
    ///
    /// # Errors
    /// [`ScenarioErrorKind::Build`] (with the entry's line) when a constructor refuses a
    /// value of the file, or an action cannot act on its entity.
    pub fn run(&self) -> Result<Report, ScenarioError> {
        self.run_with(&mut RunOptions::default())
    }

    /// [`Scenario::run`] with traces and a progress callback.
    ///
    /// # Errors
    /// As [`Scenario::run`].
    pub fn run_with(&self, options: &mut RunOptions) -> Result<Report, ScenarioError> {
        run::run(self, options)
    }

    /// Builds the scene as it stands at step 0, without running it: the world a test
    /// steps by hand, and the names of its entries.
    ///
    /// # Errors
    /// As [`Scenario::run`].
    pub fn build(&self) -> Result<(bevy_ecs::world::World, NamedEntities), ScenarioError> {
        let (world, names) = run::build(self)?;
        let mut named: Vec<_> = names.into_iter().collect();
        named.sort();
        Ok((world, named))
    }

    fn error(&self, line: usize, kind: ScenarioErrorKind) -> ScenarioError {
        ScenarioError {
            file: self.file.clone(),
            line,
            column: 1,
            kind,
        }
    }
}
