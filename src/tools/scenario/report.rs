//! What a run found: one [`Outcome`] per expectation, the final state's hash, and traces.

use std::fmt;
use std::io::Write;
use std::path::Path;
use std::time::Duration;

/// One expectation's result.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The line of the expectation in the file.
    pub line: usize,
    /// What was expected, in words: `at 3 s: crate y in [0.45, 0.55]`.
    pub expected: String,
    /// Whether it held.
    pub passed: bool,
    /// The time (s) the reported value was read: the first failure, else the value
    /// closest to failing (the last read for a single moment).
    pub time: f64,
    /// What was measured then, with units: `y = 0.5012 m`.
    pub measured: String,
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} line {:>3}  {}  (measured {} at {:.3} s)",
            if self.passed { "pass" } else { "FAIL" },
            self.line,
            self.expected,
            self.measured,
            self.time
        )
    }
}

/// One traced entity: a row per step.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The name as written in `trace`.
    pub name: String,
    /// `[t, x, y, z, vx, vy, vz, speed]` per step (s, m, m/s).
    pub rows: Vec<[f64; 8]>,
}

impl Trace {
    /// The CSV header.
    pub const HEADER: &'static str = "t_s,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,speed_m_s";

    /// Writes the trace as CSV.
    ///
    /// # Errors
    /// The file system's.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "{}", Self::HEADER)?;
        for r in &self.rows {
            let cells: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
            writeln!(out, "{}", cells.join(","))?;
        }
        out.flush()
    }
}

/// A run's results. [`Report::passed`] is what a test asserts; `Display` prints one line
/// per expectation.
#[derive(Debug, Clone)]
pub struct Report {
    /// The scenario's name.
    pub name: String,
    /// The file.
    pub file: String,
    /// Steps run.
    pub steps: u64,
    /// Simulated time (s): steps × dt.
    pub seconds: f64,
    /// One per expectation, in file order, then the hash check if the file pins one.
    pub outcomes: Vec<Outcome>,
    /// [`crate::snapshot::Snapshot::digest`] of the final state.
    pub hash: u64,
    /// The hash the file pins, if any.
    pub expected_hash: Option<u64>,
    /// Traces of the names in the file's `trace` (or of every name, when asked).
    pub traces: Vec<Trace>,
    /// Wall-clock time of the run (building and stepping).
    pub wall: Duration,
}

impl Report {
    /// Every expectation held (and the hash matched, if pinned).
    #[must_use]
    pub fn passed(&self) -> bool {
        self.outcomes.iter().all(|o| o.passed)
    }

    /// The earliest failure in simulated time (file order among equals).
    #[must_use]
    pub fn first_failure(&self) -> Option<&Outcome> {
        self.outcomes
            .iter()
            .filter(|o| !o.passed)
            .min_by(|a, b| a.time.total_cmp(&b.time).then(a.line.cmp(&b.line)))
    }

    /// Failed outcomes.
    pub fn failures(&self) -> impl Iterator<Item = &Outcome> {
        self.outcomes.iter().filter(|o| !o.passed)
    }

    /// The hash as printed and pinned: 16 hex digits.
    #[must_use]
    pub fn hash_hex(&self) -> String {
        format!("{:016x}", self.hash)
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let failed = self.failures().count();
        writeln!(
            f,
            "{}  {}  ({} steps, {:.2} s simulated, {:.0} ms)",
            if failed == 0 { "PASS" } else { "FAIL" },
            self.file,
            self.steps,
            self.seconds,
            self.wall.as_secs_f64() * 1e3
        )?;
        for o in &self.outcomes {
            writeln!(f, "  {o}")?;
        }
        write!(f, "  hash {}", self.hash_hex())?;
        match self.expected_hash {
            Some(h) if h == self.hash => write!(f, " (pinned, matches)"),
            Some(h) => write!(f, " (pinned {h:016x}: CHANGED)"),
            None => write!(f, " (not pinned)"),
        }
    }
}
