//! Fuzzing in a child process, so that what cannot be caught in-process is counted too: an
//! abort (stack overflow, allocation failure) ends the child, a hang stops its output. The
//! child prints `done …` (its tally so far) and `case K` before each case and `tally …` at
//! the end; the parent reads its
//! output with a watchdog, counts an abort when the child dies mid-run and a hang when a
//! case prints nothing for longer than the watchdog (it kills the child), and starts a new
//! child after the case that failed, keeping the dead child's last `done` tally. Shared by `robustness::fuzz` and `examples/fuzz.rs`.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use super::harness::Tally;

/// What a supervised run found.
#[derive(Debug, Default, Clone)]
pub struct Supervised {
    /// The children's tallies, summed.
    pub tally: Tally,
    /// Cases that ended their child (an abort or any death without a tally).
    pub aborts: Vec<u32>,
    /// Cases that printed nothing for longer than the watchdog.
    pub hangs: Vec<u32>,
    /// What the children reported of failing cases (lines that are not the protocol's).
    pub reports: Vec<String>,
}

/// How the harnesses begin the line of a failing case.
const REPORTS: [&str; 5] = [
    "failure",
    "panic:",
    "snapshot failure",
    "scenario panic",
    "silently bad",
];

/// The fuzz kinds a child runs.
pub const KINDS: [&str; 3] = ["worlds", "snapshots", "scenarios"];

/// Runs `total` cases of a child made by `child(skip)` (which runs cases `skip..total`),
/// restarting after each abort or hang.
pub fn supervise(child: impl Fn(u32) -> Command, total: u32, watchdog: Duration) -> Supervised {
    let mut out = Supervised::default();
    let mut skip = 0;
    while skip < total {
        let mut cmd = child(skip);
        let Ok(mut process) = cmd.stdout(Stdio::piped()).stderr(Stdio::null()).spawn() else {
            out.aborts.push(skip);
            break;
        };
        let Some(stdout) = process.stdout.take() else {
            break;
        };
        let (send, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if send.send(line).is_err() {
                    break;
                }
            }
        });
        let mut current = skip;
        let mut finished = false;
        // What the child had done before the case it is in; counted if it dies there.
        let mut done = Tally::default();
        loop {
            match lines.recv_timeout(watchdog) {
                Ok(line) => {
                    if let Some(k) = line
                        .strip_prefix("case ")
                        .and_then(|k| k.trim().parse().ok())
                    {
                        current = k;
                    } else if let Some(t) = line.strip_prefix("done ") {
                        done = Tally::default();
                        add(&mut done, t);
                    } else if let Some(t) = line.strip_prefix("tally ") {
                        add(&mut out.tally, t);
                        finished = true;
                    } else if REPORTS.iter().any(|r| line.starts_with(r)) {
                        out.reports.push(line);
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    let _ = process.kill();
                    out.hangs.push(current);
                    add_tally(&mut out.tally, &done);
                    break;
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    if !finished {
                        out.aborts.push(current);
                        add_tally(&mut out.tally, &done);
                    }
                    break;
                }
            }
        }
        let _ = process.wait();
        skip = if finished { total } else { current + 1 };
    }
    out
}

/// The tally line a child prints.
pub fn tally_line(t: &Tally) -> String {
    format!(
        "tally {} {} {} {} {} {} {} {}",
        t.inputs,
        t.accepted,
        t.errors,
        t.panics,
        t.quarantines,
        t.silent,
        t.steps,
        t.snapshot_mismatches
    )
}

fn add(t: &mut Tally, line: &str) {
    let v: Vec<usize> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    if let [
        inputs,
        accepted,
        errors,
        panics,
        quarantines,
        silent,
        steps,
        mismatches,
    ] = v[..]
    {
        t.inputs += inputs;
        t.accepted += accepted;
        t.errors += errors;
        t.panics += panics;
        t.quarantines += quarantines;
        t.silent += silent;
        t.steps += steps;
        t.snapshot_mismatches += mismatches;
    }
}

fn add_tally(t: &mut Tally, more: &Tally) {
    add(t, &tally_line(more)["tally ".len()..]);
}
