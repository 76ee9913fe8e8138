//! Particles and tracers: free fall, projectiles, damping and velocity fields against closed forms.

mod particles;
