//! The long fuzz run: `cargo run --release --example fuzz -- --cases 20000 --seed 1` (worlds; ten
//! times as many constructor cases). Prints the table in the README.

#[path = "../tests/it/robustness/harness.rs"]
mod harness;

fn main() {
    let cases: u32 = std::env::args()
        .skip_while(|a| a != "--cases")
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let seed: u64 = std::env::args()
        .skip_while(|a| a != "--seed")
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    // Panics are counted, not printed (each is also reported with its case).
    std::panic::set_hook(Box::new(|_| {}));
    let start = std::time::Instant::now();
    let c = harness::fuzz_constructors(cases * 10, seed);
    let w = harness::fuzz_worlds(cases, seed, true);
    println!(
        "| fuzzed | inputs | accepted | typed errors | panics | quarantines | silent NaN / unbounded | snapshot mismatches |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    println!(
        "| constructor calls | {} | {} | {} | {} | – | – | – |",
        c.inputs, c.accepted, c.errors, c.panics
    );
    println!(
        "| worlds ({} steps) | {} | – | – | {} | {} | {} | {} |",
        w.steps, w.inputs, w.panics, w.quarantines, w.silent, w.snapshot_mismatches
    );
    for failure in [&c.failure, &w.failure].into_iter().flatten() {
        println!("\nfailed: {failure}");
    }
    println!("\n{:.0} s", start.elapsed().as_secs_f64());
}
