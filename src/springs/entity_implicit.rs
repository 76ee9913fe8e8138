//! Backward Euler for [`Spring`] entities: ropes, chains and hair built with
//! [`super::ChainBuilder`], and springs anchored on rigid bodies.
//!
//! A spring is solved implicitly when the global [`Integrator`] is
//! [`Integrator::ImplicitEuler`], when it carries an [`ImplicitEuler`] component (put there by
//! game code, or by [`crate::integrator::StabilityPolicy`] when the spring is too stiff
//! for the substep), and both its ends are integrated by a scheme that kicks then drifts
//! (symplectic or backward Euler; a pinned end always qualifies). Every such spring of the
//! world goes into one solve, the same Newton and conjugate-gradient machinery as spring
//! meshes ([`crate::integrator::implicit`]): each distinct end (a body, and an anchor on it)
//! becomes a node, the springs become a [`SpringNetwork`] over those nodes, and every other
//! force on the ends (gravity, damping, explicit springs, game code's forces) is the solve's
//! f_ext.
//!
//! The solve yields each end's backward-Euler velocity v₁. The spring force handed to the end
//! is f = m (v₁ − v₀) / h − f_ext, added to its [`Force`] (and r × f to a rigid body's
//! [`Torque`]), so that the end's own kick v ← v₀ + h F / m and drift x ← x₀ + h v land on the
//! backward-Euler state: a particle's step is backward Euler exactly, up to rounding.
//!
//! **Rigid ends.** An end on a rigid body moves with the body: under a force f at lever arm
//! r its acceleration is W f, W = I/m − [r]ₓ I⁻¹ [r]ₓ (the body's linear and angular
//! response, linearised at the step's start, I⁻¹ in world axes). The solve gives the end the
//! scalar mass 1 / (n · maxₛ d̂ₛᵀ W d̂ₛ), the largest response along the springs s it holds
//! (d̂ₛ their directions at the step's start), n being how many distinct anchors of that body
//! the solve holds. For one spring at one anchor this is the exact response along the
//! spring, so the stiff (axial) motion is backward Euler of the linearised body and a body
//! hangs at the static stretch; the soft transverse motion is approximated. With n anchors on
//! one body the mass is divided by n so that the solve never takes the body for heavier than
//! it is (that could overshoot); the price is a bias of about h² g (n − 1) in the static
//! stretch (0.17 mm for two anchors at 240 Hz). The anchor's prediction follows the arc the
//! body's spin gives it (see [`End::curve`]). Forces applied at points in
//! [`crate::core::schedule::StepSystems::AccumulateTorque`] (after this solve) are not in f_ext.

use std::collections::HashMap;

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use super::{Spinning, Spring, SpringNetwork, anchor_state};
use crate::core::quarantine::{DivergenceGuard, QuarantineReason, Quarantined};
use crate::core::time::SubstepTime;
use crate::integrator::implicit::{Scratch, step};
use crate::integrator::{
    ImplicitEuler, ImplicitScheme, ImplicitState, Integrator, IntegratorOverride,
};
use crate::particles::{Force, LinearVelocity, Mass, Nodes, Position};
use crate::rigid::{Inertia, Torque};

/// What the solve needs of an end's body.
pub(crate) type EndBody<'a> = (
    &'a Position,
    &'a LinearVelocity,
    &'a Mass,
    Option<&'a IntegratorOverride>,
);

/// Whether a spring is wanted in the implicit solve (before its ends are looked at).
#[inline]
pub(crate) fn wants_implicit(global: Integrator, flagged: bool) -> bool {
    flagged || global == Integrator::ImplicitEuler
}

/// Whether an end can take a force from the implicit solve: pinned, or integrated by a
/// scheme that kicks then drifts.
#[inline]
pub(crate) fn end_accepts(global: Integrator, mass: &Mass, o: Option<&IntegratorOverride>) -> bool {
    mass.is_pinned() || o.map_or(global, |o| o.0).kicks_then_drifts()
}

