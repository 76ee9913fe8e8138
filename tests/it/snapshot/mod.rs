//! Snapshots and determinism goldens: a restored world continues bit for bit.

mod determinism_goldens;
mod snapshot;
