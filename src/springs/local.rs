//! Local substeps ([`LocalSubsteps`]): a spring system too stiff for the world's substep is
//! stepped explicitly n times per substep on its own, the substep's other forces held.
//!
//! Symplectic Euler at h/n: the same scheme as the rest of the world at a finer step, so it
//! takes nothing from the motion (no numerical damping) and costs n passes over the system's
//! own springs instead of a Newton solve. [`crate::integrator::StabilityPolicy::Automatic`]
//! chooses it while n is small (see [`crate::integrator::stability`]).
//!
//! **Meshes** ([`SpringNetwork`] + [`Nodes`]) are advanced whole inside
//! [`crate::core::schedule::ImplicitSystems::Springs`], as an implicit mesh is; the
//! integrators leave them alone, and node contacts correct them afterwards.
//!
//! **Entity springs** ([`Spring`]) with a [`LocalSubsteps`] share one local integration over
//! the bodies they join, at the largest count among them. A rigid end is stepped whole: its
//! position, velocity, orientation and angular momentum, with the springs' torques at their
//! anchors, so that a top on a stiff pivot keeps its spin. The result is handed to each body
//! as the force and torque that make its own kick land on the locally stepped velocity and
//! angular momentum, and as corrections of position and orientation applied after its own
//! drift ([`PositionSystems::Correct`](crate::core::schedule::PositionSystems::Correct)):
//! a body no contact touched ends exactly where the local steps took it, and a contact's
//! impulse on it in between still acts. While any spring of the world is solved implicitly
//! (an [`ImplicitEuler`] on it, or the implicit dial), the locally substepped ones join that
//! solve instead, which is stable for them too.

use std::collections::HashMap;

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};

use super::{Spring, SpringNetwork, spring_force};
use crate::core::quarantine::{DivergenceGuard, QuarantineReason, Quarantined};
use crate::core::time::SubstepTime;
use crate::integrator::{ImplicitEuler, Integrator, LocalSubsteps};
use crate::particles::{Force, Mass, Nodes, Position};
use crate::rigid::{
    AngularMomentum, AngularVelocity, Inertia, OrientationUpdate, Rotation, Torque,
};

/// Whether the entity springs are solved implicitly this substep: then the locally
/// substepped ones join that solve.
pub(crate) fn entity_springs_implicit<F: bevy_ecs::query::QueryFilter>(
    global: Integrator,
    flagged: &Query<(), (With<Spring>, With<ImplicitEuler>, F)>,
) -> bool {
    global == Integrator::ImplicitEuler || !flagged.is_empty()
}

/// A rigid end's turning state during the local steps.
#[derive(Debug, Clone, Copy)]
struct Turning {
    q0: Quat,
    q: Quat,
    l0: Vec3A,
    l: Vec3A,
    /// ω as stored (what a body of infinite inertia turns at).
    stored: Vec3A,
    inertia: Inertia,
    /// The torque of the substep's other effects (N·m).
    tau_ext: Vec3A,
}

/// A body joined by locally substepped springs.
#[derive(Debug, Clone, Copy)]
struct Body {
    entity: Entity,
    /// Mass (kg) and inverse mass; zero inverse for a pinned body, which moves at its
    /// velocity.
    m: f32,
    w: f32,
    x0: Vec3A,
    v0: Vec3A,
    x: Vec3A,
    v: Vec3A,
    /// The force of the substep's other effects (N).
    f_ext: Vec3A,
    turning: Option<Turning>,
}

/// A spring between two bodies of the local integration.
#[derive(Debug, Clone, Copy)]
struct Link {
    ends: [u32; 2],
    anchors: [Vec3; 2],
    rest: f32,
    k: f32,
    c: f32,
}

/// The buffers of the entity springs' local integration, kept so a warm step allocates
/// nothing.
#[derive(Default)]
pub(crate) struct LocalSolve {
    bodies: Vec<Body>,
    index: HashMap<Entity, u32>,
    links: Vec<Link>,
    f: Vec<Vec3A>,
    tau: Vec<Vec3A>,
}

/// What the local integration reads of a body.
pub(crate) type LocalBody<'a> = (
    &'a Position,
    &'a crate::particles::LinearVelocity,
    &'a Mass,
    Option<&'a crate::integrator::IntegratorOverride>,
    Has<crate::core::rest::Sleeping>,
);

/// What it reads of a turning body.
pub(crate) type LocalTurning<'a> = (
    &'a Rotation,
    &'a AngularVelocity,
    &'a AngularMomentum,
    &'a Inertia,
);

/// Poses handed from the local integration to the bodies after their own drift: a
/// translation and a rotation (applied on the left) per body.
#[derive(Resource, Debug, Clone, Default)]
pub(crate) struct LocalCorrections(pub Vec<(Entity, Vec3A, Quat)>);

