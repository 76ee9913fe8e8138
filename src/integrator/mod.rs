//! Time integrators: the accuracy dial.
//!
//! A body's state is position **x** (m) and velocity **v** (m/s); forces give the
//! acceleration **a** = **f**/m (m/s²). One step of length h (s) advances (x, v):
//!
//! | integrator | update | order | force evaluations per step |
//! |---|---|---|---|
//! | [`Integrator::ExplicitEuler`] | x ← x + h v₀, v ← v + h a(x₀, v₀) | 1 | 1 |
//! | [`Integrator::SymplecticEuler`] (default) | v ← v + h a(x₀, v₀), x ← x + h v (new v) | 1 | 1 |
//! | [`Integrator::VelocityVerlet`] | v½ = v + ½h a₀, x ← x + h v½, v ← v½ + ½h a(x₁, v½) | 2 | 2 |
//! | [`Integrator::Rk4`] | classic Runge–Kutta on (ẋ, v̇) = (v, a) | 4 | 4 |
//! | [`Integrator::ImplicitEuler`] | v ← v + h a(x₁, v₁), x ← x + h v (backward Euler) | 1 | Newton |
//!
//! Symplectic Euler is the lecture's scheme and the default: it costs one force evaluation,
//! and on an undamped oscillator its energy stays bounded (error about ωh/2) instead of
//! growing like explicit Euler's, by a factor (1 + ω²h²) per step.
//!
//! Velocity Verlet here costs two force evaluations, not the textbook one: the textbook
//! reuse of a(x₁) as the next step's a₀ is wrong for velocity-dependent forces (damping), and
//! the substep schedule evaluates forces at the start of every substep anyway.
//!
//! Multi-stage integrators never copy force code: they re-run [`crate::core::schedule::ForceSchedule`]
//! (the same systems as the substep's force sets) at each stage state.
//!
//! **Mixing integrators.** The [`Integrator`] resource sets the default and an
//! [`IntegratorOverride`] component overrides it for one body. Bodies coupled by springs should
//! share an integrator: during a stage re-evaluation, other bodies sit at their end-of-step
//! state.
//!
//! **Measuring order.** Symplectic Euler looks second order when sampled at whole periods of
//! an oscillator; measure at a time that is not a multiple of the period (the tests use
//! t = 0.3 s for a 1 s period).

pub(crate) mod implicit;
mod measure;
mod plugin;
mod rotation;
pub(crate) mod skyline;
pub mod stability;
mod stages;

pub use implicit::ImplicitReport;
pub(crate) use plugin::constant_force;
pub use plugin::{ConstraintsActive, IntegratorPlugin};

/// Meshes the explicit integrators advance: alive, awake, and not solved implicitly.
pub(crate) type ExplicitMesh = (
    Without<crate::core::quarantine::Quarantined>,
    Without<crate::core::rest::Sleeping>,
    Without<ImplicitEuler>,
    Without<stability::LocalSubsteps>,
);
pub use stability::{LocalSubsteps, Rescue, StabilityPolicy, StabilityWarning};
pub use stages::{AngularRk4, Rk4Scratch};

use bevy_ecs::prelude::*;
use glam::Vec3A;

use crate::core::quarantine::{DivergenceGuard, QuarantineReason};
use crate::particles::Nodes;

/// Which time integrator advances bodies. A resource (the default for every body) and, through
/// [`IntegratorOverride`], a per-body choice.
#[derive(
    serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq, Hash, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub enum Integrator {
    /// Forward Euler. First order; energy grows every step. For teaching and comparison.
    ExplicitEuler,
    /// Semi-implicit (symplectic) Euler, the lecture's scheme. First order, bounded energy.
    #[default]
    SymplecticEuler,
    /// Velocity Verlet (kick–drift–kick). Second order, bounded energy, two force evaluations.
    VelocityVerlet,
    /// Classic fourth-order Runge–Kutta. Four force evaluations; slowly loses energy.
    Rk4,
    /// Backward Euler: unconditionally stable, first order, damps. Springs ([`crate::springs::Spring`]
    /// entities and `SpringNetwork` meshes) and soft bodies are solved by Newton's method
    /// ([`ImplicitEuler`] holds the solver's settings); every other force is integrated as
    /// by symplectic Euler, which for forces that do not depend on the state is the same
    /// step.
    ImplicitEuler,
}

