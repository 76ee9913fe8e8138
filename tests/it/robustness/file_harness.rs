//! The fuzz of what is read from disk, shared by `robustness::fuzz` and `examples/fuzz.rs`:
//! snapshots of fuzzed worlds with their bytes or their RON edited (a CRC re-sealed after
//! the edit, so that the checks past the checksum are reached), and the scenario corpus with
//! its numbers replaced by wild ones. Each input is read, restored or run, then stepped and
//! checked as a fuzzed world is.
#![allow(dead_code)]

use std::panic::{AssertUnwindSafe, catch_unwind};

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenario::Scenario;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

use super::harness::{self, Cases, Tally, WorldCase};

/// The bytes of a snapshot's header before its payload: magic, version, length, CRC.
const HEADER: usize = 24;

/// What is done to a file before it is read.
#[derive(Debug, Clone)]
pub enum Edit {
    /// Bytes of the payload set to values, the CRC re-sealed.
    Bytes(Vec<(u32, u8)>),
    /// Bytes anywhere set to values, the CRC left as it was.
    RawBytes(Vec<(u32, u8)>),
    /// Cut to a fraction of its length (per mille).
    Truncate(u16),
    /// Numbers of the text replaced by wild ones: (which number, which wild value).
    Numbers(Vec<(u32, u8)>),
    /// Characters of the text deleted.
    Delete(Vec<u32>),
}

fn edit() -> impl Strategy<Value = Edit> {
    let spots = || prop::collection::vec((any::<u32>(), any::<u8>()), 1..6);
    prop_oneof![
        3 => spots().prop_map(Edit::Bytes),
        1 => spots().prop_map(Edit::RawBytes),
        1 => (0u16..1000).prop_map(Edit::Truncate),
        4 => spots().prop_map(Edit::Numbers),
        1 => prop::collection::vec(any::<u32>(), 1..4).prop_map(Edit::Delete),
    ]
}

/// Numbers a hostile file holds, as RON writes them.
const WILD: [&str; 16] = [
    "NaN",
    "inf",
    "-inf",
    "-1",
    "0",
    "-0.0",
    "1e30",
    "-1e30",
    "1e-30",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "9223372036854775807",
    "255",
    "1000000",
    "0.5",
];

/// The byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        // A digit inside a name (p12) is not a number.
        let in_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !in_word {
            let mut j = i + 1;
            while j < b.len()
                && (b[j].is_ascii_digit() || matches!(b[j], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                j += 1;
            }
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// `text` with `edit` applied (byte edits act on its UTF-8 and keep it valid by dropping
/// what no longer decodes).
fn edit_text(text: &str, edit: &Edit) -> String {
    match edit {
        Edit::Numbers(spots) => {
            let found = numbers(text);
            if found.is_empty() {
                return text.to_owned();
            }
            let mut chosen: Vec<(usize, usize, &str)> = spots
                .iter()
                .map(|&(k, w)| {
                    let (a, b) = found[k as usize % found.len()];
                    (a, b, WILD[w as usize % WILD.len()])
                })
                .collect();
            chosen.sort_unstable_by_key(|c| std::cmp::Reverse(c.0));
            chosen.dedup_by_key(|c| c.0);
            let mut out = text.to_owned();
            for (a, b, w) in chosen {
                out.replace_range(a..b, w);
            }
            out
        }
        Edit::Delete(at) => {
            let mut chars: Vec<char> = text.chars().collect();
            for &k in at {
                if !chars.is_empty() {
                    let i = k as usize % chars.len();
                    chars.remove(i);
                }
            }
            chars.into_iter().collect()
        }
        other => String::from_utf8_lossy(&edit_bytes(text.as_bytes(), other)).into_owned(),
    }
}

/// `bytes` with `edit` applied; a `Bytes` edit re-seals the snapshot's CRC.
fn edit_bytes(bytes: &[u8], edit: &Edit) -> Vec<u8> {
    let mut out = bytes.to_vec();
    match edit {
        Edit::Bytes(spots) if out.len() > HEADER => {
            let n = out.len() - HEADER;
            for &(k, v) in spots {
                out[HEADER + k as usize % n] = v;
            }
            let crc = crc32fast::hash(&out[HEADER..]);
            out[20..24].copy_from_slice(&crc.to_le_bytes());
        }
        Edit::Bytes(spots) | Edit::RawBytes(spots) => {
            let n = out.len().max(1);
            for &(k, v) in spots {
                if let Some(b) = out.get_mut(k as usize % n) {
                    *b = v;
                }
            }
        }
        Edit::Truncate(per_mille) => out.truncate(out.len() * usize::from(*per_mille) / 1000),
        Edit::Numbers(_) | Edit::Delete(_) => {}
    }
    out
}

/// Outcome of one input: read and ran (`Ok(silent)`), refused with a typed error, or
/// panicked.
fn count(tally: &mut Tally, outcome: std::thread::Result<Option<usize>>) {
    tally.inputs += 1;
    match outcome {
        Ok(Some(silent)) => {
            tally.accepted += 1;
            tally.silent += silent;
        }
        Ok(None) => tally.errors += 1,
        Err(_) => tally.panics += 1,
    }
}

/// Restores `read` into a fresh world and steps it; `None` if it was refused.
fn restore_and_step(
    read: Result<Snapshot, hooke::snapshot::SnapshotError>,
    tally: &mut Tally,
) -> Option<usize> {
    let snapshot = read.ok()?;
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    snapshot.restore(&mut world).ok()?;
    let mut silent = 0;
    for _ in 0..20 {
        world.step_physics();
        tally.steps += 1;
        silent += harness::silent_bad(&mut world);
    }
    tally.quarantines += world.query::<&Quarantined>().iter(&world).count();
    Some(silent)
}

/// One snapshot case: the world of `case` saved, edited, read, restored and stepped.
pub fn run_snapshot(case: &WorldCase, edit: &Edit, tally: &mut Tally) {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let world = harness::play(case);
        let snapshot = Snapshot::capture(&world).expect("no custom fields here");
        let mut t = Tally::default();
        let silent = match edit {
            Edit::Numbers(_) | Edit::Delete(_) => {
                let text = snapshot.to_ron().expect("own RON");
                restore_and_step(Snapshot::from_ron(&edit_text(&text, edit)), &mut t)
            }
            _ => restore_and_step(
                Snapshot::from_bytes(&edit_bytes(&snapshot.to_bytes(), edit)),
                &mut t,
            ),
        };
        (silent, t)
    }));
    let outcome = outcome.map(|(silent, t)| {
        tally.steps += t.steps;
        tally.quarantines += t.quarantines;
        silent
    });
    if matches!(outcome, Err(_) | Ok(Some(1..))) {
        println!("snapshot failure: {edit:?} of {case:?}");
    }
    count(tally, outcome);
}

