//! Systems of the particle effects: gravity, damping and velocity-field advection.

use bevy_ecs::prelude::*;
use glam::Vec3A;

use super::fields::{Advection, Gravity, VelocityField};
use super::fields::{advect_euler, advect_midpoint, advect_rk4};
use super::{Force, LinearDamping, LinearVelocity, Mass, Position, Tracer};
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::quarantine_non_finite;
use crate::core::rest::Simulated;
use crate::core::schedule::{
    ForceSystems, StepSystems, SubstepSchedule, add_own_force_systems, add_own_systems,
};
use crate::core::time::SubstepTime;

/// Uniform gravity, f = m g s: installs the [`Gravity`] resource. Gravity is a constant
/// force, so the core's force-clearing pass writes it into each accumulator (see
/// [`crate::core::schedule::StepSystems::ClearForces`]); this plugin adds no system, and a world
/// without it has no gravity at all.
#[derive(Debug, Default, Clone, Copy)]
pub struct GravityPlugin;

impl WorldPlugin for GravityPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<Gravity>(world);
        crate::core::quarantine::validate_writes::<super::GravityScale>(world);
    }
}

/// Linear drag f = −c m v for bodies with [`LinearDamping`]. Runs only while one exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct DampingPlugin;

impl WorldPlugin for DampingPlugin {
    fn build(&self, world: &mut World) {
        crate::core::whole_step::block_on::<LinearDamping>(world);
        add_own_force_systems(world, || {
            apply_damping
                .run_if(any_with_component::<LinearDamping>)
                .in_set(ForceSystems::Damping)
        });
    }
}

fn apply_damping(
    mut bodies: Query<(&mut Force, &LinearVelocity, &Mass, &LinearDamping), Simulated>,
) {
    for (mut f, v, m, c) in &mut bodies {
        f.bypass_change_detection().0 -= (c.0 * m.force_scale()) * v.0;
    }
}

/// Advects [`Tracer`]s through the [`VelocityField`]s. Runs only while a tracer exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct VelocityFieldPlugin;

impl WorldPlugin for VelocityFieldPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<Advection>(world);
        crate::core::whole_step::block_on::<Tracer>(world);
        add_own_systems(
            world,
            SubstepSchedule,
            advect_tracers
                .run_if(any_with_component::<Tracer>)
                .in_set(StepSystems::IntegratePositions),
        );
    }
}

/// Tracers are massless; `Without<Mass>` also proves to the scheduler that this query never
/// aliases the particle integrator's positions.
type TracerFilter = (With<Tracer>, Without<Mass>, Simulated);

fn advect_tracers(
    mut commands: Commands,
    scheme: Res<Advection>,
    time: Res<SubstepTime>,
    fields: Query<&VelocityField>,
    mut tracers: Query<(Entity, &mut Position), TracerFilter>,
) {
    if fields.is_empty() {
        return;
    }
    let (t, h) = (time.t, time.h);
    let u = |x: Vec3A, t: f32| fields.iter().map(|f| f.velocity(x, t)).sum::<Vec3A>();
    for (e, mut p) in &mut tracers {
        let x = p.0;
        let x = match *scheme {
            Advection::Euler => advect_euler(x, t, h, u),
            Advection::Midpoint => advect_midpoint(x, t, h, u),
            Advection::Rk4 => advect_rk4(x, t, h, u),
        };
        if x.is_finite() {
            p.0 = x;
        } else {
            quarantine_non_finite(&mut commands, e);
        }
    }
}