/// One node of the solve: whose end it is.
#[derive(Debug, Clone, Copy)]
struct End {
    body: Entity,
    /// Lever arm r = R a (zero at the centre of mass or on a particle).
    lever: Vec3A,
    /// The body's world inverse inertia (zero without rotation or at the centre of mass).
    inverse_inertia: glam::Mat3A,
    /// The largest d̂ᵀ W d̂ over the springs at this end (1/kg): how far a unit force along a
    /// spring moves the end, linear and angular response together.
    mobility: f32,
    /// How far the anchor's path over the step curves off the straight line x + h v as the
    /// body turns at its present spin: R(h ω) r − r − h ω × r (m).
    curve: Vec3A,
    /// The end's position and velocity at the step's start and its share of the body's
    /// other forces.
    x0: Vec3A,
    v0: Vec3A,
    f_ext: Vec3A,
}

/// The solve's buffers, kept between substeps so a warm step allocates nothing.
#[derive(Default)]
pub(crate) struct EntitySolve {
    nodes: Nodes,
    network: SpringNetwork,
    ends: Vec<End>,
    index: HashMap<(Entity, [u32; 3]), u32>,
    anchors_per_body: HashMap<Entity, u32>,
    scratch: Scratch<SpringNetwork>,
}

/// What the entity-spring solve keeps from one step to the next: the preconditioner's factor
/// and the topology it was built for. A resource, not the system's scratch, so that a
/// snapshot carries it (a restored world that refactored would round differently).
#[derive(Resource, Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct EntitySpringFactor {
    last_ends: Vec<[u32; 2]>,
    state: ImplicitState,
    /// BDF2's position corrections of this substep, per body (see [`correct_end_positions`]).
    #[serde(skip)]
    corrections: Vec<(Entity, Vec3A)>,
}

impl EntitySolve {
    fn clear(&mut self) {
        let n = &mut self.nodes;
        for buf in [&mut n.x, &mut n.v, &mut n.f] {
            buf.clear();
        }
        n.mass.clear();
        n.inv_mass.clear();
        let s = &mut self.network;
        s.ends.clear();
        s.rest.clear();
        s.k.clear();
        s.c.clear();
        s.max_index = 0;
        s.max_k = 0.0;
        self.ends.clear();
        self.index.clear();
        self.anchors_per_body.clear();
    }

    /// The node for `body`'s end at anchor `a`, added at (x, v) if new.
    fn node(&mut self, body: Entity, a: Vec3, x: Vec3A, v: Vec3A, lever: Vec3A) -> u32 {
        let key = (body, a.to_array().map(f32::to_bits));
        if let Some(&i) = self.index.get(&key) {
            return i;
        }
        let i = self.ends.len() as u32;
        self.index.insert(key, i);
        *self.anchors_per_body.entry(body).or_default() += 1;
        self.nodes.x.push(x);
        self.nodes.v.push(v);
        self.ends.push(End {
            body,
            lever,
            inverse_inertia: glam::Mat3A::ZERO,
            mobility: 0.0,
            curve: Vec3A::ZERO,
            x0: x,
            v0: v,
            f_ext: Vec3A::ZERO,
        });
        i
    }
}

/// The solve's other inputs: the spring order's storage, where its numerical damping goes,
/// and whether the energy diagnostics want it.
type SolveContext<'w, 's> = (
    &'w bevy_ecs::archetype::Archetypes,
    bevy_ecs::component::ComponentIdFor<'s, Spring>,
    Local<'s, Vec<Entity>>,
    ResMut<'w, crate::integrator::stability::SharedNumericalDamping>,
    Option<Res<'w, crate::core::diagnostics::DiagnosticsSettings>>,
);