impl Integrator {
    /// Every integrator, cheapest first.
    pub const ALL: [Integrator; 5] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
        Integrator::ImplicitEuler,
    ];

    /// The explicit integrators (every one but [`Integrator::ImplicitEuler`]).
    pub const EXPLICIT: [Integrator; 4] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ];

    /// The global order of accuracy.
    #[must_use]
    pub const fn order(self) -> u32 {
        match self {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler | Integrator::ImplicitEuler => {
                1
            }
            Integrator::VelocityVerlet => 2,
            Integrator::Rk4 => 4,
        }
    }

    /// Force evaluations per step (for [`Integrator::ImplicitEuler`], the springs' and soft
    /// bodies' Newton iterations come on top).
    #[must_use]
    pub const fn force_evaluations(self) -> u32 {
        match self {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler | Integrator::ImplicitEuler => {
                1
            }
            Integrator::VelocityVerlet => 2,
            Integrator::Rk4 => 4,
        }
    }

    /// A short lowercase name for reports.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "explicit_euler",
            Integrator::SymplecticEuler => "symplectic_euler",
            Integrator::VelocityVerlet => "velocity_verlet",
            Integrator::Rk4 => "rk4",
            Integrator::ImplicitEuler => "implicit_euler",
        }
    }

    /// True for integrators that need more than the substep's own force evaluation.
    #[must_use]
    pub const fn is_multistage(self) -> bool {
        matches!(self, Integrator::VelocityVerlet | Integrator::Rk4)
    }

    /// True for the integrators whose velocity update is v ← v + h f / m followed by
    /// x ← x + h v (symplectic and backward Euler): a spring solved implicitly hands its
    /// endpoints the force f that makes that update land on the backward-Euler state.
    #[must_use]
    pub const fn kicks_then_drifts(self) -> bool {
        matches!(
            self,
            Integrator::SymplecticEuler | Integrator::ImplicitEuler
        )
    }
}

/// Backward (implicit) Euler for one mesh, in place of the explicit integrators:
/// v₁ = v₀ + h M⁻¹ f(x₁, v₁), x₁ = x₀ + h v₁, solved by Newton's method on the incremental
/// potential ½ (x − y)ᵀ M (x − y) / h² + U(x) − f_extᵀ x with y = x₀ + h v₀, each Newton step a
/// Jacobi-preconditioned conjugate-gradient solve with the element Hessians projected to be
/// positive semi-definite, and a backtracking line search on the potential. Pinned nodes
/// (zero inverse mass) move with their velocity and are filtered out of the solve.
///
/// Unconditionally stable: the step never adds energy, whatever the stiffness and h. It is
/// first order and damps: an undamped oscillator loses the factor 1/(1 + ω²h²) of its energy
/// per step. Put it on an entity beside the mesh ([`crate::soft::SoftBody`]); the constant
/// forces of the step (gravity, external, damping) enter as f_ext.
///
/// Read from a file (a snapshot), its settings are checked: a tolerance positive and finite,
/// Newton iterations 1 to 1,000, conjugate-gradient iterations 1 to 100,000.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[serde(try_from = "ImplicitRecord")]
#[require(ImplicitState)]
pub struct ImplicitEuler {
    /// Newton stops when the gradient's norm has fallen below this fraction of the step's
    /// force scale — the smaller of its first gradient and the external and elastic forces
    /// on the nodes at the iterate (dimensionless; default 1e-3) — or when it stalls at the
    /// floor that f32 positions set (about 1e-4 of the first gradient on a stiff body).
    pub tolerance: f32,
    /// Newton iterations per substep at most (default 8).
    pub max_newton: u32,
    /// Conjugate-gradient iterations per Newton step at most (default 200); each solve stops
    /// at a relative residual of 1e-3.
    pub max_cg: u32,
    /// The conjugate gradients are preconditioned by a Cholesky factor of the system matrix
    /// when that factor (its envelope after a reverse Cuthill–McKee ordering) holds at most
    /// this many numbers (8 bytes each; default 2,000,000, 16 MB); a larger body falls back
    /// to the diagonal (Jacobi). 0 turns the factor off.
    pub max_factor_entries: usize,
    /// The factor is kept from step to step: a factor of a nearby matrix is still an
    /// exact-enough preconditioner, and renewing it costs about a bandwidth² times the
    /// unknowns. Conjugate-gradient iterations past this many per solve (default 1: a fresh
    /// factor solves in one) are counted against it, and it is renewed once they add up to
    /// the cost of a new one (each iteration is a pair of triangular solves).
    pub refactor_after: u32,
    /// The implicit scheme (default [`ImplicitScheme::BackwardEuler`], the dial's).
    pub scheme: ImplicitScheme,
}

