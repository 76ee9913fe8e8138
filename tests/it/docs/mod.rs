//! What the README shows, run as written.

mod images;
mod readme;
mod readme_bevy;
