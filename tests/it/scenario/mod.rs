//! Scenario files: checks, the corpus with its pinned hashes, errors and the command line.

mod checks;
mod cli;
mod corpus;
mod errors;
mod hostile_expressions;
mod large_files_read_in_linear_time;
