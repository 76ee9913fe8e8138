//! The Bevy layer: App clock, Transform sync, spawning by required components, prelude imports.

mod app;
mod character_in_app;
mod collision_hooks_and_reports_in_app;
mod debug_view;
mod locked_axes_in_app;
mod preludes;
mod reflection;
mod required_components_spawning;
mod teleports_under_interpolation;
