//! Scenario files: checks, the corpus with its pinned hashes, errors and the command line.

mod checks;
mod cli;
mod corpus;
mod errors;
mod hostile_expressions;
