//! Bad input and fuzzing: typed errors, quarantine, never a panic.

mod bad_input;
mod bad_input_caught;
mod bounded_clock;
mod closed_worlds_never_gain_energy;
mod file_counts_never_overflow;
mod file_harness;
mod fuzz;
mod fuzz_findings;
mod harness;
mod restores_validate;
mod runaway_velocity_quarantined_first;
mod sizes_are_bounded;
mod supervisor;
mod world_cases;
