//! The integration systems shared by particle entities and [`Nodes`] meshes.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use super::{Integrator, IntegratorOverride, drift, explicit_euler, kick};
use crate::particles::{
    ExternalForce, ExternalImpulse, Force, Gravity, GravityScale, LinearVelocity, Mass, Nodes,
    Position,
};
use crate::quarantine::{QuarantineReason, Quarantined};
use crate::schedule::{ForceSchedule, StepSystems, add_force_systems, add_systems};
use crate::time::SubstepTime;
use crate::{Plugin, SubstepSchedule};

/// Whether any constraint (contact, joint) acts in this step. Constraint plugins set it in
/// [`crate::PhysicsSystems::Prepare`]. While it is false nothing runs between the velocity and
/// the position half of symplectic Euler, so particles take both halves in one pass: the same
/// arithmetic, bit for bit, with one read of memory instead of two.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ConstraintsActive(pub bool);

impl ConstraintsActive {
    fn fuses(self, method: Integrator) -> bool {
        !self.0 && method == Integrator::SymplecticEuler
    }
}

/// Integration, force clearing, impulses and the NaN quarantine of moving bodies. Part of the
/// core: every other effect needs it.
#[derive(Debug, Default, Clone, Copy)]
pub struct IntegratorPlugin;

impl Plugin for IntegratorPlugin {
    fn build(&self, world: &mut World) {
        world.init_resource::<Integrator>();
        world.init_resource::<ConstraintsActive>();
        add_force_systems(world, || clear_forces.in_set(StepSystems::ClearForces));
        add_systems(
            world,
            SubstepSchedule,
            (
                (
                    apply_impulses.run_if(any_with_component::<ExternalImpulse>),
                    integrate_velocities,
                )
                    .chain()
                    .in_set(StepSystems::IntegrateVelocities),
                integrate_positions.in_set(StepSystems::IntegratePositions),
                complete_stages
                    .run_if(needs_stages)
                    .in_set(StepSystems::CompleteStages),
            ),
        );
    }
}

type Live = Without<Quarantined>;

/// Initialises every accumulator with the body's constant forces: f ← f_ext + m g s.
///
/// Gravity and external forces don't depend on the state, so they are written here in the one
/// pass that has to touch every accumulator anyway; state-dependent forces are added in
/// [`StepSystems::ApplyForces`]. Without the gravity plugin there is no [`Gravity`] resource
/// and g = 0. On a million particles this saves a full sweep of memory per substep.
#[allow(clippy::type_complexity)] // four disjoint archetype filters; naming them adds nothing
pub(crate) fn clear_forces(
    gravity: Option<Res<Gravity>>,
    mut plain: Query<(&mut Force, &Mass), (Without<ExternalForce>, Without<GravityScale>, Live)>,
    mut scaled: Query<(&mut Force, &Mass, &GravityScale), (Without<ExternalForce>, Live)>,
    mut external: Query<(&mut Force, &Mass, &ExternalForce, Option<&GravityScale>), Live>,
    mut meshes: Query<&mut Nodes, Live>,
) {
    let g = gravity.map_or(Vec3A::ZERO, |g| g.get().into());
    // Force is an accumulator nobody watches for changes; skipping the tick write keeps
    // this pass at raw-loop speed.
    plain
        .iter_mut()
        .for_each(|(mut f, m)| f.bypass_change_detection().0 = m.force_scale() * g);
    scaled.iter_mut().for_each(|(mut f, m, s)| {
        f.bypass_change_detection().0 = (m.force_scale() * s.0) * g;
    });
    external.iter_mut().for_each(|(mut f, m, ext, s)| {
        let s = s.map_or(1.0, |s| s.0);
        f.bypass_change_detection().0 = Vec3A::from(ext.0) + (m.force_scale() * s) * g;
    });
    for mut nodes in &mut meshes {
        let n = nodes.bypass_change_detection();
        for (f, m) in n.f.iter_mut().zip(&n.mass) {
            *f = *m * g;
        }
    }
}

