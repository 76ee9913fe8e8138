//! The explicit stability limit of spring systems, told.
//!
//! For a spring system the highest frequency ω_max is bounded by Gershgorin's row sums of
//! M^(−1/2) K M^(−1/2), K the springs' stiffness matrix (k d̂ d̂ᵀ blocks, |d̂ d̂ᵀ| ≤ 1), and its
//! damping rate by the same sums of the damping matrix:
//!
//! ```text
//! K = max over free nodes i of  Σ_{springs (i, j)} k (1/m_i + 1/√(m_i m_j))
//! C = the same sum with the damping c
//! h_crit = (√(C² + 4K) − C) / K      (see crate::integrator::stability)
//! ```
//!
//! The bound is exact for one damped spring between two free masses (ω² = k (1/m_a + 1/m_b),
//! 2ζω = c (1/m_a + 1/m_b)) and for a long uniform chain (ω_max → 2 √(k/m)). A pinned end
//! counts as infinitely heavy.
//!
//! Each [`SpringNetwork`] mesh carries its limit in [`SpringStability`], and the entity
//! springs share one in [`EntitySpringStability`]; both are recomputed when springs or
//! masses change. When the configured substep dt / substeps exceeds a system's limit under
//! an explicit integrator, [`StabilityPolicy`] decides (by default: solved by BDF2 from then on),
//! a [`StabilityWarning`] is written once for that system with the substeps it needs, and
//! [`crate::core::diagnostics::PhysicsDiagnostics::stability_warnings`] counts it. Past the
//! limit, explicit springs diverge within a few steps, and
//! [`crate::core::quarantine::DivergenceGuard`] quarantines what runs away.

use std::collections::HashMap;

use bevy_ecs::prelude::*;

use super::{Spring, SpringNetwork};
use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::time::PhysicsTime;
use crate::integrator::stability::{
    LocalSubsteps, RescueOptions, StabilityPolicy, StabilityWarning, SystemLimit, apply_policy,
    critical_step, put_rescue, substeps_needed, tell,
};
use crate::integrator::{ImplicitEuler, Integrator, IntegratorOverride};
use crate::particles::{Mass, Nodes};

/// Local substeps per substep at most that [`StabilityPolicy::Automatic`] takes for a spring
/// system before it solves it by BDF2 instead: measured, BDF2's Newton solve costs about as
/// much as 70 local substeps of the same springs (a 20-bead rope: 9 local substeps cost 0.34
/// of BDF2, 64 cost 0.92; `examples/perf_report`, `local_substeps_*` lines).
pub const LOCAL_SUBSTEPS_CHEAPER_UP_TO: u32 = 64;

/// A [`SpringNetwork`] mesh's explicit stability limit (see the module docs).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct SpringStability {
    /// The largest stable substep h_crit (s); infinite for springs between pinned nodes only.
    pub critical_step: f32,
    /// Whether it has been computed for the current springs and masses.
    computed: bool,
    /// Whether its warning has been written.
    warned: bool,
}

/// The entity springs' shared stability limit (see the module docs).
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct EntitySpringStability {
    /// The largest stable substep over all [`Spring`] entities (s).
    pub critical_step: f32,
    /// The spring at the node with the highest frequency.
    pub spring: Option<Entity>,
    warned: bool,
    /// How many springs were solved implicitly when the limit was computed, and the substep
    /// it was computed for: a change in either recomputes it.
    implicit: usize,
    substep: f32,
}

/// h_crit from per-node (stiffness row sum, damping row sum): the smallest node limit.
fn limit(rows: impl Iterator<Item = (f32, f32)>) -> f32 {
    rows.map(|(k, c)| critical_step(k, c))
        .fold(f32::INFINITY, f32::min)
}

impl SpringNetwork {
    /// The explicit stability limit h_crit (s) of these springs on `nodes` (see
    /// [`crate::springs::stability`]); infinite when no spring touches a free node.
    #[must_use]
    pub fn critical_step(&self, nodes: &Nodes) -> f32 {
        if !self.fits(nodes) {
            return f32::INFINITY;
        }
        let n = nodes.len();
        let (mut kk, mut cc) = (vec![0.0f32; n], vec![0.0f32; n]);
        for (s, &[a, b]) in self.ends.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let (wa, wb) = (nodes.inv_mass[a], nodes.inv_mass[b]);
            let cross = (wa * wb).sqrt();
            kk[a] += self.k[s] * (wa + cross);
            kk[b] += self.k[s] * (wb + cross);
            cc[a] += self.c[s] * (wa + cross);
            cc[b] += self.c[s] * (wb + cross);
        }
        limit(
            (0..n)
                .filter(|&i| nodes.inv_mass[i] > 0.0)
                .map(|i| (kk[i], cc[i])),
        )
    }
}

