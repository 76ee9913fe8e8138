//! The integration systems shared by particle entities and [`Nodes`] meshes.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use super::{Integrator, IntegratorOverride, drift, explicit_euler, kick, mesh_divergence};
use crate::core::diagnostics::energy_on;
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::{DivergenceGuard, Quarantined, quarantine_non_finite};
use crate::core::rest::Simulated;
use crate::core::schedule::{
    IntegrationSystems, MeasureSystems, PhysicsSchedule, PositionSystems, PrepareSystems,
    StepSystems, SubstepSchedule, add_own_force_systems, add_own_systems,
};
use crate::core::time::SubstepTime;
use crate::particles::{
    ExternalForce, ExternalImpulse, Force, Gravity, GravityScale, LinearVelocity, Mass, Nodes,
    Position, Tracer,
};
use crate::rigid::{
    AngularMomentum, CenterOfMass, ExternalImpulseAtPoint, ExternalTorque, Inertia, LockedAxes,
    Rotation, Torque, world_point,
};

/// Whether any constraint (contact, joint) acts in this step. Constraint plugins set it in
/// [`crate::core::schedule::PhysicsSystems::Prepare`]. While it is false nothing runs between the velocity and
/// the position half of symplectic Euler, so particles take both halves in one pass: the same
/// arithmetic, bit for bit, with one read of memory instead of two.
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct ConstraintsActive(pub bool);

impl ConstraintsActive {
    fn fuses(self, method: Integrator) -> bool {
        !self.0 && method.kicks_then_drifts()
    }
}

/// Integration, force clearing, impulses and the NaN quarantine of moving bodies. Part of the
/// core: every other effect needs it.
#[derive(Debug, Default, Clone, Copy)]
pub struct IntegratorPlugin;

impl WorldPlugin for IntegratorPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<Integrator>(world);
        crate::core::restore::init::<ConstraintsActive>(world);
        world.init_resource::<super::stages::Rk4Starts>();
        world.init_resource::<super::stages::Rk4TurnStarts>();
        crate::core::restore::init::<super::StabilityPolicy>(world);
        crate::core::plugin::add_message::<super::StabilityWarning>(world);
        crate::core::restore::init::<super::stability::SharedNumericalDamping>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            // It writes only its own diagnostics field: its order among the reports is free.
            super::stability::report_numerical_damping
                .ambiguous_with_all()
                .in_set(crate::core::schedule::FinishSystems::Writeback),
        );
        // The whole-step path integrates rigid bodies only, with constant forces.
        crate::core::whole_step::block_on::<ExternalImpulse>(world);
        crate::core::whole_step::block_on::<ExternalImpulseAtPoint>(world);
        crate::core::whole_step::block_on::<IntegratorOverride>(world);
        crate::core::whole_step::block_on::<Nodes>(world);
        crate::core::plugin::moves::<Mass>(world);
        crate::core::plugin::moves::<Nodes>(world);
        crate::core::plugin::moves::<Tracer>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                quarantine_runaway_velocities.in_set(PrepareSystems::Guard),
                // Again at the end, over what the step itself wrote (a contact or a spring
                // can leave a body past the guard after its integrator's check): the state
                // a step leaves, and so a snapshot of it, holds no unreported runaway.
                // Before, the next step caught it by its change tick, which a restored copy
                // does not have, and the copy went on differently.
                quarantine_runaway_velocities
                    .in_set(crate::core::schedule::FinishSystems::Diagnostics),
            ),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            MeasureSystems::configure(super::measure::measure_motion.run_if(energy_on)),
        );
        add_own_force_systems(world, || clear_forces.in_set(StepSystems::ClearForces));
        add_own_systems(
            world,
            SubstepSchedule,
            (
                apply_impulses
                    .run_if(
                        any_with_component::<ExternalImpulse>
                            .or_else(any_with_component::<ExternalImpulseAtPoint>),
                    )
                    .in_set(IntegrationSystems::Impulses),
                integrate_velocities.in_set(IntegrationSystems::Integrate),
                super::rotation::integrate_angular_momenta
                    .run_if(any_with_component::<Inertia>)
                    .in_set(IntegrationSystems::Integrate),
                integrate_positions.in_set(PositionSystems::Integrate),
                super::rotation::integrate_orientations
                    .run_if(any_with_component::<Inertia>)
                    .in_set(PositionSystems::Integrate),
                super::stages::complete_stages
                    .run_if(super::stages::needs_stages)
                    .in_set(StepSystems::CompleteStages),
            ),
        );
    }
}