/// Solves every implicit entity spring of the world in one backward-Euler step and hands the
/// resulting forces to the ends (see the module docs).
#[allow(clippy::too_many_arguments, clippy::type_complexity)] // a system: one query or resource each
pub(crate) fn solve_entity_springs(
    mut commands: Commands,
    global: Res<Integrator>,
    guard: Res<DivergenceGuard>,
    time: Res<SubstepTime>,
    springs: Query<
        (
            Entity,
            &Spring,
            Option<&ImplicitEuler>,
            Has<crate::integrator::LocalSubsteps>,
        ),
        Without<Quarantined>,
    >,
    bodies: Query<EndBody, Without<Quarantined>>,
    spinning: Query<(Spinning, &Inertia), Without<Quarantined>>,
    mut forces: Query<&mut Force, Without<Quarantined>>,
    mut torques: Query<&mut Torque, Without<Quarantined>>,
    mut solve: Local<EntitySolve>,
    mut kept: ResMut<EntitySpringFactor>,
    (archetypes, spring_id, mut order, mut shared, diagnostics): SolveContext,
) {
    let kept = &mut *kept;
    let global = *global;
    let s = &mut *solve;
    s.clear();
    let mut settings = None;
    // Locally substepped springs join the solve while there is one (see `super::local`).
    let solving = global == Integrator::ImplicitEuler || springs.iter().any(|s| s.2.is_some());
    // The nodes are numbered, and the system assembled, in spring order (see `crate::core::order`).
    let all =
        crate::core::order::stable(&springs, archetypes, spring_id.get(), &mut order, |i| i.0);
    for (_, spring, flag, local) in all {
        if !(wants_implicit(global, flag.is_some()) || (local && solving)) {
            continue;
        }
        let (Ok(a), Ok(b)) = (bodies.get(spring.a), bodies.get(spring.b)) else {
            continue;
        };
        if !(end_accepts(global, a.2, a.3) && end_accepts(global, b.2, b.3)) {
            continue;
        }
        let end = |e: Entity, body: EndBody, anchor: Vec3| {
            let spin = if anchor == Vec3::ZERO {
                None
            } else {
                spinning.get(e).ok()
            };
            let (x, v, r) = anchor_state((body.0, body.1), spin.map(|s| s.0), anchor);
            let (inverse_inertia, curve) =
                spin.map_or((glam::Mat3A::ZERO, Vec3A::ZERO), |((q, w), inertia)| {
                    let turned = glam::Quat::from_scaled_axis((w.0 * time.h).into()) * r;
                    (
                        inertia.world_tensors(q.0).1,
                        turned - r - time.h * w.0.cross(r),
                    )
                });
            (x, v, r, inverse_inertia, curve)
        };
        let (xa, va, ra, wa, ca) = end(spring.a, a, spring.anchor_a);
        let (xb, vb, rb, wb, cb) = end(spring.b, b, spring.anchor_b);
        if !(xa.is_finite() && xb.is_finite() && va.is_finite() && vb.is_finite()) {
            // Caught and named by the state check after integration, as for explicit springs.
            continue;
        }
        settings = settings.or(flag.copied());
        let ia = s.node(spring.a, spring.anchor_a, xa, va, ra);
        let ib = s.node(spring.b, spring.anchor_b, xb, vb, rb);
        let dir = (xb - xa).normalize_or_zero();
        for (i, w, c, e) in [(ia, wa, ca, a), (ib, wb, cb, b)] {
            let end = &mut s.ends[i as usize];
            (end.inverse_inertia, end.curve) = (w, c);
            // d̂ᵀ W d̂ = 1/m + (r × d̂)ᵀ I⁻¹ (r × d̂); for coincident ends, any direction's
            // bound 1/m + |r|² |I⁻¹|.
            let arm = end.lever.cross(dir);
            let turning = if dir == Vec3A::ZERO {
                end.lever.length_squared()
                    * w.x_axis
                        .length()
                        .max(w.y_axis.length())
                        .max(w.z_axis.length())
            } else {
                arm.dot(w * arm)
            };
            end.mobility = end.mobility.max(e.2.inverse() + turning);
        }
        let net = &mut s.network;
        net.ends.push([ia, ib]);
        net.rest.push(spring.rest_length);
        net.k.push(spring.stiffness);
        net.c.push(spring.damping);
        net.max_index = net.max_index.max(ia).max(ib);
    }
    if s.network.is_empty() {
        shared.0 = 0.0;
        return;
    }
    let h = time.h;
    for end in &mut s.ends {
        let Ok((_, _, mass, _)) = bodies.get(end.body) else {
            continue;
        };
        let f = forces.get(end.body).map_or(Vec3A::ZERO, |f| f.0);
        let count = s.anchors_per_body[&end.body];
        let (m, f_ext) = if mass.is_pinned() {
            (0.0, Vec3A::ZERO)
        } else if count == 1 && end.lever == Vec3A::ZERO {
            // A particle, or a body held at its centre of mass: exactly its own mass.
            (mass.value(), f)
        } else {
            let m = 1.0 / (count as f32 * end.mobility);
            (m, f * (m * mass.inverse()))
        };
        // The solve predicts an end at x + h v + h² f_ext / m; the anchor of a turning body
        // follows an arc, and a prediction off that arc would stretch a stiff spring by the
        // difference every step (pumping energy into it). The arc's curvature enters as the
        // force that bends the prediction onto it; it is not handed to the body.
        let f_ext = f_ext + end.curve * (m / (h * h));
        end.f_ext = f_ext;
        s.nodes.mass.push(m);
        s.nodes.inv_mass.push(if m > 0.0 { 1.0 / m } else { 0.0 });
        s.nodes.f.push(f_ext);
    }
    if s.network.ends != kept.last_ends || kept.state.built_for.map(|k| k.0) != Some(s.ends.len()) {
        // A new topology needs a new envelope for the factor.
        kept.state = ImplicitState::default();
        kept.last_ends.clone_from(&s.network.ends);
    }
    let mut settings = settings.unwrap_or_default();
    if s.ends.iter().any(|e| e.lever != Vec3A::ZERO) {
        // BDF2's correction moves a body, not its anchor: off the centre of mass it would
        // need an orientation correction too, and without one the swing gains energy.
        settings.scheme = ImplicitScheme::BackwardEuler;
    }
    // The ends' positions are the bodies', rounded by their own integrators: there is no
    // sub-ulp remainder of the solve to carry.
    kept.state.remainder.clear();
    kept.corrections.clear();
    let report = step(
        &mut s.network,
        &mut s.nodes,
        &settings,
        &mut kept.state,
        h,
        &mut s.scratch,
        diagnostics.is_none_or(|d| d.energy),
    );
    let failure = match report {
        None => Some((QuarantineReason::NonFiniteState, None)),
        Some(report) => {
            kept.state.last = report;
            shared.0 = kept.state.numerical_damping;
            crate::integrator::mesh_divergence(&s.nodes, &guard).map(|reason| {
                let node = match reason {
                    QuarantineReason::Diverged {
                        node: Some(node), ..
                    } => Some(node as usize),
                    _ => None,
                };
                (reason, node)
            })
        }
    };
    if let Some((reason, node)) = failure {
        // The solve does not diverge at any stiffness; this is the guard for broken input
        // (a NaN force from game code, a runaway body pulling the rope).
        for (i, end) in s.ends.iter().enumerate() {
            if s.nodes.inv_mass[i] > 0.0 && node.is_none_or(|n| n == i) {
                commands.entity(end.body).insert(Quarantined {
                    reason: reason.clone(),
                });
            }
        }
        return;
    }
    for (i, end) in s.ends.iter().enumerate() {
        let m = s.nodes.mass[i];
        if m == 0.0 {
            continue;
        }
        let f = m * (s.nodes.v[i] - end.v0) / h - end.f_ext;
        if let Ok(mut force) = forces.get_mut(end.body) {
            force.bypass_change_detection().0 += f;
        }
        if end.lever != Vec3A::ZERO
            && let Ok(mut t) = torques.get_mut(end.body)
        {
            t.bypass_change_detection().0 += end.lever.cross(f);
        }
        if settings.scheme == ImplicitScheme::Bdf2 {
            // The kick lands the end on v₁ and the drift on x₀ + h v₁; BDF2's x₁ is
            // (4x₀ − x₋₁)/3 + ⅔h v₁. A body with several ends takes their mean.
            let share = 1.0 / s.anchors_per_body[&end.body] as f32;
            let delta = s.nodes.x[i] - (end.x0 + h * s.nodes.v[i]);
            kept.corrections.push((end.body, share * delta));
        }
    }
}

/// Moves each body by BDF2's position correction of its ends, before the bodies drift: the
/// force handed over sets an end's velocity, and a velocity alone would land it on the
/// symplectic drift x₀ + h v₁, a scheme that is unstable past ωh ≈ 4.
pub(crate) fn correct_end_positions(
    mut kept: ResMut<EntitySpringFactor>,
    mut positions: Query<&mut Position, Without<Quarantined>>,
) {
    for (body, delta) in kept.bypass_change_detection().corrections.drain(..) {
        if let Ok(mut p) = positions.get_mut(body) {
            p.bypass_change_detection().0 += delta;
        }
    }
}
