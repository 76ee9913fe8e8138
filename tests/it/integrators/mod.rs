//! The integrator dial: orders and energy on closed forms, the accuracy sweep, and the whole-step path.

mod accuracy_sweep;
mod backward_euler_keeps_small_motions;
mod oscillator_orders;
mod whole_step;
