//! What the README shows, run as written.

mod readme;
mod readme_bevy;