/// Which implicit scheme an [`ImplicitEuler`] mesh is solved by. Both are stable at any
/// stiffness and step and cost the same (one Newton solve per substep); they differ in what
/// they damp.
///
/// | scheme | order | an oscillator of frequency ω keeps per step (energy) |
/// |---|---|---|
/// | [`ImplicitScheme::BackwardEuler`] | 1 | 1/(1 + ω²h²): slow motions damp too |
/// | [`ImplicitScheme::Bdf2`] | 2 | 1 − O(ω⁴h⁴) for ωh ≪ 1, → 0 for ωh ≫ 1 |
///
/// BDF2 damps the modes too fast for the step (what makes them stable) and keeps the slow
/// ones (a swing, a bending mode, the motion a game shows): at ωh = 0.05 backward Euler takes
/// 0.25% of the energy per step, BDF2 about 0.0003%. It is G-stable (Dahlquist), so the
/// nonlinear solve is as robust as backward Euler's.
#[derive(
    serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Eq, Hash, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub enum ImplicitScheme {
    /// v₁ = v₀ + h a(x₁, v₁), x₁ = x₀ + h v₁. First order; damps every motion.
    #[default]
    BackwardEuler,
    /// The two-step backward differentiation formula: x₁ = (4x₀ − x₋₁)/3 + ⅔h v₁,
    /// v₁ = (4v₀ − v₋₁)/3 + ⅔h a(x₁, v₁). Second order. Its first step after a change of
    /// step or of mesh is a backward-Euler step (it has no history yet).
    Bdf2,
}

impl ImplicitScheme {
    /// A short lowercase name for reports.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            ImplicitScheme::BackwardEuler => "backward_euler",
            ImplicitScheme::Bdf2 => "bdf2",
        }
    }
}

