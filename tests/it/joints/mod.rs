//! Joints against closed forms, at the defaults.

mod pendulums;
