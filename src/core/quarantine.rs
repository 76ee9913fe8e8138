//! NaN quarantine: a body whose state turns non-finite stops being simulated, is reported,
//! and the rest of the world goes on.
//!
//! Two paths lead here:
//! - **Bad input.** A component inserted directly with a non-finite or out-of-range value
//!   (constructors can't be bypassed for [`crate::particles::Mass`], but `Position(Vec3::NAN)` can be
//!   written by hand) is caught by the component's insert hook.
//! - **Blow-up.** A body whose position or velocity is non-finite after integration.
//! - **Runaway.** A body, or a node of a mesh, whose state is still finite but moving faster
//!   than [`DivergenceGuard::max_speed`] — an explicit integrator past its stability limit
//!   gets there in a step or two, long before f32 overflows (a stiff rope reached 1e23 m in
//!   two steps, finite all along). And a spring whose force turned non-finite or whose strain
//!   passed [`DivergenceGuard::max_spring_strain`] quarantines both its ends, naming it.
//!
//! Either way the entity gets [`Quarantined`], every physics system skips it (an archetype
//! filter, so it costs nothing per body), a [`BodyQuarantined`] message is written, and
//! [`crate::core::diagnostics::PhysicsDiagnostics`] counts it. Remove [`Quarantined`] after repairing the state
//! to put the body back.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;

use crate::core::error::Error;

/// Why a body was taken out of the simulation.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(
    feature = "bevy",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Clone, Debug, PartialEq)
)]
pub enum QuarantineReason {
    /// Its position or velocity became NaN or infinite during a step.
    NonFiniteState,
    /// A component was inserted with an invalid value. (Read back from a snapshot, the error
    /// is an [`Error::Restored`] holding its message.)
    InvalidInput(#[serde(with = "error_text")] Error),
    /// Its position passed [`DivergenceGuard::max_distance`] from the origin while finite (a
    /// body flung that far in one step by a pass whose velocity the next pass undid).
    OutOfBounds {
        /// The largest coordinate (m).
        distance: f32,
        /// The mesh node, for a [`crate::particles::Nodes`] mesh.
        node: Option<u32>,
    },
    /// Its speed (m/s) passed [`DivergenceGuard::max_speed`] while finite: the integration
    /// diverged. For a mesh, `node` is its fastest node.
    Diverged {
        /// The speed found (m/s).
        speed: f32,
        /// The mesh node, for a [`crate::particles::Nodes`] mesh.
        node: Option<u32>,
    },
    /// The collision geometry library failed (panicked) on its pair with `other`: a shape at
    /// the edge of what parry handles. The pair is dropped.
    GeometryFailed {
        /// The other collider of the pair.
        other: Entity,
    },
    /// A spring attached to it failed: its force was not finite, or its strain |l − r| / r
    /// passed [`DivergenceGuard::max_spring_strain`].
    SpringFailed {
        /// The spring entity.
        spring: Entity,
        /// Its strain when it failed (infinite or NaN for a non-finite force).
        strain: f32,
    },
    /// Its angular speed passed [`DivergenceGuard::max_angular_speed`] while finite (spun up
    /// by game code or by contacts gone wrong).
    SpunOut {
        /// |ω| (rad/s).
        angular_speed: f32,
    },
}

impl core::fmt::Display for QuarantineReason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let at = |node: &Option<u32>| node.map(|n| format!(" (node {n})")).unwrap_or_default();
        match self {
            Self::NonFiniteState => write!(f, "its state became NaN or infinite"),
            Self::InvalidInput(e) => write!(f, "invalid input: {e}"),
            Self::OutOfBounds { distance, node } => {
                write!(f, "it left the world, {distance} m out{}", at(node))
            }
            Self::Diverged { speed, node } => {
                write!(f, "it diverged at {speed} m/s{}", at(node))
            }
            Self::GeometryFailed { other } => {
                write!(f, "the collision geometry failed on its pair with {other}")
            }
            Self::SpringFailed { spring, strain } => {
                write!(f, "spring {spring} failed at strain {strain}")
            }
            Self::SpunOut { angular_speed } => {
                write!(f, "it spun out at {angular_speed} rad/s")
            }
        }
    }
}

