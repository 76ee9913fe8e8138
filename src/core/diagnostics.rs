//! What the last step did: energies, momentum, counts and where the time went.
//!
//! Energies are in J, momentum in kg·m/s, times in wall-clock durations.
//! - kinetic T = Σ ½ m |v|² over particles and mesh nodes (pinned bodies excluded), plus
//!   Σ ½ ω·L over rigid bodies;
//! - angular momentum about the origin Σ x × m v + L;
//! - gravitational U_g = −Σ m g·x (zero at the origin);
//! - spring U_s = Σ ½ k (l − r)²;
//! - linear momentum P = Σ m v.
//!
//! The kernel measures timings and counts quarantined bodies; each effect measures what it
//! owns in [`MeasureSystems`] (the integrators: motion, momentum and gravity; springs: their
//! elastic energy; soft bodies: theirs). The energy pass reads every body once per step; turn it off with
//! [`DiagnosticsSettings::energy`] when a scene is too large to afford it. Timings per set
//! are summed over the substeps of the last step.

use std::time::Duration;

use bevy_platform::time::Instant;

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::core::schedule::{
    FinishSystems, MeasureSystems, PhysicsSchedule, PhysicsSystems, ProbeSystems, StepSystems,
    SubstepSchedule, add_own_systems,
};

/// How many things of each kind the world holds (quarantined ones counted apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct BodyCounts {
    /// Particle entities (with [`Mass`](crate::particles::Mass)).
    pub particles: usize,
    /// Tracers.
    pub tracers: usize,
    /// Spring entities.
    pub springs: usize,
    /// Mesh entities (with [`Nodes`](crate::particles::Nodes)).
    pub meshes: usize,
    /// Nodes over all meshes.
    pub mesh_nodes: usize,
    /// Springs over all spring networks.
    pub mesh_springs: usize,
    /// Rigid bodies with finite or infinite inertia (dynamic and kinematic).
    pub rigid_bodies: usize,
    /// Entities currently quarantined.
    pub quarantined: usize,
}

/// Diagnostics of the last step. A resource.
#[derive(Resource, Debug, Clone, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct PhysicsDiagnostics {
    /// Kinetic energy, translational plus rotational (J).
    pub kinetic_energy: f64,
    /// The rotational part of the kinetic energy, Σ ½ ω·L (J).
    pub rotational_energy: f64,
    /// Total angular momentum about the world origin, Σ x × m v + L (kg·m²/s).
    pub angular_momentum: Vec3,
    /// Gravitational potential energy relative to the origin (J).
    pub gravitational_energy: f64,
    /// Elastic energy stored in springs (J).
    pub spring_energy: f64,
    /// Elastic energy stored in soft bodies (J), from their last force evaluation.
    pub elastic_energy: f64,
    /// Total linear momentum (kg·m/s).
    pub linear_momentum: Vec3,
    /// Entity counts.
    pub counts: BodyCounts,
    /// Wall time per [`StepSystems`] set, in `StepSystems::ORDER`, summed over substeps.
    /// Zero after a step on the whole-step path, which has no sets.
    pub set_times: [Duration; 10],
    /// Whether the last step ran its substeps on the whole-step path (see
    /// [`crate::core::whole_step`]) instead of through [`crate::core::schedule::SubstepSchedule`].
    pub whole_step: bool,
    /// Wall time of the whole last step.
    pub step_time: Duration,
    /// Bodies quarantined since the world started.
    pub quarantined_total: u64,
    /// The most recent quarantine.
    pub last_quarantined: Option<(Entity, QuarantineReason)>,
    /// Frame time dropped by the step cap in the last `advance_physics` call (s).
    pub dropped_time: f32,
    /// The smallest explicit stability limit of the spring systems (s; 0 until the spring
    /// plugin has looked, infinite without springs). See [`crate::springs::stability`].
    pub spring_critical_step: f32,
    /// The smallest explicit stability limit of the soft bodies (s; infinite without any).
    /// See [`crate::soft`].
    pub soft_critical_step: f32,
    /// Systems (spring meshes, the entity springs, soft bodies) warned to be past their
    /// stability limit (each once).
    pub stability_warnings: u64,
    /// Of those, the ones [`crate::integrator::StabilityPolicy`] rescued, by local substeps or
    /// an implicit scheme (since the world started).
    pub rescued: u64,
    /// Of the rescued, the ones stepped by [`crate::integrator::stability::LocalSubsteps`].
    pub rescued_by_substeps: u64,
    /// The energy the implicit schemes take from the motion beyond what the model's own
    /// damping takes, summed over every implicitly solved system (W = J/s, averaged over about
    /// a second): the price of the rescue, in the motion it removes. Zero when nothing is
    /// solved implicitly.
    pub numerical_damping: f64,
}

