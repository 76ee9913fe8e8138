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
//! [`StabilityPolicy::Automatic`], takes the cheapest [`Rescue`] that keeps the motion:
//!
//! - **[`Rescue::LocalSubsteps`]**: the system alone is stepped explicitly n times per substep
//!   (h/n < h_crit), everything else once. Exact symplectic Euler at a finer step: no
//!   numerical damping, and cheaper than a Newton solve while n is small (a stiff rope of
//!   twenty beads needs 9 and costs a third of BDF2; a top on a stiff pivot needs 8). Chosen
//!   while n is at most the count up to which each effect measured it cheaper than its BDF2
//!   solve (spring systems and soft bodies; `examples/perf_report`, `local_substeps_*`
//!   lines), and for springs anchored off a rigid body's centre up to
//!   [`MAX_LOCAL_SUBSTEPS`], because their implicit alternative, backward Euler, takes a
//!   spinning top's spin.
//! - **[`Rescue::Implicit`]**`(`[`ImplicitScheme::Bdf2`]`)`: past that count. Stable at any
//!   stiffness; it damps only the motions too fast for the step: a pendulum on a stiff rod
//!   keeps its swing, a taut string its tone. One Newton solve per substep.
//! - **[`Rescue::Implicit`]**`(`[`ImplicitScheme::BackwardEuler`]`)`, last: springs anchored off
//!   a body's centre that need more than [`MAX_LOCAL_SUBSTEPS`] (BDF2's position correction
//!   cannot turn a body). It damps every motion.
//!
//! [`StabilityPolicy::SwitchToImplicit`] always takes the implicit scheme it names (backward
//! Euler stays on the [`super::Integrator`] dial too), and [`StabilityPolicy::Warn`] only
//! warns. The policy acts on systems integrated by [`super::Integrator::SymplecticEuler`]
//! (the default); one given another integrator on purpose keeps it and is only warned. Each
//! decision is written once as a [`StabilityWarning`] and counted in
//! [`crate::core::diagnostics::PhysicsDiagnostics::rescued`] (by kind in
//! `rescued_by_substeps`); what an implicit scheme then takes from the motion is measured in
//! [`crate::core::diagnostics::PhysicsDiagnostics::numerical_damping`].

use bevy_ecs::prelude::*;

use super::{ImplicitScheme, Integrator};

/// Local substeps per substep at most for springs anchored off a rigid body's centre, whose
/// only implicit rescue, backward Euler, damps the body's spin; past it, backward Euler.
pub const MAX_LOCAL_SUBSTEPS: u32 = 256;

/// What hooke does with a system (a spring mesh, the entity springs, a soft body) whose
/// explicit stability limit is below the substep. A resource.
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq, Hash, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub enum StabilityPolicy {
    /// The cheapest rescue that keeps the motion (see the module docs): local substeps for a
    /// spring system that needs few, BDF2 otherwise. The default.
    #[default]
    Automatic,
    /// Solve it implicitly by this scheme from then on (an [`super::ImplicitEuler`] is put on
    /// it), and write a [`StabilityWarning`] saying so.
    SwitchToImplicit(ImplicitScheme),
    /// Keep integrating it explicitly and write a [`StabilityWarning`]; the
    /// [`crate::core::quarantine::DivergenceGuard`] catches what then runs away.
    Warn,
}

/// How a system past its explicit limit is integrated from then on.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rescue {
    /// Stepped explicitly this many times per substep, on its own ([`LocalSubsteps`]).
    LocalSubsteps(u32),
    /// Solved implicitly by this scheme ([`super::ImplicitEuler`]).
    Implicit(ImplicitScheme),
}

impl Rescue {
    /// A short lowercase name for reports: `local_substeps`, `bdf2`, `backward_euler`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Rescue::LocalSubsteps(_) => "local_substeps",
            Rescue::Implicit(s) => s.name(),
        }
    }
}