/// When a finite state counts as diverged (see the module docs). Set a field to
/// `f32::INFINITY` to turn that check off. Read from a file (a snapshot), every limit must be
/// positive and not NaN (a NaN limit would turn its check off unseen).
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
#[serde(try_from = "GuardRecord")]
pub struct DivergenceGuard {
    /// Speed beyond any body's in a game (m/s; default 1e4, ten times a rifle bullet's).
    pub max_speed: f32,
    /// Spring strain |l − r| / r beyond any rope's (dimensionless; default 100: a spring
    /// stretched to 101 times its rest length). Zero-length springs and dampers (k = 0) are
    /// not checked: neither has a length to keep.
    pub max_spring_strain: f32,
    /// Distance from the origin along any axis beyond any game world's (m; default 1e6,
    /// [`crate::collision::Collider::MAX_EXTENT`]: f32 resolves positions there to 6 cm). Checked
    /// on positions as well as speeds: a body can be flung far within one step at a speed the
    /// step's last pass has already undone.
    #[serde(default = "far")]
    pub max_distance: f32,
    /// Angular speed beyond any body's in a game (rad/s; default 1e5, 16,000 turns a second:
    /// 265 turns in one 60 Hz step, past anything a step resolves). Game code that spun a
    /// crate to 2e11 rad/s went unreported and, before the contacts' arc casts were capped,
    /// held a step for minutes.
    #[serde(default = "spin_limit")]
    pub max_angular_speed: f32,
}

/// [`DivergenceGuard`] as a file holds it.
#[derive(serde::Deserialize)]
struct GuardRecord {
    max_speed: f32,
    max_spring_strain: f32,
    #[serde(default = "far")]
    max_distance: f32,
    #[serde(default = "spin_limit")]
    max_angular_speed: f32,
}

impl TryFrom<GuardRecord> for DivergenceGuard {
    type Error = crate::core::error::Error;

    fn try_from(r: GuardRecord) -> crate::core::error::Result<Self> {
        for (what, value) in [
            ("guard max_speed", r.max_speed),
            ("guard max_spring_strain", r.max_spring_strain),
            ("guard max_distance", r.max_distance),
            ("guard max_angular_speed", r.max_angular_speed),
        ] {
            // Infinity turns a check off on purpose; NaN would do it unseen.
            if value.is_nan() || value <= 0.0 {
                return Err(crate::core::error::Error::NotPositive { what, value });
            }
        }
        Ok(Self {
            max_speed: r.max_speed,
            max_spring_strain: r.max_spring_strain,
            max_distance: r.max_distance,
            max_angular_speed: r.max_angular_speed,
        })
    }
}

fn far() -> f32 {
    1e6
}

fn spin_limit() -> f32 {
    1e5
}

impl Default for DivergenceGuard {
    fn default() -> Self {
        Self {
            max_speed: 1e4,
            max_spring_strain: 100.0,
            max_distance: far(),
            max_angular_speed: spin_limit(),
        }
    }
}

impl DivergenceGuard {
    /// The hot loops' check folds speed into their finiteness probe, `(x + v s) · 0`, which
    /// is NaN when anything is non-finite or when v s overflows: s = f32::MAX / (max_speed/√3)
    /// makes any axis faster than max_speed/√3 overflow (so every body faster than
    /// max_speed does), at no cost beyond the multiply. A hit is then checked exactly.
    #[must_use]
    #[inline]
    pub(crate) fn overflow_scale(&self) -> f32 {
        let trigger = self.max_speed / 3f32.sqrt();
        if trigger.is_finite() && trigger > 0.0 {
            f32::MAX / trigger
        } else {
            0.0
        }
    }

    /// The position half of the probe: x · scale overflows when |x| > max_distance on an
    /// axis (1 when the check is off).
    #[must_use]
    #[inline]
    pub(crate) fn distance_scale(&self) -> f32 {
        let d = self.max_distance;
        if d.is_finite() && d > 0.0 {
            f32::MAX / d
        } else {
            1.0
        }
    }