/// What the implicit solve keeps from one step to the next for one body (the preconditioner's
/// factor); added with [`ImplicitEuler`], nothing to set.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct ImplicitState {
    #[cfg_attr(feature = "bevy", reflect(ignore))]
    pub(crate) factor: Option<skyline::SkylineCholesky>,
    /// (nodes, elements) the factor's pattern was built for; `None` before the first build.
    pub(crate) built_for: Option<(usize, usize)>,
    /// The substep the factor was made at, and whether the last solve asked for a new one.
    pub(crate) h: f32,
    pub(crate) refactor: bool,
    /// Conjugate-gradient iterations past `refactor_after` since the factor was made.
    pub(crate) excess: f64,
    /// The last substep's solve.
    pub(crate) last: ImplicitReport,
    /// [`ImplicitScheme::Bdf2`]'s history: each node's change of position (f64) and of
    /// velocity over the last solve (zero for a node held by a contact), and the substep it
    /// was made at (0: none, or the nodes were changed from outside the step since: the next
    /// solve is a backward-Euler step). Increments, not states, so that an impulse from a
    /// contact or an attachment between solves is not extrapolated as a trend.
    #[serde(default)]
    pub(crate) history: Vec<(glam::DVec3, glam::DVec3)>,
    #[serde(default)]
    pub(crate) history_h: f32,
    /// Each node's position below f32 resolution: what rounding its last solved position
    /// dropped (m). Carried into the next solve, so that a motion of less than an ulp per
    /// substep still adds up instead of rounding away.
    #[serde(default)]
    pub(crate) remainder: Vec<glam::Vec3>,
    /// The energy the scheme takes from the motion beyond the model's own damping (W),
    /// averaged over about a second: see [`ImplicitState::numerical_damping`].
    #[serde(default)]
    pub(crate) numerical_damping: f32,
}

impl ImplicitState {
    /// What the last substep's solve did (Newton and CG iterations, final residual).
    #[must_use]
    pub fn last_solve(&self) -> ImplicitReport {
        self.last
    }

    /// The energy (W = J/s) the implicit scheme takes from this body's motion beyond its own
    /// damping, averaged over about a second of simulated time: the start's kinetic and
    /// elastic energy plus the work of the step's constant forces (gravity, external), less
    /// the model's damping and the end's energy. Backward Euler on an oscillator of energy E
    /// and frequency ω takes about E ω² h; BDF2 orders of magnitude less at ωh ≪ 1. What a
    /// contact held in the solve takes counts too. Zero while the energy diagnostics are off
    /// (`DiagnosticsSettings::energy`): the account costs an element pass per substep.
    #[must_use]
    pub fn numerical_damping(&self) -> f32 {
        self.numerical_damping
    }
}

impl Default for ImplicitEuler {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_newton: 8,
            max_cg: 200,
            max_factor_entries: 2_000_000,
            refactor_after: 1,
            scheme: ImplicitScheme::BackwardEuler,
        }
    }
}

/// [`ImplicitEuler`] as a file holds it.
#[derive(serde::Deserialize)]
struct ImplicitRecord {
    tolerance: f32,
    max_newton: u32,
    max_cg: u32,
    max_factor_entries: usize,
    refactor_after: u32,
    #[serde(default)]
    scheme: ImplicitScheme,
}

impl TryFrom<ImplicitRecord> for ImplicitEuler {
    type Error = crate::core::error::Error;

    fn try_from(r: ImplicitRecord) -> crate::core::error::Result<Self> {
        use crate::core::error::Error;
        if !(r.tolerance.is_finite() && r.tolerance > 0.0) {
            return Err(Error::NotPositive {
                what: "implicit solve tolerance",
                value: r.tolerance,
            });
        }
        for (what, value, max) in [
            ("Newton iterations", r.max_newton, 1_000),
            ("conjugate-gradient iterations", r.max_cg, 100_000),
        ] {
            if value == 0 {
                return Err(Error::TooFew {
                    what,
                    min: 1,
                    got: 0,
                });
            }
            if value > max {
                return Err(Error::TooMany {
                    what,
                    max: max.into(),
                    got: value.into(),
                });
            }
        }
        Ok(Self {
            tolerance: r.tolerance,
            max_newton: r.max_newton,
            max_cg: r.max_cg,
            max_factor_entries: r.max_factor_entries,
            refactor_after: r.refactor_after,
            scheme: r.scheme,
        })
    }
}

impl ImplicitEuler {
    /// The default settings, solved by `scheme`.
    #[must_use]
    pub fn solved_by(scheme: ImplicitScheme) -> Self {
        Self {
            scheme,
            ..Self::default()
        }
    }
}