/// Δv = J / m, then J ← 0 without marking it changed (so the next step sees no new impulse).
pub(crate) fn apply_impulses(
    mut bodies: Query<
        (&mut LinearVelocity, &mut ExternalImpulse, &Mass),
        (Changed<ExternalImpulse>, Live),
    >,
) {
    for (mut v, mut j, m) in &mut bodies {
        if j.0 != Vec3::ZERO {
            v.0 += Vec3A::from(j.0) * m.inverse();
            j.bypass_change_detection().0 = Vec3::ZERO;
        }
    }
}

/// The velocity half of a step; explicit Euler does its whole step here.
#[inline]
fn velocity_phase(method: Integrator, x: &mut Vec3A, v: &mut Vec3A, a: Vec3A, h: f32) {
    match method {
        Integrator::ExplicitEuler => (*x, *v) = explicit_euler(*x, *v, a, h),
        Integrator::SymplecticEuler => *v = kick(*v, a, h),
        Integrator::VelocityVerlet => *v = kick(*v, a, 0.5 * h),
        Integrator::Rk4 => {}
    }
}

/// The position half of a step.
#[inline]
fn position_phase(method: Integrator, x: &mut Vec3A, v: Vec3A, h: f32) {
    if matches!(
        method,
        Integrator::SymplecticEuler | Integrator::VelocityVerlet
    ) {
        *x = drift(*x, v, h);
    }
}

type BodyState<'a> = (
    &'a mut Position,
    &'a mut LinearVelocity,
    &'a Force,
    &'a Mass,
);