    /// The reason for a finite body at `x` moving at `v`, if it diverged or left the world.
    #[must_use]
    pub(crate) fn check(
        &self,
        x: glam::Vec3A,
        v: glam::Vec3A,
        node: Option<u32>,
    ) -> Option<QuarantineReason> {
        let distance = x.abs().max_element();
        if distance > self.max_distance {
            return Some(QuarantineReason::OutOfBounds { distance, node });
        }
        let speed = v.length();
        (speed > self.max_speed).then_some(QuarantineReason::Diverged { speed, node })
    }
}

/// Errors go into snapshots as their message: several variants hold `&'static str` names.
mod error_text {
    use crate::core::error::Error;

    pub(super) fn serialize<S: serde::Serializer>(e: &Error, s: S) -> Result<S::Ok, S::Error> {
        match e {
            Error::Restored(message) => s.serialize_str(message),
            other => s.serialize_str(&other.to_string()),
        }
    }

    pub(super) fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Error, D::Error> {
        <String as serde::Deserialize>::deserialize(d).map(Error::Restored)
    }
}

/// Marks a body that is no longer simulated. See the module docs.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_add = report_quarantine)]
pub struct Quarantined {
    /// Why.
    pub reason: QuarantineReason,
}

/// Written once for every body put into quarantine. Read it with
/// `World::resource::<Messages<BodyQuarantined>>()` or a `MessageReader`; messages live for
/// two `step_physics` / `advance_physics` calls.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct BodyQuarantined {
    /// The body.
    pub entity: Entity,
    /// Why.
    pub reason: QuarantineReason,
}

/// Writes the message, once per body: a second insert while the body is quarantined (a
/// spring's two ends, a NaN found by two systems in one step) only replaces the reason.
/// Effects that care (diagnostics' counts, the broad phase's lists)
/// observe the insert themselves: the core calls none of them.
fn report_quarantine(mut world: DeferredWorld, ctx: HookContext) {
    let Some(reason) = world
        .get::<Quarantined>(ctx.entity)
        .map(|q| q.reason.clone())
    else {
        return;
    };
    world.write_message(BodyQuarantined {
        entity: ctx.entity,
        reason,
    });
}

/// Quarantines `entity` because its state turned non-finite during a step.
pub(crate) fn quarantine_non_finite(commands: &mut Commands, entity: Entity) {
    commands.entity(entity).insert(Quarantined {
        reason: QuarantineReason::NonFiniteState,
    });
}

/// A component whose value can be checked after a direct insert.
pub(crate) trait Validate {
    fn validate(&self) -> Result<(), Error>;
}

/// Insert hook shared by every validated component: quarantine on a bad value.
pub(crate) fn validate_on_insert<T: Component + Validate>(
    mut world: DeferredWorld,
    ctx: HookContext,
) {
    let Some(Err(err)) = world.get::<T>(ctx.entity).map(Validate::validate) else {
        return;
    };
    world.commands().entity(ctx.entity).insert(Quarantined {
        reason: QuarantineReason::InvalidInput(err),
    });
}

/// A `T` changed since the last step, on a body still simulated.
type ChangedLive<T> = (Changed<T>, Without<Quarantined>);

/// Values written through `get_mut` (or any other way past the insert hook): each step,
/// before anything reads them, every changed `T` is validated as an insert would be, and a
/// body with a bad value is quarantined. For cold configuration only (materials, damping,
/// targets) that only some bodies carry: a pass over a component every collider requires
/// would cost every idle body a tick check (materials are checked where contacts read them).
/// Hot state is checked by the integrators' finiteness probes.
pub(crate) fn validate_changed<T: Component + Validate>(
    mut commands: Commands,
    changed: Query<(Entity, &T), ChangedLive<T>>,
) {
    for (e, value) in &changed {
        if let Err(err) = value.validate() {
            commands.entity(e).try_insert(Quarantined {
                reason: QuarantineReason::InvalidInput(err),
            });
        }
    }
}

/// Adds [`validate_changed`] for `T` to the step (effects call it for their cold components).
pub(crate) fn validate_writes<T: Component + Validate>(world: &mut World) {
    crate::core::schedule::add_own_systems(
        world,
        crate::core::schedule::PhysicsSchedule,
        validate_changed::<T>
            .run_if(any_with_component::<T>)
            .in_set(crate::core::schedule::PrepareSystems::Inputs),
    );
}
