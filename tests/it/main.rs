//! hooke's integration tests: one binary, a module per subject.

mod architecture;
mod bevy;
mod character;
mod cloth;
mod collision;
mod common;
mod docs;
mod integrators;
mod joints;
mod particles;
mod rigid;
mod robustness;
mod scenario;
mod schedule;
mod sleep;
mod snapshot;
mod soft;
mod springs;