#[allow(clippy::type_complexity)] // a ParamSet of queries; naming each adds nothing
fn integrate_velocities(
    mut commands: Commands,
    global: Res<Integrator>,
    constraints: Res<ConstraintsActive>,
    time: Res<SubstepTime>,
    mut set: ParamSet<(
        Query<BodyState, (Without<IntegratorOverride>, Live)>,
        Query<(BodyState, &IntegratorOverride), Live>,
        Suspects,
    )>,
    mut meshes: Query<(&mut Nodes, Option<&IntegratorOverride>), Live>,
) {
    let h = time.h;
    let method = *global;
    if constraints.fuses(method) {
        // Both halves of symplectic Euler in one pass; see `ConstraintsActive`.
        let mut probe = Vec3A::ZERO;
        set.p0().iter_mut().for_each(|(mut x, mut v, f, m)| {
            let va = kick(v.0, f.0 * m.inverse(), h);
            let xa = drift(x.0, va, h);
            probe += (xa + va) * 0.0;
            v.0 = va;
            x.0 = xa;
        });
        if probe != Vec3A::ZERO {
            quarantine_suspects(&mut commands, &set.p2());
        }
    } else if method == Integrator::SymplecticEuler {
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

fn quarantine_non_finite(commands: &mut Commands, entity: Entity) {
    commands.entity(entity).insert(Quarantined {
        reason: QuarantineReason::NonFiniteState,
    });
}

type Drift<'a> = (&'a mut Position, &'a LinearVelocity);

/// Finds the bodies whose state is non-finite; runs only after the fast pass saw one.
type Suspects<'w, 's> =
    Query<'w, 's, (Entity, &'static Position, &'static LinearVelocity), (With<Mass>, Live)>;

fn quarantine_suspects(commands: &mut Commands, suspects: &Suspects) {
    for (e, x, v) in suspects {
        if !(x.0.is_finite() && v.0.is_finite()) {
            quarantine_non_finite(commands, e);
        }
    }
}

#[allow(clippy::type_complexity)] // a ParamSet of queries; naming each adds nothing
fn integrate_positions(
    mut commands: Commands,
    global: Res<Integrator>,
    constraints: Res<ConstraintsActive>,
    time: Res<SubstepTime>,
    mut bodies: ParamSet<(
        Query<Drift, (With<Mass>, Without<IntegratorOverride>, Live)>,
        Query<(Drift, &IntegratorOverride), (With<Mass>, Live)>,
        Suspects,
    )>,
    mut meshes: Query<(Entity, &mut Nodes, Option<&IntegratorOverride>), Live>,
) {
    let h = time.h;
    let method = *global;
    // 0·x + 0·v stays zero unless a lane is NaN or infinite: a branch-free finiteness
    // check that keeps the loop vectorised.
    let mut probe = Vec3A::ZERO;
    if constraints.fuses(method) {
        // Done in the velocity pass.
    } else if matches!(
        method,
        Integrator::SymplecticEuler | Integrator::VelocityVerlet
    ) {
        bodies.p0().iter_mut().for_each(|(mut x, v)| {
            let (xa, va) = (x.0, v.0);
            let xa = drift(xa, va, h);
            probe += (xa + va) * 0.0;
            x.0 = xa;
        });
    } else if method == Integrator::ExplicitEuler {
        // The whole step happened in the velocity phase; only check it.
        bodies
            .p0()
            .iter()
            .for_each(|(x, v)| probe += (x.0 + v.0) * 0.0);
    }
    bodies.p1().iter_mut().for_each(|((mut x, v), o)| {
        if matches!(
            o.0,
            Integrator::SymplecticEuler | Integrator::VelocityVerlet
        ) {
            x.0 = drift(x.0, v.0, h);
        }
        probe += (x.0 + v.0) * 0.0;
    });
    if probe != Vec3A::ZERO {
        quarantine_suspects(&mut commands, &bodies.p2());
    }
    for (e, mut nodes, o) in &mut meshes {
        let method = o.map_or(method, |o| o.0);
        let n = nodes.bypass_change_detection();
        let mut probe = Vec3A::ZERO;
        for (x, v) in n.x.iter_mut().zip(&n.v) {
            position_phase(method, x, *v, h);
            probe += (*x + *v) * 0.0;
        }
        if probe != Vec3A::ZERO {
            quarantine_non_finite(&mut commands, e);
        }
    }
}

fn needs_stages(global: Res<Integrator>, overrides: Query<&IntegratorOverride>) -> bool {
    global.is_multistage() || overrides.iter().any(|o| o.0.is_multistage())
}

/// RK4 bookkeeping for one particle: the start state and the weighted derivative sums.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Rk4Scratch {
    x0: Vec3A,
    v0: Vec3A,
    sum_x: Vec3A,
    sum_v: Vec3A,
}

impl Rk4Scratch {
    const WEIGHT: [f32; 4] = [1.0, 2.0, 2.0, 1.0];
    const OFFSET: [f32; 3] = [0.5, 0.5, 1.0];

    /// Starts a step from (x₀, v₀).
    #[must_use]
    #[inline]
    pub fn begin(x0: Vec3A, v0: Vec3A) -> Self {
        Self {
            x0,
            v0,
            ..Default::default()
        }
    }

    /// Records stage `k`'s derivative (ẋ, v̇) = (`v`, `a`), both taken at stage `k`'s state,
    /// and returns the state of stage k + 1, or the end-of-step state after stage 3.
    #[must_use]
    #[inline]
    pub fn stage(&mut self, k: usize, v: Vec3A, a: Vec3A, h: f32) -> (Vec3A, Vec3A) {
        let w = Self::WEIGHT[k & 3];
        self.sum_x += w * v;
        self.sum_v += w * a;
        if k < 3 {
            let c = Self::OFFSET[k] * h;
            (self.x0 + c * v, self.v0 + c * a)
        } else {
            let s = h / 6.0;
            (self.x0 + s * self.sum_x, self.v0 + s * self.sum_v)
        }
    }
}

/// Reused allocations of [`complete_stages`].
#[derive(Default)]
struct StageScratch {
    bodies: Vec<(Entity, Rk4Scratch)>,
    verlet: Vec<Entity>,
    meshes: Vec<(Entity, Integrator, Vec<Rk4Scratch>)>,
}

type StageBody<'a> = (
    Entity,
    &'a mut Position,
    &'a mut LinearVelocity,
    &'a Force,
    &'a Mass,
    Option<&'a IntegratorOverride>,
);