impl LocalSolve {
    fn body(
        &mut self,
        e: Entity,
        bodies: &Query<LocalBody, Without<Quarantined>>,
        turning: &Query<LocalTurning, Without<Quarantined>>,
        forces: &Query<&mut Force, Without<Quarantined>>,
        torques: &Query<&mut Torque, Without<Quarantined>>,
    ) -> Option<u32> {
        if let Some(&i) = self.index.get(&e) {
            return Some(i);
        }
        let (x, v, m, _, asleep) = bodies.get(e).ok()?;
        // A sleeping body is held where it is, as a pin: its own integrator skips it.
        let held = m.is_pinned() || asleep;
        let turning = turning.get(e).ok().map(|(q, w, l, inertia)| Turning {
            q0: q.0,
            q: q.0,
            l0: l.0,
            l: l.0,
            stored: w.0,
            inertia: *inertia,
            tau_ext: torques.get(e).map_or(Vec3A::ZERO, |t| t.0),
        });
        let i = self.bodies.len() as u32;
        self.index.insert(e, i);
        self.bodies.push(Body {
            entity: e,
            m: if held { 0.0 } else { m.value() },
            w: if held { 0.0 } else { m.inverse() },
            x0: x.0,
            v0: v.0,
            x: x.0,
            v: v.0,
            f_ext: forces.get(e).map_or(Vec3A::ZERO, |f| f.0),
            turning,
        });
        Some(i)
    }

    /// A spring end's world anchor, its velocity and lever arm.
    fn anchor(&self, i: u32, anchor: Vec3) -> (Vec3A, Vec3A, Vec3A) {
        let b = &self.bodies[i as usize];
        if anchor == Vec3::ZERO {
            return (b.x, b.v, Vec3A::ZERO);
        }
        match b.turning {
            Some(t) => {
                let r = t.q * Vec3A::from(anchor);
                let omega = crate::rigid::omega_of(&t.inertia, t.q, t.l, t.stored);
                (b.x + r, b.v + omega.cross(r), r)
            }
            None => (b.x + Vec3A::from(anchor), b.v, Vec3A::ZERO),
        }
    }

    /// n symplectic-Euler steps of h/n over the bodies; false if the state went non-finite.
    fn run(&mut self, n: u32, h: f32, update: OrientationUpdate) -> bool {
        let hs = h / n as f32;
        for _ in 0..n {
            self.f.clear();
            self.tau.clear();
            self.f.extend(self.bodies.iter().map(|b| b.f_ext));
            self.tau.extend(
                self.bodies
                    .iter()
                    .map(|b| b.turning.map_or(Vec3A::ZERO, |t| t.tau_ext)),
            );
            for link in &self.links {
                let (pa, va, ra) = self.anchor(link.ends[0], link.anchors[0]);
                let (pb, vb, rb) = self.anchor(link.ends[1], link.anchors[1]);
                let f = spring_force(pa, pb, va, vb, link.rest, link.k, link.c);
                let (a, b) = (link.ends[0] as usize, link.ends[1] as usize);
                self.f[a] += f;
                self.f[b] -= f;
                self.tau[a] += ra.cross(f);
                self.tau[b] -= rb.cross(f);
            }
            let mut finite = true;
            for (i, b) in self.bodies.iter_mut().enumerate() {
                b.v += (hs * b.w) * self.f[i];
                b.x += hs * b.v;
                if let Some(t) = b.turning.as_mut() {
                    // `turn` takes ω from L (the stored ω only for infinite inertia).
                    if !t.inertia.is_infinite() {
                        t.l += hs * self.tau[i];
                    }
                    t.q = crate::rigid::turn(t.q, t.l, t.stored, &t.inertia, hs, update, false)
                        .normalize();
                }
                finite &= b.x.is_finite() && b.v.is_finite();
            }
            if !finite {
                return false;
            }
        }
        true
    }
}