/// Initialises every accumulator with the body's constant forces, f ← f_ext + m g s, and
/// every torque accumulator with its constant torque, τ ← τ_ext.
///
/// Gravity and external forces don't depend on the state, so they are written here in the one
/// pass that has to touch every accumulator anyway; state-dependent forces are added in
/// [`StepSystems::ApplyForces`]. Without the gravity plugin there is no [`Gravity`] resource
/// and g = 0. On a million particles this saves a full sweep of memory per substep.
#[allow(clippy::type_complexity)] // four disjoint archetype filters; naming them adds nothing
pub(crate) fn clear_forces(
    gravity: Option<Res<Gravity>>,
    mut plain: Query<
        (&mut Force, &Mass),
        (Without<ExternalForce>, Without<GravityScale>, Simulated),
    >,
    mut scaled: Query<(&mut Force, &Mass, &GravityScale), (Without<ExternalForce>, Simulated)>,
    mut external: Query<(&mut Force, &Mass, &ExternalForce, Option<&GravityScale>), Simulated>,
    mut meshes: Query<&mut Nodes, Simulated>,
    mut plain_torques: Query<&mut Torque, (Without<ExternalTorque>, Simulated)>,
    mut external_torques: Query<(&mut Torque, &ExternalTorque), Simulated>,
) {
    let g = gravity.map_or(Vec3A::ZERO, |g| g.get().into());
    // Force is an accumulator nobody watches for changes; skipping the tick write keeps
    // this pass at raw-loop speed.
    plain
        .iter_mut()
        .for_each(|(mut f, m)| f.bypass_change_detection().0 = constant_force(m, None, None, g));
    scaled.iter_mut().for_each(|(mut f, m, s)| {
        f.bypass_change_detection().0 = constant_force(m, None, Some(s), g);
    });
    external.iter_mut().for_each(|(mut f, m, ext, s)| {
        f.bypass_change_detection().0 = constant_force(m, Some(ext), s, g);
    });
    for mut nodes in &mut meshes {
        let n = nodes.bypass_change_detection();
        for (f, m) in n.f.iter_mut().zip(&n.mass) {
            *f = *m * g;
        }
    }
    // Torques start at the external torque, likewise.
    plain_torques
        .iter_mut()
        .for_each(|mut t| t.bypass_change_detection().0 = Vec3A::ZERO);
    external_torques
        .iter_mut()
        .for_each(|(mut t, e)| t.bypass_change_detection().0 = e.0);
}

/// A body's constant force f_ext + m g s, which every substep's accumulator starts from.
#[must_use]
#[inline(always)]
pub(crate) fn constant_force(
    m: &Mass,
    ext: Option<&ExternalForce>,
    scale: Option<&GravityScale>,
    g: Vec3A,
) -> Vec3A {
    match (ext, scale) {
        (None, None) => m.force_scale() * g,
        (None, Some(s)) => (m.force_scale() * s.0) * g,
        (Some(ext), s) => Vec3A::from(ext.0) + (m.force_scale() * s.map_or(1.0, |s| s.0)) * g,
    }
}

