//! The explicit stability limit, and what hooke does with a system past it.
//!
//! Symplectic Euler on a damped oscillator ẍ + 2ζω ẋ + ω² x = 0 is stable while
//! ωh ≤ 2 (√(1 + ζ²) − ζ): 2/ω undamped, 1/(ζω) heavily damped. For a system of many nodes
//! each effect bounds ω² by K, the largest row sum of M^(−1/2) K M^(−1/2) (Gershgorin), and the
//! damping rate 2ζω by C, the same row sum of its damping matrix; then
//!
//! ```text
//! h_crit = (√(C² + 4K) − C) / K        (2/√K without damping, 2/C without stiffness)
//! ```
//!
//! Both sums count the coupling between two free nodes (the k/√(m_i m_j) and c/√(m_i m_j)
//! terms): two free masses on a damper relax twice as fast as one mass on a damper to a wall.
//! Spring systems ([`crate::springs::stability`]) and soft bodies ([`crate::soft`]) each compute
//! their limit and compare it with the substep dt / substeps.
//!
//! **[`StabilityPolicy`]** decides what happens to a system past its limit. The default,
//! [`StabilityPolicy::SwitchToImplicit`] with [`ImplicitScheme::Bdf2`], solves it implicitly
//! from that step on by BDF2, which is stable at any stiffness and damps only the motions too
//! fast for the step: a pendulum on a stiff rod keeps its swing, a taut string its tone. It
//! costs one Newton solve per substep, as backward Euler does (which stays available as
//! `SwitchToImplicit(BackwardEuler)`, and on the [`super::Integrator`] dial). The policy acts on
//! systems integrated by [`super::Integrator::SymplecticEuler`] (the default); one given
//! another integrator on purpose keeps it and is only warned. Each decision is written once
//! as a [`StabilityWarning`] and counted in
//! [`crate::core::diagnostics::PhysicsDiagnostics::rescued`]; what the implicit scheme then
//! takes from the motion is measured in
//! [`crate::core::diagnostics::PhysicsDiagnostics::numerical_damping`].

use bevy_ecs::prelude::*;

use super::{ImplicitScheme, Integrator};

/// What hooke does with a system (a spring mesh, the entity springs, a soft body) whose
/// explicit stability limit is below the substep. A resource.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StabilityPolicy {
    /// Solve it implicitly by this scheme from then on (an [`super::ImplicitEuler`] is put on
    /// it), and write a [`StabilityWarning`] saying so. The default is
    /// [`ImplicitScheme::Bdf2`], which keeps the motion the step can resolve.
    SwitchToImplicit(ImplicitScheme),
    /// Keep integrating it explicitly and write a [`StabilityWarning`]; the
    /// [`crate::core::quarantine::DivergenceGuard`] catches what then runs away.
    Warn,
}

impl Default for StabilityPolicy {
    fn default() -> Self {
        StabilityPolicy::SwitchToImplicit(ImplicitScheme::Bdf2)
    }
}

impl StabilityPolicy {
    /// The scheme a system integrated by `method` is switched to, if any: only systems
    /// under [`Integrator::SymplecticEuler`] (the default) are switched.
    #[must_use]
    pub fn rescue(self, method: Integrator) -> Option<ImplicitScheme> {
        match self {
            StabilityPolicy::SwitchToImplicit(s) if method == Integrator::SymplecticEuler => {
                Some(s)
            }
            _ => None,
        }
    }
}

/// Written once per system whose explicit stability limit is below the substep.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct StabilityWarning {
    /// The spring mesh or soft body, or the spring entity at the stiffest node.
    pub entity: Entity,
    /// Its limit h_crit (s).
    pub critical_step: f32,
    /// The configured substep dt / substeps (s).
    pub substep: f32,
    /// Substeps per step that would keep it stable under the explicit integrators.
    pub substeps_needed: u32,
    /// The implicit scheme [`StabilityPolicy`] switched it to; None if it stays explicit.
    pub rescue: Option<ImplicitScheme>,
}

