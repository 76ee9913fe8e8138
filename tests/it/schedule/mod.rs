//! The one order: schedules, plugins, diagnostics and the test helpers.

mod schedule;
mod testing_helpers;