/// Δv = J / m (and ΔL = r × J at a point), then J ← 0 without marking it changed, so the next
/// step sees no new impulse.
#[allow(clippy::type_complexity)] // two queries of plain component tuples
pub(crate) fn apply_impulses(
    mut bodies: Query<
        (
            &mut LinearVelocity,
            &mut ExternalImpulse,
            &Mass,
            Option<&LockedAxes>,
        ),
        (Changed<ExternalImpulse>, Simulated),
    >,
    mut at_points: Query<
        (
            &mut LinearVelocity,
            &mut AngularMomentum,
            &mut ExternalImpulseAtPoint,
            &Mass,
            &Inertia,
            &Position,
            &Rotation,
            Option<&CenterOfMass>,
            Option<&LockedAxes>,
        ),
        (
            Changed<ExternalImpulseAtPoint>,
            Without<ExternalImpulse>,
            Simulated,
        ),
    >,
) {
    for (mut v, mut j, m, locks) in &mut bodies {
        if j.0 != Vec3::ZERO {
            v.0 += Vec3A::from(j.0) * LockedAxes::inverse_mass_of(locks, m.inverse());
            j.bypass_change_detection().0 = Vec3::ZERO;
        }
    }
    for (mut v, mut l, mut j, m, inertia, x, q, com, locks) in &mut at_points {
        if j.impulse == Vec3::ZERO {
            continue;
        }
        let p = if j.local {
            world_point(x.0, q.0, com.map_or(Vec3::ZERO, |c| c.0), j.point)
        } else {
            j.point.into()
        };
        let impulse = Vec3A::from(j.impulse);
        v.0 += impulse * LockedAxes::inverse_mass_of(locks, m.inverse());
        if !inertia.is_infinite() {
            l.0 += (p - x.0).cross(impulse);
        }
        j.bypass_change_detection().impulse = Vec3::ZERO;
    }
}

/// The velocity half of a step; explicit Euler does its whole step here.
#[inline]
fn velocity_phase(method: Integrator, x: &mut Vec3A, v: &mut Vec3A, a: Vec3A, h: f32) {
    match method {
        Integrator::ExplicitEuler => (*x, *v) = explicit_euler(*x, *v, a, h),
        Integrator::SymplecticEuler | Integrator::ImplicitEuler => *v = kick(*v, a, h),
        Integrator::VelocityVerlet => *v = kick(*v, a, 0.5 * h),
        Integrator::Rk4 => {}
    }
}

/// The position half of a step.
#[inline]
fn position_phase(method: Integrator, x: &mut Vec3A, v: Vec3A, h: f32) {
    if matches!(
        method,
        Integrator::SymplecticEuler | Integrator::VelocityVerlet | Integrator::ImplicitEuler
    ) {
        *x = drift(*x, v, h);
    }
}

type IntegratedBody<'a> = (
    &'a mut Position,
    &'a mut LinearVelocity,
    &'a Force,
    &'a Mass,
);

