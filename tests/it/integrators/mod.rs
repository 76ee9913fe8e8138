//! The integrator dial: orders and energy on closed forms, the accuracy sweep, and the whole-step path.

mod accuracy_sweep;
mod oscillator_orders;
mod whole_step;