/// Verlet's second kick and RK4's stages 2–4. Each extra force evaluation re-runs
/// [`ForceSchedule`]: the same systems as the substep's force sets.
fn complete_stages(
    world: &mut World,
    bodies: &mut QueryState<StageBody, Live>,
    meshes: &mut QueryState<(Entity, &mut Nodes, Option<&IntegratorOverride>), Live>,
    mut scratch: Local<StageScratch>,
) {
    let global = *world.resource::<Integrator>();
    let h = world.resource::<SubstepTime>().h;
    let StageScratch {
        bodies: rk4,
        verlet,
        meshes: mesh_stages,
    } = &mut *scratch;
    rk4.clear();
    verlet.clear();
    mesh_stages.clear();

    // Stage 1: RK4 bodies still sit at (x₀, v₀) with forces f(x₀, v₀).
    for (e, mut x, mut v, f, m, o) in bodies.iter_mut(world) {
        match o.map_or(global, |o| o.0) {
            Integrator::Rk4 => {
                let mut s = Rk4Scratch::begin(x.0, v.0);
                let (xs, vs) = s.stage(0, v.0, f.0 * m.inverse(), h);
                (x.0, v.0) = (xs, vs);
                rk4.push((e, s));
            }
            Integrator::VelocityVerlet => verlet.push(e),
            _ => {}
        }
    }
    for (e, mut nodes, o) in meshes.iter_mut(world) {
        let method = o.map_or(global, |o| o.0);
        if !method.is_multistage() {
            continue;
        }
        let mut stages = Vec::new();
        if method == Integrator::Rk4 {
            let n = nodes.bypass_change_detection();
            stages.reserve(n.x.len());
            for i in 0..n.x.len() {
                let mut s = Rk4Scratch::begin(n.x[i], n.v[i]);
                (n.x[i], n.v[i]) = s.stage(0, n.v[i], n.f[i] * n.inv_mass[i], h);
                stages.push(s);
            }
        }
        mesh_stages.push((e, method, stages));
    }
    if rk4.is_empty() && verlet.is_empty() && mesh_stages.is_empty() {
        return;
    }

    let _ = world.try_run_schedule(ForceSchedule);

    // Verlet: v ← v½ + ½h a(x₁, v½).
    for &e in verlet.iter() {
        if let Ok((_, _, mut v, f, m, _)) = bodies.get_mut(world, e) {
            v.0 = kick(v.0, f.0 * m.inverse(), 0.5 * h);
        }
    }
    for (e, method, _) in mesh_stages.iter() {
        if *method == Integrator::VelocityVerlet
            && let Ok((_, mut nodes, _)) = meshes.get_mut(world, *e)
        {
            let n = nodes.bypass_change_detection();
            for i in 0..n.v.len() {
                n.v[i] = kick(n.v[i], n.f[i] * n.inv_mass[i], 0.5 * h);
            }
        }
    }

    let any_rk4 = !rk4.is_empty() || mesh_stages.iter().any(|m| m.1 == Integrator::Rk4);
    if !any_rk4 {
        return;
    }
    for k in 1..4 {
        for (e, s) in rk4.iter_mut() {
            if let Ok((_, mut x, mut v, f, m, _)) = bodies.get_mut(world, *e) {
                let (xs, vs) = s.stage(k, v.0, f.0 * m.inverse(), h);
                (x.0, v.0) = (xs, vs);
            }
        }
        for (e, method, stages) in mesh_stages.iter_mut() {
            if *method != Integrator::Rk4 {
                continue;
            }
            if let Ok((_, mut nodes, _)) = meshes.get_mut(world, *e) {
                let n = nodes.bypass_change_detection();
                for (i, s) in stages.iter_mut().enumerate() {
                    (n.x[i], n.v[i]) = s.stage(k, n.v[i], n.f[i] * n.inv_mass[i], h);
                }
            }
        }
        if k < 3 {
            let _ = world.try_run_schedule(ForceSchedule);
        }
    }

    // RK4 bodies skipped the position phase, so check them here.
    let mut bad = Vec::new();
    for (e, _) in rk4.iter() {
        if let Ok((_, x, v, ..)) = bodies.get(world, *e)
            && !(x.0.is_finite() && v.0.is_finite())
        {
            bad.push(*e);
        }
    }
    for (e, method, _) in mesh_stages.iter() {
        if *method == Integrator::Rk4
            && let Ok((_, nodes, _)) = meshes.get(world, *e)
            && !nodes.is_finite()
        {
            bad.push(*e);
        }
    }
    for e in bad {
        world.entity_mut(e).insert(Quarantined {
            reason: QuarantineReason::NonFiniteState,
        });
    }
}