/// Runs `cases` edited snapshots from `seed`.
pub fn fuzz_snapshots(cases: u32, seed: u64, which: Cases) -> Tally {
    let which = std::cell::RefCell::new(which);
    let mut tally = Tally::default();
    let mut runner = harness::runner(cases, seed);
    let cell = std::cell::RefCell::new((&mut tally, Tally::default(), false));
    let result = runner.run(&(harness::world_case(), edit()), |(case, edit)| {
        let (tally, scratch, failed) = &mut *cell.borrow_mut();
        if !*failed && !which.borrow_mut().take(tally) {
            return Ok(());
        }
        let t: &mut Tally = if *failed { scratch } else { tally };
        let before = (t.panics, t.silent);
        run_snapshot(&case, &edit, t);
        if (t.panics, t.silent) != before {
            *failed = true;
            return Err(TestCaseError::fail("a panic or a silent non-finite body"));
        }
        Ok(())
    });
    tally.failure = harness::shrunk(result);
    tally
}

/// The scenario corpus: (file name, text).
pub fn corpus() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.sort();
    files
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .filter_map(|p| {
            Some((
                p.file_name()?.to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).ok()?,
            ))
        })
        .collect()
}

/// The most steps × substeps × entities an edited scenario is run for (a wild duration,
/// substep count or column height is read and checked, and run only up to this budget: a
/// column of 10⁶ boxes for 5 s is slow, not stuck).
const RUN_BUDGET: u64 = 200_000;

/// One scenario case: a corpus file edited, read and (if cheap enough) run.
pub fn run_scenario(file: &(String, String), edit: &Edit, tally: &mut Tally) {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let text = edit_text(&file.1, edit);
        let trace = std::env::var_os("HOOKE_FUZZ_TRACE").is_some();
        if trace {
            println!("{}:\n{text}", file.0);
        }
        let scenario = Scenario::from_str(&text, &file.0).ok()?;
        let cost = scenario
            .steps()
            .saturating_mul(u64::from(scenario.settings().substeps))
            .saturating_mul(scenario.entities_spawned().max(1));
        if trace {
            println!(
                "read: {} steps x {}",
                scenario.steps(),
                scenario.settings().substeps
            );
        }
        if cost > RUN_BUDGET {
            return Some(0);
        }
        // An expectation that fails is a result, not an error; a build error is typed.
        scenario.run().ok().map(|_| 0)
    }));
    if outcome.is_err() {
        println!("scenario panic: {edit:?} of {}", file.0);
    }
    count(tally, outcome);
}

/// Runs `cases` edited scenario files from `seed`.
pub fn fuzz_scenarios(cases: u32, seed: u64, which: Cases) -> Tally {
    let which = std::cell::RefCell::new(which);
    let files = corpus();
    assert!(!files.is_empty(), "the corpus is found");
    let mut tally = Tally::default();
    let mut runner = harness::runner(cases, seed);
    let cell = std::cell::RefCell::new((&mut tally, Tally::default(), false));
    let result = runner.run(&(any::<u32>(), edit()), |(pick, edit)| {
        let (tally, scratch, failed) = &mut *cell.borrow_mut();
        if !*failed && !which.borrow_mut().take(tally) {
            return Ok(());
        }
        let t: &mut Tally = if *failed { scratch } else { tally };
        let before = t.panics;
        run_scenario(&files[pick as usize % files.len()], &edit, t);
        if t.panics != before {
            *failed = true;
            return Err(TestCaseError::fail("a panic"));
        }
        Ok(())
    });
    tally.failure = harness::shrunk(result);
    tally
}

/// A child's run: `kind` (one of [`super::supervisor::KINDS`]) from case `skip` of
/// `cases`, each announced, then its tally line.
pub fn child(kind: &str, cases: u32, seed: u64, skip: u32) {
    let which = Cases::announced_from(skip);
    let t = match kind {
        "worlds" => harness::fuzz_worlds_of(cases, seed, true, which),
        "snapshots" => fuzz_snapshots(cases, seed, which),
        "scenarios" => fuzz_scenarios(cases, seed, which),
        _ => Tally::default(),
    };
    println!("{}", super::supervisor::tally_line(&t));
}