/// What a system past its limit offers the policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RescueOptions {
    /// Local substeps per substep that would keep it stable, if it can be stepped on its own.
    pub local_substeps: Option<u32>,
    /// Up to how many local substeps per substep cost less than its implicit solve (each
    /// effect measures its own: `springs::stability::LOCAL_SUBSTEPS_CHEAPER_UP_TO`,
    /// `soft::stability::LOCAL_SUBSTEPS_CHEAPER_UP_TO`).
    pub cheaper_up_to: u32,
    /// Whether BDF2 is out: springs anchored off a rigid body's centre, whose correction
    /// would have to turn the body.
    pub no_bdf2: bool,
}

impl StabilityPolicy {
    /// The rescue of a system integrated by `method` (only systems under
    /// [`Integrator::SymplecticEuler`], the default, are rescued) given its `options`.
    #[must_use]
    pub fn choose(self, method: Integrator, options: RescueOptions) -> Option<Rescue> {
        if method != Integrator::SymplecticEuler {
            return None;
        }
        let implicit = |s: ImplicitScheme| {
            Rescue::Implicit(if options.no_bdf2 {
                ImplicitScheme::BackwardEuler
            } else {
                s
            })
        };
        match self {
            StabilityPolicy::Warn => None,
            StabilityPolicy::SwitchToImplicit(s) => Some(implicit(s)),
            StabilityPolicy::Automatic => {
                let cap = if options.no_bdf2 {
                    MAX_LOCAL_SUBSTEPS
                } else {
                    options.cheaper_up_to.min(MAX_LOCAL_SUBSTEPS)
                };
                Some(match options.local_substeps {
                    Some(n) if n <= cap => Rescue::LocalSubsteps(n.max(2)),
                    _ => implicit(ImplicitScheme::Bdf2),
                })
            }
        }
    }

    /// The implicit scheme a system that can only be solved implicitly (a soft body) is
    /// switched to under `method`, if any.
    #[must_use]
    pub fn rescue(self, method: Integrator) -> Option<ImplicitScheme> {
        match self.choose(
            method,
            RescueOptions {
                local_substeps: None,
                cheaper_up_to: 0,
                no_bdf2: false,
            },
        ) {
            Some(Rescue::Implicit(s)) => Some(s),
            _ => None,
        }
    }
}

/// A system (a [`crate::springs::SpringNetwork`] mesh, or a [`crate::springs::Spring`]
/// entity) stepped explicitly [`LocalSubsteps::count`] times per substep on its own, with
/// the substep's other forces held: the rescue [`StabilityPolicy::Automatic`] puts on a
/// spring system that needs few more substeps than the world's. Game code may add it too.
/// The entity springs share one local integration, at the largest count among them.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Hash,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[serde(try_from = "u32", into = "u32")]
pub struct LocalSubsteps {
    count: u32,
}

impl TryFrom<u32> for LocalSubsteps {
    type Error = crate::core::error::Error;

    fn try_from(count: u32) -> crate::core::error::Result<Self> {
        Self::try_new(count)
    }
}

impl From<LocalSubsteps> for u32 {
    fn from(local: LocalSubsteps) -> u32 {
        local.count
    }
}

impl LocalSubsteps {
    /// `count` local substeps per substep, 1 to [`MAX_LOCAL_SUBSTEPS`].
    ///
    /// # Errors
    /// [`crate::core::error::Error::OutOfRange`] outside that range.
    pub fn try_new(count: u32) -> crate::core::error::Result<Self> {
        if !(1..=MAX_LOCAL_SUBSTEPS).contains(&count) {
            return Err(crate::core::error::Error::OutOfRange {
                what: "local substeps",
                value: count as f32,
                range: "1 to 256",
            });
        }
        Ok(Self { count })
    }

    /// Local substeps per substep.
    #[must_use]
    pub fn count(self) -> u32 {
        self.count
    }
}

/// Puts `rescue` on a system's entity, replacing the other kind of rescue if it had one.
pub(crate) fn put_rescue(commands: &mut Commands, e: Entity, rescue: Rescue) {
    match rescue {
        Rescue::LocalSubsteps(n) => {
            if let Ok(local) = LocalSubsteps::try_new(n) {
                commands.entity(e).insert(local);
            }
        }
        Rescue::Implicit(scheme) => {
            commands
                .entity(e)
                .remove::<LocalSubsteps>()
                .insert(super::ImplicitEuler::solved_by(scheme));
        }
    }
}

