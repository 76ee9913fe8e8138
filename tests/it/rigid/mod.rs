//! Rigid bodies: torque-free motion, mass properties from shapes, and a cross-check with rapier.

mod dominance_pushes_without_being_pushed;
mod forces_without_inserting_first;
mod locked_axes_keep_the_constrained_motion;
mod mass;
mod rapier_crosscheck;
mod torque_free_motion;