/// Steps the locally substepped entity springs (see the module docs), unless the entity
/// springs are solved implicitly this substep.
#[allow(clippy::too_many_arguments, clippy::type_complexity)] // a system: one query or resource each
pub(crate) fn substep_entity_springs(
    mut commands: Commands,
    global: Res<Integrator>,
    guard: Res<DivergenceGuard>,
    time: Res<SubstepTime>,
    update: Option<Res<OrientationUpdate>>,
    springs: Query<(Entity, &Spring, &LocalSubsteps), Without<Quarantined>>,
    flagged: Query<(), (With<Spring>, With<ImplicitEuler>, Without<Quarantined>)>,
    (bodies, turning): (
        Query<LocalBody, Without<Quarantined>>,
        Query<LocalTurning, Without<Quarantined>>,
    ),
    mut forces: Query<&mut Force, Without<Quarantined>>,
    mut torques: Query<&mut Torque, Without<Quarantined>>,
    mut corrections: ResMut<LocalCorrections>,
    mut solve: Local<LocalSolve>,
    (archetypes, spring_id, mut order): (
        &bevy_ecs::archetype::Archetypes,
        bevy_ecs::component::ComponentIdFor<Spring>,
        Local<Vec<Entity>>,
    ),
) {
    let global = *global;
    corrections.0.clear();
    if entity_springs_implicit(global, &flagged) {
        return;
    }
    let s = &mut *solve;
    s.bodies.clear();
    s.index.clear();
    s.links.clear();
    let mut count = 1;
    let all =
        crate::core::order::stable(&springs, archetypes, spring_id.get(), &mut order, |i| i.0);
    for (_, spring, local) in all {
        let accepts = |e: Entity| {
            bodies
                .get(e)
                .is_ok_and(|(_, _, m, o, _)| super::entity_implicit::end_accepts(global, m, o))
        };
        if !(accepts(spring.a) && accepts(spring.b)) {
            continue;
        }
        let (Some(a), Some(b)) = (
            s.body(spring.a, &bodies, &turning, &forces, &torques),
            s.body(spring.b, &bodies, &turning, &forces, &torques),
        ) else {
            continue;
        };
        count = count.max(local.count());
        s.links.push(Link {
            ends: [a, b],
            anchors: [spring.anchor_a, spring.anchor_b],
            rest: spring.rest_length,
            k: spring.stiffness,
            c: spring.damping,
        });
    }
    if s.links.is_empty() {
        return;
    }
    let h = time.h;
    let update = update.map_or_else(OrientationUpdate::default, |u| *u);
    if !s.bodies.iter().all(|b| b.x.is_finite() && b.v.is_finite()) {
        // Caught and named by the state check after integration, as for explicit springs.
        return;
    }
    let finite = s.run(count, h, update);
    for b in &s.bodies {
        if b.w == 0.0 {
            continue;
        }
        let over = guard.check(b.x, b.v, None);
        if !finite || over.is_some() {
            commands.entity(b.entity).insert(Quarantined {
                reason: over.unwrap_or(QuarantineReason::NonFiniteState),
            });
            continue;
        }
        // The kick v₀ + h F / m lands on the local v, the drift on x₀ + h v; the correction
        // takes it from there to the local x.
        if let Ok(mut f) = forces.get_mut(b.entity) {
            f.bypass_change_detection().0 += b.m * (b.v - b.v0) / h - b.f_ext;
        }
        let mut turn = Quat::IDENTITY;
        if let Some(t) = b.turning
            && !t.inertia.is_infinite()
        {
            if let Ok(mut tau) = torques.get_mut(b.entity) {
                tau.bypass_change_detection().0 += (t.l - t.l0) / h - t.tau_ext;
            }
            // The body's own turn from q₀ with the local L, as the orientation phase will
            // take it; the correction rotates that onto the local q.
            let own = crate::rigid::turn(t.q0, t.l, t.stored, &t.inertia, h, update, false);
            turn = t.q * own.normalize().inverse();
        }
        corrections.0.push((b.entity, b.x - (b.x0 + h * b.v), turn));
    }
}

/// A body's pose, for the corrections (`With<Mass>` keeps it apart from tracers).
type Pose<'a> = (&'a mut Position, Option<&'a mut Rotation>);

/// Applies the local integration's corrections after the bodies' own drift (see the module
/// docs).
pub(crate) fn correct_local_poses(
    mut corrections: ResMut<LocalCorrections>,
    mut poses: Query<Pose, (With<Mass>, Without<Quarantined>)>,
) {
    for (body, dx, turn) in corrections.bypass_change_detection().0.drain(..) {
        if let Ok((mut x, q)) = poses.get_mut(body) {
            x.bypass_change_detection().0 += dx;
            if let Some(mut q) = q
                && turn != Quat::IDENTITY
            {
                let q = q.bypass_change_detection();
                q.0 = turn * q.0;
            }
        }
    }
}

/// Meshes stepped locally: alive, awake, not solved implicitly.
type LocalMesh = (
    Without<Quarantined>,
    Without<ImplicitEuler>,
    Without<crate::core::rest::Sleeping>,
);

/// Steps each [`SpringNetwork`] mesh with [`LocalSubsteps`] (and no [`ImplicitEuler`]) n times
/// per substep: its springs' forces are recomputed at each local step, the other forces on
/// its nodes (gravity, damping, game code's) held from the substep's start.
pub(crate) fn substep_meshes(
    mut commands: Commands,
    guard: Res<DivergenceGuard>,
    time: Res<SubstepTime>,
    mut meshes: Query<(Entity, &mut Nodes, &SpringNetwork, &LocalSubsteps), LocalMesh>,
    mut scratch: Local<Vec<Vec3A>>,
) {
    for (e, mut nodes, network, local) in &mut meshes {
        let n = nodes.bypass_change_detection();
        if let Some(reason) = network.misfit(n) {
            commands.entity(e).insert(Quarantined { reason });
            continue;
        }
        crate::integrator::stability::step_locally(n, local.count(), time.h, &mut scratch, |n| {
            network.accumulate(n)
        });
        let reason = if n.is_finite() {
            crate::integrator::mesh_divergence(n, &guard)
        } else {
            Some(QuarantineReason::NonFiniteState)
        };
        if let Some(reason) = reason {
            commands.entity(e).insert(Quarantined { reason });
        }
    }
}
