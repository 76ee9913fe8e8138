//! The extra force evaluations of multi-stage integrators, for particles, meshes and rigid
//! bodies together.
//!
//! Velocity Verlet: after the drift, forces and torques are re-evaluated at (x₁, q₁) and the
//! second half-kick v ← v½ + ½h a₁, L ← L½ + ½h τ₁ completes the step.
//!
//! RK4 on y = (x, v, q, L) with ẏ = (v, f/m, ½ ω ⊗ q, τ), ω = I(q)⁻¹ L: the substep's own force
//! evaluation is stage 1; stages 2–4 each set every RK4 body to its stage state and re-run
//! [`ForceSchedule`] (the same systems as the substep's force sets; no force code is copied).
//! Quaternions are combined as 4-vectors; the stage rotation shown to force systems is
//! normalised, and the end-of-step q is renormalised by the renormalise set.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3A};

use super::{Integrator, IntegratorOverride, kick};
use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::core::rest::Simulated;
use crate::core::schedule::ForceSchedule;
use crate::core::time::SubstepTime;
use crate::particles::{Force, LinearVelocity, Mass, Nodes, Position};
use crate::rigid::{AngularMomentum, AngularVelocity, Inertia, Rotation, Torque, quat_derivative};

const WEIGHT: [f32; 4] = [1.0, 2.0, 2.0, 1.0];
const OFFSET: [f32; 3] = [0.5, 0.5, 1.0];

pub(crate) fn needs_stages(global: Res<Integrator>, overrides: Query<&IntegratorOverride>) -> bool {
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
        let w = WEIGHT[k & 3];
        self.sum_x += w * v;
        self.sum_v += w * a;
        if k < 3 {
            let c = OFFSET[k] * h;
            (self.x0 + c * v, self.v0 + c * a)
        } else {
            let s = h / 6.0;
            (self.x0 + s * self.sum_x, self.v0 + s * self.sum_v)
        }
    }
}

/// RK4 bookkeeping for one rotation: (q₀, L₀) and the weighted sums of (q̇, L̇).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngularRk4 {
    q0: Quat,
    l0: Vec3A,
    sum_q: Quat,
    sum_l: Vec3A,
}

impl AngularRk4 {
    /// Starts a step from (q₀, L₀).
    #[must_use]
    #[inline]
    pub fn begin(q0: Quat, l0: Vec3A) -> Self {
        Self {
            q0,
            l0,
            sum_q: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
            sum_l: Vec3A::ZERO,
        }
    }

    /// Records stage `k`'s derivative (½ ω ⊗ q, τ) at stage state (`q`, ω) and returns the
    /// next stage's (q, L), or the end-of-step state after stage 3 (q not yet normalised).
    #[must_use]
    #[inline]
    pub fn stage(&mut self, k: usize, q: Quat, omega: Vec3A, tau: Vec3A, h: f32) -> (Quat, Vec3A) {
        let dq = quat_derivative(q, omega);
        let w = WEIGHT[k & 3];
        self.sum_q += dq * w;
        self.sum_l += w * tau;
        if k < 3 {
            let c = OFFSET[k] * h;
            (self.q0 + dq * c, self.l0 + c * tau)
        } else {
            let s = h / 6.0;
            (self.q0 + self.sum_q * s, self.l0 + s * self.sum_l)
        }
    }
}

/// Each RK4 body's (x₀, v₀) at the substep's start and the symplectic velocity it was
/// given for the constraint solve (written by the velocity phase).
#[derive(Resource, Debug, Default)]
pub(crate) struct Rk4Starts(pub Vec<(Entity, Vec3A, Vec3A, Vec3A)>);

/// Each RK4 body's (q₀, L₀) at the substep's start and the angular momentum the symplectic
/// kick gave it for the constraint solve (written by the velocity phase): as for
/// [`Rk4Starts`], a body no constraint touched takes RK4's stages from the start, one a
/// constraint touched keeps the symplectic turn that the constraint saw.
#[derive(Resource, Debug, Default)]
pub(crate) struct Rk4TurnStarts(pub Vec<(Entity, Quat, Vec3A, Vec3A)>);

/// Reused allocations of [`complete_stages`].
#[derive(Default)]
pub(crate) struct StageScratch {
    bodies: Vec<(Entity, Rk4Scratch)>,
    verlet: Vec<Entity>,
    meshes: Vec<(Entity, Integrator, Vec<Rk4Scratch>)>,
    /// RK4 rotations: entity, scratch and the un-normalised stage quaternion.
    rotations: Vec<(Entity, AngularRk4, Quat)>,
    verlet_rotations: Vec<Entity>,
    /// [`Rk4Starts`] by entity.
    starts: std::collections::HashMap<Entity, (Vec3A, Vec3A, Vec3A)>,
    /// [`Rk4TurnStarts`] by entity.
    turn_starts: std::collections::HashMap<Entity, (Quat, Vec3A, Vec3A)>,
}

