//! The long fuzz run: `cargo run --release --example fuzz -- --cases 20000 --seed 1`.
//!
//! Constructors run in this process (ten times `--cases`); random worlds, edited snapshots
//! and edited scenario files each run `--cases` cases in child processes of this program
//! under a watchdog, so that an abort or a hang is counted beside the panics, silent NaN
//! and unbounded bodies instead of ending the run. `--kinds worlds,snapshots` picks some.
//! Prints the table of `docs/validation.md`.

#[path = "../tests/it/robustness/file_harness.rs"]
mod file_harness;
#[path = "../tests/it/robustness/harness.rs"]
mod harness;
#[path = "../tests/it/robustness/supervisor.rs"]
mod supervisor;
#[path = "../tests/it/robustness/world_cases.rs"]
mod world_cases;

use std::process::Command;
use std::time::Duration;

fn arg(name: &str) -> Option<String> {
    std::env::args().skip_while(|a| a != name).nth(1)
}

fn main() {
    let cases: u32 = arg("--cases").and_then(|s| s.parse().ok()).unwrap_or(2000);
    let seed: u64 = arg("--seed").and_then(|s| s.parse().ok()).unwrap_or(1);
    // Panics are counted, not printed (each is also reported with its case).
    std::panic::set_hook(Box::new(|_| {}));
    if let Some(kind) = arg("--child") {
        let skip = arg("--skip").and_then(|s| s.parse().ok()).unwrap_or(0);
        file_harness::child(&kind, cases, seed, skip);
        return;
    }
    let kinds = arg("--kinds").unwrap_or_else(|| supervisor::KINDS.join(","));
    let start = std::time::Instant::now();
    println!(
        "| fuzzed | inputs | accepted | typed errors | panics | aborts | hangs | quarantines | silent NaN / unbounded | snapshot mismatches |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let c = harness::fuzz_constructors(cases * 10, seed);
    println!(
        "| constructor calls | {} | {} | {} | {} | 0 | 0 | – | – | – |",
        c.inputs, c.accepted, c.errors, c.panics
    );
    let mut failures: Vec<String> = c.failure.into_iter().collect();
    let me = std::env::current_exe().expect("this program");
    for kind in kinds.split(',').filter(|k| supervisor::KINDS.contains(k)) {
        let s = supervisor::supervise(
            |skip| {
                let mut child = Command::new(&me);
                child.args(["--child", kind, "--skip", &skip.to_string()]);
                child.args(["--cases", &cases.to_string(), "--seed", &seed.to_string()]);
                child
            },
            cases,
            Duration::from_secs(300),
        );
        let t = &s.tally;
        let (accepted, errors) = if kind == "worlds" {
            ("–".to_owned(), "–".to_owned())
        } else {
            (t.accepted.to_string(), t.errors.to_string())
        };
        println!(
            "| {kind} ({} steps) | {} | {accepted} | {errors} | {} | {} | {} | {} | {} | {} |",
            t.steps,
            t.inputs,
            t.panics,
            s.aborts.len(),
            s.hangs.len(),
            t.quarantines,
            t.silent,
            t.snapshot_mismatches
        );
        // The last report of a kind is its smallest failing case (proptest shrinks to it).
        failures.extend(s.reports.last().map(|r| format!("{kind}: {r}")));
        for k in &s.aborts {
            failures.push(format!("{kind}: case {k} aborted"));
        }
        for k in &s.hangs {
            failures.push(format!("{kind}: case {k} hung (no output for 300 s)"));
        }
    }
    for failure in &failures {
        println!("\nfailed: {failure}");
    }
    println!("\n{:.0} s", start.elapsed().as_secs_f64());
}