/// The springs joined to any of `stiff` through movable bodies, transitively (`springs` as
/// (spring, end a, end b)), in `springs`' order; a pinned body joins nothing, since what
/// moves on one side of it does not move the other.
fn joined_system(
    stiff: &[Entity],
    springs: &[(Entity, Entity, Entity)],
    movable: impl Fn(Entity) -> bool,
) -> Vec<Entity> {
    let mut by_body: HashMap<Entity, Vec<usize>> = HashMap::new();
    for (i, &(_, a, b)) in springs.iter().enumerate() {
        for end in [a, b] {
            if movable(end) {
                by_body.entry(end).or_default().push(i);
            }
        }
    }
    let mut taken = vec![false; springs.len()];
    let mut queue: Vec<usize> = Vec::new();
    for (i, s) in springs.iter().enumerate() {
        if stiff.contains(&s.0) {
            taken[i] = true;
            queue.push(i);
        }
    }
    while let Some(i) = queue.pop() {
        let (_, a, b) = springs[i];
        for end in [a, b] {
            for &j in by_body.get(&end).into_iter().flatten() {
                if !taken[j] {
                    taken[j] = true;
                    queue.push(j);
                }
            }
        }
    }
    springs
        .iter()
        .zip(taken)
        .filter_map(|(s, t)| t.then_some(s.0))
        .collect()
}

/// The smallest limit over the entity springs' ends.
fn best_limit(rows: &HashMap<(Entity, [u32; 3]), (f32, f32)>) -> f32 {
    limit(rows.values().copied())
}

