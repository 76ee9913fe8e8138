//! The explicit stability limit of spring systems, told.
//!
//! Symplectic Euler on an undamped oscillator of frequency ω is stable for h < 2/ω. For a
//! spring system the highest frequency ω_max is bounded by Gershgorin's row sums of
//! M^(−1/2) K M^(−1/2), K the springs' stiffness matrix (k d̂ d̂ᵀ blocks, |d̂ d̂ᵀ| ≤ 1):
//!
//! ```text
//! ω_max² ≤ max over free nodes i of  Σ_{springs (i, j)} ( k / m_i + k / √(m_i m_j) )
//! h_crit = 2 / ω_max,   and with damping also h < 2 m_i / Σ c   (the drag's own limit)
//! ```
//!
//! The bound is exact for one spring between two free masses (ω² = k (1/m_a + 1/m_b)) and for
//! a long uniform chain (ω_max → 2 √(k/m)). A pinned end counts as infinitely heavy.
//!
//! Each [`SpringNetwork`] mesh carries its limit in [`SpringStability`], and the entity
//! springs share one in [`EntitySpringStability`]; both are recomputed when springs or
//! masses change. When the configured substep dt / substeps exceeds a system's limit under
//! an explicit integrator, a [`StabilityWarning`] is written once for that system with the
//! substeps it needs, and [`crate::PhysicsDiagnostics::stability_warnings`] counts it.
//! Past the limit the springs diverge within a few steps, and [`crate::DivergenceGuard`]
//! quarantines what runs away.

use std::collections::HashMap;

use bevy_ecs::prelude::*;

use super::{Spring, SpringNetwork};
use crate::diagnostics::PhysicsDiagnostics;
use crate::integrator::ImplicitEuler;
use crate::particles::{Mass, Nodes};
use crate::time::PhysicsTime;

/// A [`SpringNetwork`] mesh's explicit stability limit (see the module docs).
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct SpringStability {
    /// The largest stable substep h_crit (s); infinite for springs between pinned nodes only.
    pub critical_step: f32,
    /// Whether it has been computed for the current springs and masses.
    computed: bool,
    /// Whether its warning has been written.
    warned: bool,
}

/// The entity springs' shared stability limit (see the module docs).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Default)]
pub struct EntitySpringStability {
    /// The largest stable substep over all [`Spring`] entities (s).
    pub critical_step: f32,
    /// The spring at the node with the highest frequency.
    pub spring: Option<Entity>,
    warned: bool,
}

/// Written once per spring system whose explicit stability limit is below the substep.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct StabilityWarning {
    /// The [`SpringNetwork`] mesh, or the spring entity at the stiffest node.
    pub entity: Entity,
    /// Its limit h_crit (s).
    pub critical_step: f32,
    /// The configured substep dt / substeps (s).
    pub substep: f32,
    /// Substeps per step that would keep it stable under the explicit integrators.
    pub substeps_needed: u32,
}

impl StabilityWarning {
    /// The advice, as a sentence.
    #[must_use]
    pub fn advice(&self) -> String {
        format!(
            "spring system {:?} is unstable under explicit integration: substep {:.2e} s > its limit {:.2e} s; use {} substeps",
            self.entity, self.substep, self.critical_step, self.substeps_needed
        )
    }
}

/// h_crit from per-node Σ(k/m_i + k/√(m_i m_j)) and Σ c (see the module docs).
fn limit(rows: impl Iterator<Item = (f32, f32, f32)>) -> f32 {
    // (stiffness row sum, damping sum, mass) per node.
    let mut h = f32::INFINITY;
    for (kk, cc, m) in rows {
        if kk > 0.0 {
            h = h.min(2.0 / kk.sqrt());
        }
        if cc > 0.0 {
            h = h.min(2.0 * m / cc);
        }
    }
    h
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
            cc[a] += self.c[s];
            cc[b] += self.c[s];
        }
        limit(
            (0..n)
                .filter(|&i| nodes.inv_mass[i] > 0.0)
                .map(|i| (kk[i], cc[i], 1.0 / nodes.inv_mass[i])),
        )
    }
}

