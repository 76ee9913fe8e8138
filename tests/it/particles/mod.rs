//! Particles and tracers: free fall, projectiles, damping and velocity fields against closed forms.

mod free_fall_and_fields;