/// `count` symplectic-Euler steps of `h / count` on a mesh: `add_forces` adds its own
/// forces to `nodes.f` at each step's state (false if they came out non-finite), on top of the
/// other forces, held from the substep's start. Pinned nodes move at their velocity.
/// `held` is scratch. The mesh's local substeps ([`LocalSubsteps`]); false on non-finite
/// forces.
pub(crate) fn step_locally(
    nodes: &mut crate::particles::Nodes,
    count: u32,
    h: f32,
    held: &mut Vec<glam::Vec3A>,
    mut add_forces: impl FnMut(&mut crate::particles::Nodes) -> bool,
) -> bool {
    let hs = h / count as f32;
    held.clear();
    held.extend_from_slice(&nodes.f);
    for _ in 0..count {
        nodes.f.copy_from_slice(held);
        if !add_forces(nodes) {
            return false;
        }
        let crate::particles::Nodes {
            x, v, f, inv_mass, ..
        } = nodes;
        for i in 0..x.len() {
            v[i] += (hs * inv_mass[i]) * f[i];
            x[i] += hs * v[i];
        }
    }
    true
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
    /// What [`StabilityPolicy`] switched it to; None if it stays as it was.
    pub rescue: Option<Rescue>,
}

impl StabilityWarning {
    /// The advice, as a sentence.
    #[must_use]
    pub fn advice(&self) -> String {
        match self.rescue {
            Some(Rescue::LocalSubsteps(n)) => format!(
                "{:?} is too stiff for the substep ({:.2e} s > its limit {:.2e} s): it is stepped {n} times per substep on its own from now on ({} substeps would keep the whole world explicit)",
                self.entity, self.substep, self.critical_step, self.substeps_needed
            ),
            Some(Rescue::Implicit(scheme)) => format!(
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

/// One system's explicit limit as its effect computed it this step, for [`apply_policy`].
pub(crate) struct SystemLimit {
    /// The mesh, soft body or spring the rescue goes on.
    pub entity: Entity,
    /// Its limit h_crit (s).
    pub critical_step: f32,
    /// The integrator it runs under.
    pub method: Integrator,
    /// Its effect's measured crossover of local substeps against its implicit solve.
    pub cheaper_up_to: u32,
    /// Whether the limit was recomputed this step (its elements or masses changed).
    pub fresh: bool,
    /// The local substeps it is rescued by, if any.
    pub local: Option<LocalSubsteps>,
}

/// The policy on one system: past its limit for the first time, it is rescued and told once
/// (`warned` is set); rescued by local substeps whose count its changed elements or masses
/// outgrew, it is re-decided silently. Spring meshes and soft bodies share it.
#[allow(clippy::too_many_arguments)] // the system's context, passed through
pub(crate) fn apply_policy(
    commands: &mut Commands,
    warnings: &mut MessageWriter<StabilityWarning>,
    diag: Option<&mut crate::core::diagnostics::PhysicsDiagnostics>,
    policy: StabilityPolicy,
    (dt, substep): (f32, f32),
    system: &SystemLimit,
    warned: &mut bool,
) {
    let options = RescueOptions {
        local_substeps: Some(substeps_needed(substep, system.critical_step)),
        cheaper_up_to: system.cheaper_up_to,
        no_bdf2: false,
    };
    match system.local {
        Some(l) if system.fresh && substep / l.count() as f32 > system.critical_step => {
            if let Some(rescue) = policy.choose(system.method, options) {
                put_rescue(commands, system.entity, rescue);
            }
        }
        Some(_) => {}
        None if !*warned && substep > system.critical_step => {
            *warned = true;
            let rescue = policy.choose(system.method, options);
            if let Some(rescue) = rescue {
                put_rescue(commands, system.entity, rescue);
            }
            tell(
                warnings,
                diag,
                system.entity,
                system.critical_step,
                (dt, substep),
                rescue,
            );
        }
        None => {}
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
    rescue: Option<Rescue>,
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
        d.rescued_by_substeps += u64::from(matches!(rescue, Some(Rescue::LocalSubsteps(_))));
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
