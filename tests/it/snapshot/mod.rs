//! Snapshots and determinism goldens: a restored world continues bit for bit.

mod continue_bit_identically;
mod determinism_goldens;
mod joints_continue_bit_identically;