impl StabilityWarning {
    /// The advice, as a sentence.
    #[must_use]
    pub fn advice(&self) -> String {
        match self.rescue {
            Some(scheme) => format!(
                "{:?} is too stiff for explicit integration (substep {:.2e} s > its limit {:.2e} s): it is solved by {} from now on; {} substeps would keep it explicit",
                self.entity,
                self.substep,
                self.critical_step,
                scheme.name(),
                self.substeps_needed
            ),
            None => format!(
                "{:?} is unstable under explicit integration: substep {:.2e} s > its limit {:.2e} s; use {} substeps or an implicit solve (ImplicitEuler)",
                self.entity, self.substep, self.critical_step, self.substeps_needed
            ),
        }
    }
}

/// Tells that a system is past its limit, once: the [`StabilityWarning`] (with the substeps
/// a step of `dt` would need) and the diagnostics' counts.
pub(crate) fn tell(
    warnings: &mut MessageWriter<StabilityWarning>,
    diag: Option<&mut crate::core::diagnostics::PhysicsDiagnostics>,
    entity: Entity,
    critical_step: f32,
    (dt, substep): (f32, f32),
    rescue: Option<ImplicitScheme>,
) {
    warnings.write(StabilityWarning {
        entity,
        critical_step,
        substep,
        substeps_needed: substeps_needed(dt, critical_step),
        rescue,
    });
    if let Some(d) = diag {
        d.stability_warnings += 1;
        d.rescued += u64::from(rescue.is_some());
    }
}

/// The explicit limit h_crit (s) of a node whose stiffness row sum is `k` (1/s², a bound on
/// ω²) and damping row sum `c` (1/s, a bound on 2ζω); infinite when both are zero. See the
/// module docs.
#[must_use]
pub fn critical_step(k: f32, c: f32) -> f32 {
    let (k, c) = (f64::from(k.max(0.0)), f64::from(c.max(0.0)));
    if k > 0.0 {
        // (√(C² + 4K) − C)/K, written as 4/(√(C² + 4K) + C) so that a small K does not cancel.
        (4.0 / ((c * c + 4.0 * k).sqrt() + c)) as f32
    } else if c > 0.0 {
        (2.0 / c) as f32
    } else {
        f32::INFINITY
    }
}

/// Substeps per step of `dt` (s) that keep a system of limit `h_crit` explicit, with a 10%
/// margin.
#[must_use]
pub fn substeps_needed(dt: f32, h_crit: f32) -> u32 {
    let n = (f64::from(dt) / (0.9 * f64::from(h_crit))).ceil();
    if n.is_finite() && n >= 1.0 {
        n.min(f64::from(u32::MAX)) as u32
    } else {
        1
    }
}

/// The numerical damping (W) of implicit solves that live in no [`super::ImplicitState`]
/// component (the entity springs' shared solve), for [`report_numerical_damping`].
#[derive(Resource, Debug, Clone, Copy, Default)]
pub(crate) struct SharedNumericalDamping(pub f32);

/// Σ of every implicit solve's [`super::ImplicitState::numerical_damping`] into the diagnostics.
pub(crate) fn report_numerical_damping(
    states: Query<&super::ImplicitState, Without<crate::core::quarantine::Quarantined>>,
    shared: Option<Res<SharedNumericalDamping>>,
    diag: Option<ResMut<crate::core::diagnostics::PhysicsDiagnostics>>,
) {
    if let Some(mut diag) = diag {
        diag.numerical_damping = states
            .iter()
            .map(|s| f64::from(s.numerical_damping))
            .sum::<f64>()
            + shared.map_or(0.0, |s| f64::from(s.0));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_is_the_damped_oscillators() {
        // Undamped: 2/ω.
        assert!((critical_step(100.0, 0.0) - 0.2).abs() < 1e-7);
        // Pure damping: 2/C.
        assert!((critical_step(0.0, 50.0) - 0.04).abs() < 1e-7);
        // ζ = 1 at ω = 10: (2/ω)(√2 − 1).
        let h = critical_step(100.0, 20.0);
        assert!((h - 0.2 * (2f32.sqrt() - 1.0)).abs() < 1e-6, "{h}");
        assert_eq!(critical_step(0.0, 0.0), f32::INFINITY);
        assert_eq!(substeps_needed(1.0 / 60.0, f32::INFINITY), 1);
        assert_eq!(substeps_needed(1.0 / 60.0, 1e-3), 19);
    }
}