impl PhysicsDiagnostics {
    /// Kinetic + gravitational + spring + soft-body elastic energy (J).
    #[must_use]
    pub fn total_energy(&self) -> f64 {
        self.kinetic_energy + self.gravitational_energy + self.spring_energy + self.elastic_energy
    }

    /// Wall time of one set in the last step.
    #[must_use]
    pub fn set_time(&self, set: StepSystems) -> Duration {
        let i = StepSystems::ORDER
            .iter()
            .position(|s| *s == set)
            .unwrap_or(0);
        self.set_times[i]
    }
}

/// What the diagnostics measure.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct DiagnosticsSettings {
    /// Compute energies, momentum and counts every step (one read of every body).
    pub energy: bool,
    /// Time every set (two clock reads per set per substep).
    pub timings: bool,
}

impl Default for DiagnosticsSettings {
    fn default() -> Self {
        Self {
            energy: true,
            timings: true,
        }
    }
}

#[derive(Resource, Default)]
struct SetClock {
    last: Option<Instant>,
    acc: [Duration; 10],
}

pub(crate) fn install(world: &mut World) {
    crate::core::restore::init::<PhysicsDiagnostics>(world);
    world.add_observer(count_quarantine);
    crate::core::restore::init::<DiagnosticsSettings>(world);
    crate::core::restore::init::<SetClock>(world);
    for k in 0..=10u8 {
        add_own_systems(
            world,
            SubstepSchedule,
            // The setting is checked inside: a run condition would cost as much as the probe.
            (move |settings: Res<DiagnosticsSettings>, mut clock: ResMut<SetClock>| {
                if !settings.timings {
                    return;
                }
                let now = Instant::now();
                if let (Some(last), Some(slot)) = (clock.last, (k as usize).checked_sub(1)) {
                    clock.acc[slot] += now - last;
                }
                clock.last = Some(now);
            })
            .in_set(ProbeSystems(k)),
        );
    }
    add_own_systems(
        world,
        PhysicsSchedule,
        (
            reset_clock
                .run_if(timings_on)
                .in_set(PhysicsSystems::Prepare),
            publish_timings
                .run_if(timings_on)
                .in_set(FinishSystems::Diagnostics)
                .before(MeasureSystems),
            MeasureSystems::configure(count_quarantined.run_if(energy_on)),
        ),
    );
}

/// Counts every quarantine, as it happens.
fn count_quarantine(
    event: On<Insert<Quarantined>>,
    bodies: Query<&Quarantined>,
    diag: Option<ResMut<PhysicsDiagnostics>>,
) {
    let entity = event.event().entity;
    if let (Some(mut diag), Ok(q)) = (diag, bodies.get(entity)) {
        diag.quarantined_total += 1;
        diag.last_quarantined = Some((entity, q.reason.clone()));
    }
}

fn timings_on(s: Res<DiagnosticsSettings>) -> bool {
    s.timings
}

/// Whether energies, momenta and counts are measured this step: the run condition of every
/// effect's measurement.
pub fn energy_on(s: Res<DiagnosticsSettings>) -> bool {
    s.energy
}

fn reset_clock(mut clock: ResMut<SetClock>) {
    *clock = SetClock::default();
}

fn publish_timings(clock: Res<SetClock>, mut diag: ResMut<PhysicsDiagnostics>) {
    diag.set_times = clock.acc;
}

/// The kernel's own count: bodies in quarantine.
fn count_quarantined(
    mut diag: ResMut<PhysicsDiagnostics>,
    quarantined: Query<(), With<Quarantined>>,
) {
    diag.counts.quarantined = quarantined.iter().count();
}
