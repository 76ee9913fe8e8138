//! Systems of the particle effects: gravity, damping and velocity-field advection.

use bevy_ecs::prelude::*;
use glam::Vec3A;

use super::fields::{Advection, Gravity, VelocityField};
use super::{Force, GravityScale, LinearDamping, LinearVelocity, Mass, Nodes, Position, Tracer};
use crate::Plugin;
use crate::integrator::{advect_euler, advect_midpoint, advect_rk4};
use crate::quarantine::{QuarantineReason, Quarantined};
use crate::schedule::{ForceSystems, StepSystems, SubstepSchedule, add_force_systems, add_systems};
use crate::time::SubstepTime;

type Live = Without<Quarantined>;

/// Uniform gravity, f = m g s. Runs only while some body has a [`Mass`] or [`Nodes`].
#[derive(Debug, Default, Clone, Copy)]
pub struct GravityPlugin;

impl Plugin for GravityPlugin {
    fn build(&self, world: &mut World) {
        world.init_resource::<Gravity>();
        add_force_systems(world, || {
            apply_gravity
                .run_if(any_massive_body)
                .in_set(ForceSystems::Gravity)
        });
    }
}

/// True while a particle or mesh exists: the condition of every mass-proportional force.
pub(crate) fn any_massive_body(p: Query<(), With<Mass>>, m: Query<(), With<Nodes>>) -> bool {
    !(p.is_empty() && m.is_empty())
}

fn apply_gravity(
    gravity: Res<Gravity>,
    mut plain: Query<(&mut Force, &Mass), (Without<GravityScale>, Live)>,
    mut scaled: Query<(&mut Force, &Mass, &GravityScale), Live>,
    mut meshes: Query<&mut Nodes, Live>,
) {
    let g = gravity.get();
    if g == glam::Vec3::ZERO {
        return;
    }
    for (mut f, m) in &mut plain {
        f.bypass_change_detection().0 += m.force_scale() * g;
    }
    for (mut f, m, s) in &mut scaled {
        f.bypass_change_detection().0 += (m.force_scale() * s.0) * g;
    }
    let g = Vec3A::from(g);
    for mut nodes in &mut meshes {
        let n = nodes.bypass_change_detection();
        for (f, m) in n.f.iter_mut().zip(&n.mass) {
            *f += *m * g;
        }
    }
}

/// Linear drag f = −c m v for bodies with [`LinearDamping`]. Runs only while one exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct DampingPlugin;

impl Plugin for DampingPlugin {
    fn build(&self, world: &mut World) {
        add_force_systems(world, || {
            apply_damping
                .run_if(any_with_component::<LinearDamping>)
                .in_set(ForceSystems::Damping)
        });
    }
}

fn apply_damping(mut bodies: Query<(&mut Force, &LinearVelocity, &Mass, &LinearDamping), Live>) {
    for (mut f, v, m, c) in &mut bodies {
        f.bypass_change_detection().0 -= (c.0 * m.force_scale()) * v.0;
    }
}

/// Advects [`Tracer`]s through the [`VelocityField`]s. Runs only while a tracer exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct VelocityFieldPlugin;

impl Plugin for VelocityFieldPlugin {
    fn build(&self, world: &mut World) {
        world.init_resource::<Advection>();
        add_systems(
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
type TracerFilter = (With<Tracer>, Without<Mass>, Live);

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
        let x = Vec3A::from(p.0);
        let x = match *scheme {
            Advection::Euler => advect_euler(x, t, h, u),
            Advection::Midpoint => advect_midpoint(x, t, h, u),
            Advection::Rk4 => advect_rk4(x, t, h, u),
        };
        if x.is_finite() {
            p.0 = x.into();
        } else {
            commands.entity(e).insert(Quarantined {
                reason: QuarantineReason::NonFiniteState,
            });
        }
    }
}