type StageBody<'a> = (
    Entity,
    &'a mut Position,
    &'a mut LinearVelocity,
    &'a Force,
    &'a Mass,
    Option<&'a IntegratorOverride>,
);

type StageRotation<'a> = (
    Entity,
    &'a mut Rotation,
    &'a mut AngularMomentum,
    &'a mut AngularVelocity,
    &'a Torque,
    &'a Inertia,
    Option<&'a IntegratorOverride>,
);

/// Verlet's second kick and RK4's stages 2–4.
pub(crate) fn complete_stages(
    world: &mut World,
    bodies: &mut QueryState<StageBody, Simulated>,
    meshes: &mut QueryState<(Entity, &mut Nodes, Option<&IntegratorOverride>), super::ExplicitMesh>,
    rotations: &mut QueryState<StageRotation, Simulated>,
    mut scratch: Local<StageScratch>,
) {
    let global = *world.resource::<Integrator>();
    let h = world.resource::<SubstepTime>().h;
    let s = &mut *scratch;
    s.bodies.clear();
    s.verlet.clear();
    s.meshes.clear();
    s.rotations.clear();
    s.verlet_rotations.clear();

    // Stage 1. An RK4 body was kicked and drifted as symplectic Euler for the constraint
    // solve: one that no constraint touched (its state is the prediction, bit for bit) goes
    // back to its start state for RK4's stages; one a contact touched keeps the symplectic
    // step with the contact in it (RK4's stages would integrate this substep's gravity past
    // the contact that holds it: a resting ball sank through its box).
    s.starts.clear();
    s.starts.extend(
        world
            .resource::<Rk4Starts>()
            .0
            .iter()
            .map(|&(e, x0, v0, vp)| (e, (x0, v0, vp))),
    );
    for (e, mut x, mut v, f, m, o) in bodies.iter_mut(world) {
        match o.map_or(global, |o| o.0) {
            Integrator::Rk4 => {
                if let Some(&(x0, v0, predicted)) = s.starts.get(&e) {
                    let untouched = v.0 == predicted && x.0 == super::drift(x0, predicted, h);
                    if !untouched {
                        continue;
                    }
                    (x.0, v.0) = (x0, v0);
                }
                let mut r = Rk4Scratch::begin(x.0, v.0);
                (x.0, v.0) = r.stage(0, v.0, f.0 * m.inverse(), h);
                s.bodies.push((e, r));
            }
            Integrator::VelocityVerlet => s.verlet.push(e),
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
                let mut r = Rk4Scratch::begin(n.x[i], n.v[i]);
                (n.x[i], n.v[i]) = r.stage(0, n.v[i], n.f[i] * n.inv_mass[i], h);
                stages.push(r);
            }
        }
        s.meshes.push((e, method, stages));
    }
    s.turn_starts.clear();
    s.turn_starts.extend(
        world
            .resource::<Rk4TurnStarts>()
            .0
            .iter()
            .map(|&(e, q0, l0, lp)| (e, (q0, l0, lp))),
    );
    for (e, mut q, mut l, mut w, t, inertia, o) in rotations.iter_mut(world) {
        match o.map_or(global, |o| o.0) {
            Integrator::Rk4 => {
                if let Some(&(q0, l0, predicted)) = s.turn_starts.get(&e) {
                    if l.0 != predicted {
                        continue;
                    }
                    q.0 = q0;
                    l.bypass_change_detection().0 = l0;
                }
                let mut r = AngularRk4::begin(q.0, l.0);
                let omega = crate::rigid::omega_of(inertia, q.0, l.0, w.0);
                let tau = if inertia.is_infinite() {
                    Vec3A::ZERO
                } else {
                    t.0
                };
                let (qs, ls) = r.stage(0, q.0, omega, tau, h);
                set_rotation_stage(&mut q, &mut l, &mut w, inertia, qs, ls);
                s.rotations.push((e, r, qs));
            }
            Integrator::VelocityVerlet => s.verlet_rotations.push(e),
            _ => {}
        }
    }
    if s.bodies.is_empty()
        && s.verlet.is_empty()
        && s.meshes.is_empty()
        && s.rotations.is_empty()
        && s.verlet_rotations.is_empty()
    {
        return;
    }

    let _ = world.try_run_schedule(ForceSchedule);

    // Verlet: v ← v½ + ½h a(x₁), L ← L½ + ½h τ(q₁).
    for &e in &s.verlet {
        if let Ok((_, _, mut v, f, m, _)) = bodies.get_mut(world, e) {
            v.0 = kick(v.0, f.0 * m.inverse(), 0.5 * h);
        }
    }
    for (e, method, _) in &s.meshes {
        if *method == Integrator::VelocityVerlet
            && let Ok((_, mut nodes, _)) = meshes.get_mut(world, *e)
        {
            let n = nodes.bypass_change_detection();
            for i in 0..n.v.len() {
                n.v[i] = kick(n.v[i], n.f[i] * n.inv_mass[i], 0.5 * h);
            }
        }
    }
    for &e in &s.verlet_rotations {
        if let Ok((_, _, mut l, _, t, inertia, _)) = rotations.get_mut(world, e)
            && !inertia.is_infinite()
        {
            l.bypass_change_detection().0 += (0.5 * h) * t.0;
        }
    }

    let any_rk4 = !s.bodies.is_empty()
        || !s.rotations.is_empty()
        || s.meshes.iter().any(|m| m.1 == Integrator::Rk4);
    if !any_rk4 {
        return;
    }
    for k in 1..4 {
        for (e, r) in s.bodies.iter_mut() {
            if let Ok((_, mut x, mut v, f, m, _)) = bodies.get_mut(world, *e) {
                (x.0, v.0) = r.stage(k, v.0, f.0 * m.inverse(), h);
            }
        }
        for (e, method, stages) in s.meshes.iter_mut() {
            if *method != Integrator::Rk4 {
                continue;
            }
            if let Ok((_, mut nodes, _)) = meshes.get_mut(world, *e) {
                let n = nodes.bypass_change_detection();
                for (i, r) in stages.iter_mut().enumerate() {
                    (n.x[i], n.v[i]) = r.stage(k, n.v[i], n.f[i] * n.inv_mass[i], h);
                }
            }
        }
        for (e, r, q_stage) in s.rotations.iter_mut() {
            if let Ok((_, mut q, mut l, mut w, t, inertia, _)) = rotations.get_mut(world, *e) {
                // ω was set for this stage state when the state was written.
                let tau = if inertia.is_infinite() {
                    Vec3A::ZERO
                } else {
                    t.0
                };
                let (qs, ls) = r.stage(k, *q_stage, w.0, tau, h);
                set_rotation_stage(&mut q, &mut l, &mut w, inertia, qs, ls);
                *q_stage = qs;
            }
        }
        if k < 3 {
            let _ = world.try_run_schedule(ForceSchedule);
        }
    }

    // RK4 bodies skipped the position phase, so check them here (non-finite, or faster than
    // the divergence guard allows).
    let guard = world
        .get_resource::<crate::core::quarantine::DivergenceGuard>()
        .copied()
        .unwrap_or_default();
    let mut bad = Vec::new();
    for (e, _) in &s.bodies {
        if let Ok((_, x, v, ..)) = bodies.get(world, *e) {
            if !(x.0.is_finite() && v.0.is_finite()) {
                bad.push((*e, QuarantineReason::NonFiniteState));
            } else if let Some(reason) = guard.check(x.0, v.0, None) {
                bad.push((*e, reason));
            }
        }
    }
    for (e, method, _) in &s.meshes {
        if *method == Integrator::Rk4
            && let Ok((_, nodes, _)) = meshes.get(world, *e)
        {
            if !nodes.is_finite() {
                bad.push((*e, QuarantineReason::NonFiniteState));
            } else if let Some(reason) = super::mesh_divergence(nodes, &guard) {
                bad.push((*e, reason));
            }
        }
    }
    for (e, ..) in &s.rotations {
        if let Ok((_, q, l, ..)) = rotations.get(world, *e)
            && !(q.0.is_finite() && l.0.is_finite())
        {
            bad.push((*e, QuarantineReason::NonFiniteState));
        }
    }
    for (e, reason) in bad {
        world.entity_mut(e).insert(Quarantined { reason });
    }
}

/// Writes a stage state: the normalised rotation (what force systems should see), L, and
/// the matching ω.
fn set_rotation_stage(
    q: &mut Mut<Rotation>,
    l: &mut Mut<AngularMomentum>,
    w: &mut Mut<AngularVelocity>,
    inertia: &Inertia,
    qs: Quat,
    ls: Vec3A,
) {
    let qn = qs.normalize();
    q.0 = if qn.is_finite() { qn } else { qs };
    l.bypass_change_detection().0 = ls;
    if !inertia.is_infinite() {
        w.bypass_change_detection().0 = inertia.angular_velocity(q.0, ls);
    }
}