/// Recomputes the limits that springs or masses changed, and warns once per system past it.
#[allow(clippy::type_complexity)] // the change filters are the point
pub(crate) fn check_stability(
    time: Res<PhysicsTime>,
    mut meshes: Query<
        (
            Entity,
            Ref<Nodes>,
            Ref<SpringNetwork>,
            &mut SpringStability,
            Has<ImplicitEuler>,
        ),
        Without<crate::quarantine::Quarantined>,
    >,
    springs: Query<(Entity, Ref<Spring>)>,
    masses: Query<Ref<Mass>>,
    mut entity_limit: ResMut<EntitySpringStability>,
    mut warnings: MessageWriter<StabilityWarning>,
    mut diag: Option<ResMut<PhysicsDiagnostics>>,
) {
    let substep = time.dt() / time.substeps() as f32;
    let needed = |h_crit: f32| ((time.dt() / (0.9 * h_crit)).ceil() as u32).max(1);
    let mut smallest = f32::INFINITY;
    let mut warn = |entity: Entity, h_crit: f32, diag: &mut Option<ResMut<PhysicsDiagnostics>>| {
        warnings.write(StabilityWarning {
            entity,
            critical_step: h_crit,
            substep,
            substeps_needed: needed(h_crit),
        });
        if let Some(d) = diag {
            d.stability_warnings += 1;
        }
    };
    for (e, nodes, network, mut stability, implicit) in &mut meshes {
        if !stability.computed || nodes.is_changed() || network.is_changed() {
            stability.critical_step = network.critical_step(&nodes);
            stability.computed = true;
        }
        smallest = smallest.min(stability.critical_step);
        // (`ImplicitEuler` on a spring mesh is reserved for the implicit spring solve.)
        if !implicit && !stability.warned && substep > stability.critical_step {
            stability.warned = true;
            warn(e, stability.critical_step, &mut diag);
        }
    }
    let changed = !springs.is_empty()
        && (springs.iter().any(|(_, s)| s.is_changed())
            || masses.iter().any(|m| m.is_changed())
            || entity_limit.spring.is_none());
    if changed {
        let mut rows: HashMap<Entity, (f32, f32)> = HashMap::new();
        let inverse = |e: Entity| masses.get(e).map_or(0.0, |m| m.inverse());
        for (_, s) in &springs {
            let (wa, wb) = (inverse(s.a()), inverse(s.b()));
            let cross = (wa * wb).sqrt();
            for (end, w) in [(s.a(), wa), (s.b(), wb)] {
                if w > 0.0 {
                    let row = rows.entry(end).or_default();
                    row.0 += s.stiffness() * (w + cross);
                    row.1 += s.damping();
                }
            }
        }
        let mut best = (f32::INFINITY, None);
        for (_, s) in &springs {
            for end in [s.a(), s.b()] {
                if let Some(&(kk, cc)) = rows.get(&end) {
                    let h = limit([(kk, cc, 1.0 / inverse(end))].into_iter());
                    if h < best.0 {
                        best = (h, Some(end));
                    }
                }
            }
        }
        let spring = best.1.and_then(|end| {
            springs
                .iter()
                .find(|(_, s)| s.a() == end || s.b() == end)
                .map(|(e, _)| e)
        });
        entity_limit.critical_step = best.0;
        entity_limit.spring = spring;
    }
    smallest = smallest.min(entity_limit.critical_step);
    if let Some(spring) = entity_limit.spring
        && !entity_limit.warned
        && substep > entity_limit.critical_step
    {
        entity_limit.warned = true;
        warn(spring, entity_limit.critical_step, &mut diag);
    }
    if let Some(d) = diag.as_mut() {
        d.spring_critical_step = smallest;
    }
}