#[allow(clippy::type_complexity, clippy::too_many_arguments)] // a system: one query or resource each
fn integrate_velocities(
    mut commands: Commands,
    guard: Res<DivergenceGuard>,
    global: Res<Integrator>,
    constraints: Res<ConstraintsActive>,
    time: Res<SubstepTime>,
    mut set: ParamSet<(
        Query<IntegratedBody, (Without<IntegratorOverride>, Simulated)>,
        Query<(IntegratedBody, &IntegratorOverride), Simulated>,
        Suspects,
        Query<Rk4Body, Simulated>,
    )>,
    mut meshes: Query<(&mut Nodes, Option<&IntegratorOverride>), super::ExplicitMesh>,
    mut starts: ResMut<super::stages::Rk4Starts>,
) {
    let h = time.h;
    let method = *global;
    starts.0.clear();
    if method == Integrator::Rk4 || !set.p1().is_empty() {
        // RK4 bodies kick and drift as symplectic Euler around the constraint solve, so that
        // contacts see this substep's approach; the stages replace that step by RK4's where
        // no constraint touched the body (see `stages::complete_stages`).
        for (e, x, mut v, f, m, o) in &mut set.p3() {
            if o.map_or(method, |o| o.0) == Integrator::Rk4 {
                let predicted = kick(v.0, f.0 * m.inverse(), h);
                starts.0.push((e, x.0, v.0, predicted));
                v.0 = predicted;
            }
        }
    }
    if constraints.fuses(method) {
        // Both halves of symplectic Euler in one pass; see `ConstraintsActive`.
        let mut probe = Vec3A::ZERO;
        // Speed is checked in the step's last substep only: the multiply costs 6% of this
        // loop, and a divergence is still caught in the step it happens.
        if time.index + 1 >= time.count {
            let (s, sx) = (guard.overflow_scale(), guard.distance_scale());
            set.p0().iter_mut().for_each(|(mut x, mut v, f, m)| {
                let va = kick(v.0, f.0 * m.inverse(), h);
                let xa = drift(x.0, va, h);
                probe += (xa * sx + va * s) * 0.0;
                v.0 = va;
                x.0 = xa;
            });
        } else {
            set.p0().iter_mut().for_each(|(mut x, mut v, f, m)| {
                let va = kick(v.0, f.0 * m.inverse(), h);
                let xa = drift(x.0, va, h);
                probe += (xa + va) * 0.0;
                v.0 = va;
                x.0 = xa;
            });
        }
        if probe != Vec3A::ZERO {
            quarantine_suspects(&mut commands, &set.p2(), &guard);
        }
    } else if method.kicks_then_drifts() {
        set.p0().iter_mut().for_each(|(_, mut v, f, m)| {
            v.0 = kick(v.0, f.0 * m.inverse(), h);
        });
    } else if method != Integrator::Rk4 {
        for (mut x, mut v, f, m) in &mut set.p0() {
            body_velocity_phase(method, &mut x, &mut v, f, m, h);
        }
    }
    for ((mut x, mut v, f, m), o) in &mut set.p1() {
        body_velocity_phase(o.0, &mut x, &mut v, f, m, h);
    }
    for (mut nodes, o) in &mut meshes {
        let method = o.map_or(method, |o| o.0);
        let n = nodes.bypass_change_detection();
        for i in 0..n.x.len() {
            let a = n.f[i] * n.inv_mass[i];
            velocity_phase(method, &mut n.x[i], &mut n.v[i], a, h);
        }
    }
}

fn body_velocity_phase(
    method: Integrator,
    x: &mut Mut<Position>,
    v: &mut Mut<LinearVelocity>,
    f: &Force,
    m: &Mass,
    h: f32,
) {
    let mut xa = x.0;
    let mut va = v.0;
    velocity_phase(method, &mut xa, &mut va, f.0 * m.inverse(), h);
    if method == Integrator::ExplicitEuler {
        x.0 = xa;
    }
    v.0 = va;
}

type Drift<'a> = (&'a mut Position, &'a LinearVelocity);

/// What RK4's prediction reads and writes of a body.
type Rk4Body<'a> = (
    Entity,
    &'a Position,
    &'a mut LinearVelocity,
    &'a Force,
    &'a Mass,
    Option<&'a IntegratorOverride>,
);

/// Finds the bodies whose state is non-finite; runs only after the fast pass saw one.
type Suspects<'w, 's> =
    Query<'w, 's, (Entity, &'static Position, &'static LinearVelocity), (With<Mass>, Simulated)>;

fn quarantine_suspects(commands: &mut Commands, suspects: &Suspects, guard: &DivergenceGuard) {
    for (e, x, v) in suspects {
        if !(x.0.is_finite() && v.0.is_finite()) {
            quarantine_non_finite(commands, e);
        } else if let Some(reason) = guard.check(x.0, v.0, None) {
            commands.entity(e).insert(Quarantined { reason });
        }
    }
}

/// A mesh whose nodes' probe found a non-finite lane or a fast axis: quarantined if it is
/// non-finite or its fastest node diverged.
fn check_mesh(commands: &mut Commands, e: Entity, n: &Nodes, guard: &DivergenceGuard) {
    if !n.is_finite() {
        quarantine_non_finite(commands, e);
    } else if let Some(reason) = mesh_divergence(n, guard) {
        commands.entity(e).insert(Quarantined { reason });
    }
}

