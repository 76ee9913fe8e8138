//! Joints against closed forms, at the defaults.

mod hard_cases;
mod motors;
mod pendulums;