/// Marks an [`ImplicitEuler`] that [`Integrator::ImplicitEuler`] (the global dial) put on a
/// mesh, so that leaving the dial takes it off again.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, Default)]
pub(crate) struct ImplicitByDial;

/// While the global [`Integrator`] is [`Integrator::ImplicitEuler`], gives every mesh with an
/// `M` (an effect's element component: a spring network, a soft body) and neither an
/// [`ImplicitEuler`] nor an [`IntegratorOverride`] the default solver; takes the ones it gave
/// back off when the dial moves away. Each effect registers it for its own `M`.
#[allow(clippy::type_complexity)] // the filters are the point
pub(crate) fn follow_implicit_dial<M: Component>(
    mut commands: Commands,
    global: Res<Integrator>,
    adopt: Query<Entity, (With<M>, Without<ImplicitEuler>, Without<IntegratorOverride>)>,
    given: Query<Entity, (With<M>, With<ImplicitByDial>)>,
) {
    if *global == Integrator::ImplicitEuler {
        for e in &adopt {
            commands
                .entity(e)
                .insert((ImplicitEuler::default(), ImplicitByDial));
        }
    } else {
        for e in &given {
            commands
                .entity(e)
                .remove::<(ImplicitEuler, ImplicitState, ImplicitByDial)>();
        }
    }
}

/// Per-body override of the global [`Integrator`].
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct IntegratorOverride(pub Integrator);

/// One explicit Euler step: both updates use the start-of-step state.
#[must_use]
#[inline]
pub fn explicit_euler(x: Vec3A, v: Vec3A, a: Vec3A, h: f32) -> (Vec3A, Vec3A) {
    (x + h * v, v + h * a)
}

/// One symplectic Euler step: the velocity first, then the position with the new velocity.
#[must_use]
#[inline]
pub fn symplectic_euler(x: Vec3A, v: Vec3A, a: Vec3A, h: f32) -> (Vec3A, Vec3A) {
    let v = v + h * a;
    (x + h * v, v)
}

/// The velocity kick v + h a.
#[must_use]
#[inline]
pub fn kick(v: Vec3A, a: Vec3A, h: f32) -> Vec3A {
    v + h * a
}

/// The position drift x + h v.
#[must_use]
#[inline]
pub fn drift(x: Vec3A, v: Vec3A, h: f32) -> Vec3A {
    x + h * v
}

/// Why a finite mesh counts as diverged: its farthest node left the world, or its fastest
/// node is past the guard.
#[must_use]
pub(crate) fn mesh_divergence(n: &Nodes, guard: &DivergenceGuard) -> Option<QuarantineReason> {
    let (far, distance) =
        n.x.iter()
            .enumerate()
            .fold((0, 0.0f32), |(bi, bd), (i, x)| {
                let d = x.abs().max_element();
                if d > bd { (i, d) } else { (bi, bd) }
            });
    if distance > guard.max_distance {
        return Some(QuarantineReason::OutOfBounds {
            distance,
            node: Some(far as u32),
        });
    }
    let (i, _) =
        n.v.iter()
            .enumerate()
            .fold((0, 0.0f32), |(bi, bs), (i, v)| {
                let s = v.length_squared();
                if s > bs { (i, s) } else { (bi, bs) }
            });
    guard.check(glam::Vec3A::ZERO, *n.v.get(i)?, Some(i as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symplectic_uses_new_velocity() {
        let (x, v) = symplectic_euler(Vec3A::ZERO, Vec3A::ZERO, Vec3A::X, 0.5);
        assert_eq!(v, Vec3A::splat(0.0) + 0.5 * Vec3A::X);
        assert_eq!(x, 0.25 * Vec3A::X);
        let (x, _) = explicit_euler(Vec3A::ZERO, Vec3A::ZERO, Vec3A::X, 0.5);
        assert_eq!(x, Vec3A::ZERO);
    }
}