/// Recomputes the limits that springs or masses changed, and warns once per system past it
/// (switching it to an implicit scheme as [`StabilityPolicy`] says).
#[allow(clippy::type_complexity, clippy::too_many_arguments)] // the change filters are the point
pub(crate) fn check_stability(
    mut commands: Commands,
    time: Res<PhysicsTime>,
    global: Res<Integrator>,
    policy: Option<Res<StabilityPolicy>>,
    mut meshes: Query<
        (
            Entity,
            Ref<Nodes>,
            Ref<SpringNetwork>,
            &mut SpringStability,
            Has<ImplicitEuler>,
            Option<&IntegratorOverride>,
            Option<&LocalSubsteps>,
        ),
        Without<crate::core::quarantine::Quarantined>,
    >,
    springs: Query<(Entity, Ref<Spring>, Has<ImplicitEuler>)>,
    masses: Query<(Ref<Mass>, Option<&IntegratorOverride>)>,
    inertias: Query<&crate::rigid::Inertia>,
    mut entity_limit: ResMut<EntitySpringStability>,
    mut warnings: MessageWriter<StabilityWarning>,
    mut diag: Option<ResMut<PhysicsDiagnostics>>,
) {
    let global = *global;
    let policy = policy.map_or_else(StabilityPolicy::default, |p| *p);
    let substep = time.dt() / time.substeps() as f32;
    let mut smallest = f32::INFINITY;
    let implicit_dial = global == Integrator::ImplicitEuler;
    for (e, nodes, network, mut stability, implicit, o, local) in &mut meshes {
        let fresh = !stability.computed || nodes.is_changed() || network.is_changed();
        if fresh {
            stability.critical_step = network.critical_step(&nodes);
            stability.computed = true;
        }
        smallest = smallest.min(stability.critical_step);
        if implicit || implicit_dial {
            continue;
        }
        let system = SystemLimit {
            entity: e,
            critical_step: stability.critical_step,
            method: o.map_or(global, |o| o.0),
            cheaper_up_to: LOCAL_SUBSTEPS_CHEAPER_UP_TO,
            fresh,
            local: local.copied(),
        };
        let SpringStability { warned, .. } = &mut *stability;
        apply_policy(
            &mut commands,
            &mut warnings,
            diag.as_deref_mut(),
            policy,
            (time.dt(), substep),
            &system,
            warned,
        );
    }
    // The entity springs integrated explicitly; the implicit ones have no limit.
    let explicit = |flagged: bool| !super::entity_implicit::wants_implicit(global, flagged);
    let implicit_count = springs.iter().filter(|s| !explicit(s.2)).count();
    let changed = !springs.is_empty()
        && (springs.iter().any(|(_, s, _)| s.is_changed())
            || masses.iter().any(|m| m.0.is_changed())
            || entity_limit.spring.is_none()
            || entity_limit.implicit != implicit_count
            || entity_limit.substep != substep);
    if changed {
        entity_limit.implicit = implicit_count;
        entity_limit.substep = substep;
        // Per end (a body, and an anchor on it): its stiffness row, damping sum and inverse
        // mass. An anchor at lever r on a rigid body moves under a force as fast as a mass
        // 1/(1/m + |r|²/I_min) would (the angular response bounded, as in the implicit solve).
        let mut rows: HashMap<(Entity, [u32; 3]), (f32, f32)> = HashMap::new();
        let inverse = |e: Entity, anchor: glam::Vec3| {
            let w = masses.get(e).map_or(0.0, |m| m.0.inverse());
            match inertias.get(e) {
                Ok(i) if w > 0.0 => w + anchor.length_squared() * i.max_inverse_moment(),
                _ => w,
            }
        };
        let key = |e: Entity, a: glam::Vec3| (e, a.to_array().map(f32::to_bits));
        for (_, s, _) in springs.iter().filter(|s| explicit(s.2)) {
            let (anchor_a, anchor_b) = s.anchors();
            let (wa, wb) = (inverse(s.a(), anchor_a), inverse(s.b(), anchor_b));
            let cross = (wa * wb).sqrt();
            for (end, w) in [(key(s.a(), anchor_a), wa), (key(s.b(), anchor_b), wb)] {
                if w > 0.0 {
                    let row = rows.entry(end).or_default();
                    row.0 += s.stiffness() * (w + cross);
                    row.1 += s.damping() * (w + cross);
                }
            }
        }
        let node_limit =
            |end: (Entity, [u32; 3])| rows.get(&end).map(|&(kk, cc)| critical_step(kk, cc));
        let mut best = (f32::INFINITY, None);
        let mut stiff = Vec::new();
        // Springs anchored off a turning body's centre are solved by backward Euler (see
        // `entity_implicit`), and they share one solve with the rest.
        let levered = springs.iter().any(|(_, s, _)| {
            let (a, b) = s.anchors();
            (a != glam::Vec3::ZERO && inertias.contains(s.a()))
                || (b != glam::Vec3::ZERO && inertias.contains(s.b()))
        });
        let rescue = policy.choose(
            Integrator::SymplecticEuler,
            RescueOptions {
                local_substeps: Some(substeps_needed(substep, best_limit(&rows))),
                cheaper_up_to: LOCAL_SUBSTEPS_CHEAPER_UP_TO,
                no_bdf2: levered,
            },
        );
        let symplectic = |end: Entity| {
            masses.get(end).is_ok_and(|(m, o)| {
                m.is_pinned() || o.map_or(global, |o| o.0) == Integrator::SymplecticEuler
            })
        };
        for (e, s, _) in springs.iter().filter(|s| explicit(s.2)) {
            let mut over = false;
            let (anchor_a, anchor_b) = s.anchors();
            for end in [key(s.a(), anchor_a), key(s.b(), anchor_b)] {
                if let Some(h) = node_limit(end) {
                    over |= substep > h;
                    if h < best.0 {
                        best = (h, Some(e));
                    }
                }
            }
            // Under the policy, a spring touching a node past its limit is switched, when
            // both its ends are integrated by symplectic Euler.
            if over && rescue.is_some() && symplectic(s.a()) && symplectic(s.b()) {
                stiff.push(e);
            }
        }
        // The rescue takes the whole system a stiff spring is part of: a spring left at the
        // world's substep beside locally substepped ones, on a shared body, pumped energy
        // in (a 10-node rope of 7,582 N/m under gravity: its middle springs were past the
        // limit, the one at the pin was not, and the rope blew up after 2 s).
        if rescue.is_some() && !stiff.is_empty() {
            let movable = |e: Entity| masses.get(e).is_ok_and(|(m, _)| !m.is_pinned());
            let candidates: Vec<(Entity, Entity, Entity)> = springs
                .iter()
                .filter(|s| explicit(s.2))
                .filter(|(_, s, _)| symplectic(s.a()) && symplectic(s.b()))
                .map(|(e, s, _)| (e, s.a(), s.b()))
                .collect();
            stiff = joined_system(&stiff, &candidates, movable);
        }
        entity_limit.critical_step = best.0;
        entity_limit.spring = best.1;
        if let Some(spring) = best.1
            && !entity_limit.warned
            && substep > best.0
        {
            entity_limit.warned = true;
            tell(
                &mut warnings,
                diag.as_deref_mut(),
                spring,
                best.0,
                (time.dt(), substep),
                rescue.filter(|_| stiff.contains(&spring)),
            );
        }
        if let Some(rescue) = rescue {
            for e in stiff {
                put_rescue(&mut commands, e, rescue);
            }
        }
    }
    smallest = smallest.min(entity_limit.critical_step);
    if let Some(d) = diag.as_mut() {
        d.spring_critical_step = smallest;
    }
}
