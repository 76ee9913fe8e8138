//! Fuzzing in CI, on a bounded budget: every public constructor with wild numbers, and random
//! small worlds of every effect built through the public API, with game code meddling
//! mid-run (despawns, NaN and huge writes through `get_mut`, kicks, bad settings). Nothing
//! may panic, every body not quarantined must stay finite and within 1e6 m, and a snapshot
//! of each world must continue bit-identically. The long run is
//! `cargo run --release --example fuzz -- --cases 20000 --seed 1` (any seed).

use std::process::Command;
use std::time::Duration;

use super::{file_harness, harness, supervisor};

/// The CI run's seed: the same inputs every run.
const SEED: u64 = 15;

/// Cases per run: `HOOKE_FUZZ_CASES` or the CI budget.
fn cases(default: u32) -> u32 {
    std::env::var("HOOKE_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

#[test]
fn constructors_never_panic_and_accept_only_valid_input() {
    let n = cases(20_000);
    let t = harness::fuzz_constructors(n, SEED);
    println!("constructors: {t:?}");
    assert_eq!(t.failure, None, "shrunk to the smallest failing case");
    assert_eq!(t.panics, 0, "{t:?}");
    assert!(
        t.inputs >= n as usize * 40,
        "every case calls every constructor: {t:?}"
    );
    assert!(
        t.errors > t.inputs / 10 && t.accepted > t.inputs / 10,
        "{t:?}"
    );
}

#[test]
fn random_worlds_never_panic_or_go_silently_bad() {
    let n = cases(1500);
    let t = harness::fuzz_worlds(n, SEED, true);
    println!("worlds: {t:?}");
    assert_eq!(t.failure, None, "shrunk to the smallest failing case");
    assert_eq!(t.inputs, n as usize);
    assert_eq!(t.panics, 0, "{t:?}");
    assert_eq!(t.silent, 0, "{t:?}");
    assert_eq!(t.snapshot_mismatches, 0, "{t:?}");
}

#[test]
fn edited_snapshots_are_refused_or_run_never_panic() {
    let n = cases(400);
    let t = file_harness::fuzz_snapshots(n, SEED, Default::default());
    println!("snapshots: {t:?}");
    assert_eq!(t.failure, None, "shrunk to the smallest failing case");
    assert_eq!(t.inputs, n as usize);
    assert_eq!((t.panics, t.silent), (0, 0), "{t:?}");
    // Both sides are reached: edits the checks refuse, and edits that still restore.
    assert!(
        t.errors > t.inputs / 10 && t.accepted > t.inputs / 10,
        "{t:?}"
    );
}

#[test]
fn edited_scenario_files_are_refused_or_run_never_panic() {
    let n = cases(600);
    let t = file_harness::fuzz_scenarios(n, SEED, Default::default());
    println!("scenarios: {t:?}");
    assert_eq!(t.failure, None, "shrunk to the smallest failing case");
    assert_eq!(t.inputs, n as usize);
    assert_eq!(t.panics, 0, "{t:?}");
    assert!(
        t.errors > t.inputs / 10 && t.accepted > t.inputs / 10,
        "{t:?}"
    );
}

/// The child process of the supervised tests: runs what `HOOKE_FUZZ_CHILD` names
/// (`KIND CASES SEED SKIP`, or `probe CASES SKIP`); ignored, so only a supervising parent
/// runs it.
#[test]
#[ignore = "run by the supervised tests in a child process"]
fn child() {
    let Ok(spec) = std::env::var("HOOKE_FUZZ_CHILD") else {
        return;
    };
    let n: Vec<u64> = spec
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    let kind = spec.split_whitespace().next().unwrap_or("");
    match (kind, &n[..]) {
        ("probe", &[cases, skip]) => probe(cases, skip),
        (kind, &[cases, seed, skip]) => file_harness::child(kind, cases as u32, seed, skip as u32),
        _ => {}
    }
}

/// A child that aborts at case 3 and hangs at case 6: what the supervisor must catch.
fn probe(cases: u64, skip: u64) {
    let mut t = harness::Tally::default();
    for k in skip..cases {
        println!("done{}", &supervisor::tally_line(&t)["tally".len()..]);
        println!("case {k}");
        match k {
            3 => std::process::abort(),
            6 => std::thread::sleep(Duration::from_secs(3600)),
            _ => t.inputs += 1,
        }
    }
    println!("{}", supervisor::tally_line(&t));
}

fn child_process(spec: String) -> Command {
    let mut c = Command::new(std::env::current_exe().expect("the test binary"));
    c.args([
        "--exact",
        "robustness::fuzz::child",
        "--ignored",
        "--nocapture",
    ])
    .env("HOOKE_FUZZ_CHILD", spec);
    c
}

#[test]
fn the_supervisor_counts_aborts_and_hangs_apart() {
    let s = supervisor::supervise(
        |skip| child_process(format!("probe 10 {skip}")),
        10,
        Duration::from_secs(5),
    );
    println!("{s:?}");
    assert_eq!(s.aborts, vec![3], "the abort at case 3");
    assert_eq!(s.hangs, vec![6], "the hang at case 6");
    // Cases 0 to 2 in the first child (it died: its last `done` counts), 4 and 5 in the
    // second (killed), 7 to 9 in the third: none is lost.
    assert_eq!(s.tally.inputs, 8, "every case that ran is counted");
}

#[test]
fn fuzz_in_child_processes_finds_no_abort_or_hang() {
    for (kind, n) in supervisor::KINDS
        .into_iter()
        .zip([cases(200), cases(400), cases(400)])
    {
        let s = supervisor::supervise(
            |skip| child_process(format!("{kind} {n} {} {skip}", SEED + 1)),
            n,
            Duration::from_secs(120),
        );
        println!("{kind}: {s:?}");
        assert_eq!((&s.aborts, &s.hangs), (&vec![], &vec![]), "{kind}: {s:?}");
        assert_eq!(s.tally.inputs, n as usize, "{kind}: every case ran");
        assert_eq!((s.tally.panics, s.tally.silent), (0, 0), "{kind}: {s:?}");
        assert_eq!(s.tally.snapshot_mismatches, 0, "{kind}: {s:?}");
    }
}
