//! The one order: schedules, plugins, diagnostics and the test helpers.

mod order_and_plugins;
mod testing_helpers;