#[allow(clippy::type_complexity)] // a ParamSet of queries; naming each adds nothing
fn integrate_positions(
    mut commands: Commands,
    guard: Res<DivergenceGuard>,
    global: Res<Integrator>,
    constraints: Res<ConstraintsActive>,
    time: Res<SubstepTime>,
    mut bodies: ParamSet<(
        Query<Drift, (With<Mass>, Without<IntegratorOverride>, Simulated)>,
        Query<(Drift, &IntegratorOverride), (With<Mass>, Simulated)>,
        Suspects,
    )>,
    mut meshes: Query<(Entity, &mut Nodes, Option<&IntegratorOverride>), super::ExplicitMesh>,
) {
    let h = time.h;
    let method = *global;
    // 0·x + 0·v stays zero unless a lane is NaN or infinite: a branch-free finiteness
    // check that keeps the loop vectorised.
    // Speed folded into the finiteness probe (see `DivergenceGuard::overflow_scale`).
    let mut probe = Vec3A::ZERO;
    // In the step's last substep only (see `integrate_velocities`).
    let (s, sx) = if time.index + 1 >= time.count {
        (guard.overflow_scale(), guard.distance_scale())
    } else {
        (0.0, 1.0)
    };
    if constraints.fuses(method) {
        // Done in the velocity pass.
    } else if matches!(
        method,
        Integrator::SymplecticEuler
            | Integrator::VelocityVerlet
            | Integrator::ImplicitEuler
            | Integrator::Rk4
    ) {
        bodies.p0().iter_mut().for_each(|(mut x, v)| {
            let (xa, va) = (x.0, v.0);
            let xa = drift(xa, va, h);
            probe += (xa * sx + va * s) * 0.0;
            x.0 = xa;
        });
    } else if method == Integrator::ExplicitEuler {
        // The whole step happened in the velocity phase; only check it.
        bodies
            .p0()
            .iter()
            .for_each(|(x, v)| probe += (x.0 * sx + v.0 * s) * 0.0);
    }
    bodies.p1().iter_mut().for_each(|((mut x, v), o)| {
        if matches!(
            o.0,
            Integrator::SymplecticEuler
                | Integrator::VelocityVerlet
                | Integrator::ImplicitEuler
                | Integrator::Rk4
        ) {
            x.0 = drift(x.0, v.0, h);
        }
        probe += (x.0 * sx + v.0 * s) * 0.0;
    });
    if probe != Vec3A::ZERO {
        quarantine_suspects(&mut commands, &bodies.p2(), &guard);
    }
    for (e, mut nodes, o) in &mut meshes {
        let method = o.map_or(method, |o| o.0);
        let n = nodes.bypass_change_detection();
        let mut probe = Vec3A::ZERO;
        for (x, v) in n.x.iter_mut().zip(&n.v) {
            position_phase(method, x, *v, h);
            probe += (*x * sx + *v * s) * 0.0;
        }
        if probe != Vec3A::ZERO {
            check_mesh(&mut commands, e, n, &guard);
        }
    }
}

/// Bodies whose velocity was written since the last step.
type WrittenVelocity = (Changed<LinearVelocity>, Without<Quarantined>);

/// A velocity past the guard (game code set a crate to 1e30 m/s) is caught before the step
/// uses it: the contacts run before the integrators' own check, and a runaway's sweep box
/// would cover the world and fling bodies far from its path. One compare per moved body.
fn quarantine_runaway_velocities(
    mut commands: Commands,
    guard: Option<Res<DivergenceGuard>>,
    moved: Query<(Entity, &Position, &LinearVelocity), WrittenVelocity>,
) {
    let guard = guard.map_or_else(DivergenceGuard::default, |g| *g);
    for (e, x, v) in &moved {
        if let Some(reason) = guard.check(x.0, v.0, None) {
            commands.entity(e).try_insert(Quarantined { reason });
        }
    }
}
