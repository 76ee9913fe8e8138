//! Fuzzing in CI, on a bounded budget: every public constructor with wild numbers, and random
//! small worlds of every effect built through the public API, with game code meddling
//! mid-run (despawns, NaN and huge writes through `get_mut`, kicks, bad settings). Nothing
//! may panic, every body not quarantined must stay finite and within 1e6 m, and a snapshot
//! of each world must continue bit-identically. The long run is
//! `cargo run --release --example fuzz -- --cases 20000 --seed 1` (any seed).

use super::harness;

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
