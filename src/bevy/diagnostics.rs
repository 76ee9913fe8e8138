//! [`PhysicsDiagnostics`] in Bevy's `DiagnosticsStore`.

use bevy_app::{App, Plugin};
use bevy_diagnostic::{Diagnostic, DiagnosticPath, Diagnostics, RegisterDiagnostic};
use bevy_ecs::prelude::*;

use super::{AppSchedule, PhysicsAppSystems};
use crate::core::diagnostics::PhysicsDiagnostics;

/// Feeds the last step's [`PhysicsDiagnostics`] into `bevy_diagnostic` under `hooke/…`
/// paths (see the associated constants), once per physics step.
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsDiagnosticsPlugin;

impl PhysicsDiagnosticsPlugin {
    /// Wall time of the last step (ms).
    pub const STEP_TIME: DiagnosticPath = DiagnosticPath::const_new("hooke/step_time");
    /// Kinetic energy (J).
    pub const KINETIC_ENERGY: DiagnosticPath = DiagnosticPath::const_new("hooke/kinetic_energy");
    /// Kinetic + gravitational + spring energy (J).
    pub const TOTAL_ENERGY: DiagnosticPath = DiagnosticPath::const_new("hooke/total_energy");
    /// Rigid bodies, dynamic and kinematic.
    pub const RIGID_BODIES: DiagnosticPath = DiagnosticPath::const_new("hooke/rigid_bodies");
    /// Bodies quarantined since start.
    pub const QUARANTINED: DiagnosticPath = DiagnosticPath::const_new("hooke/quarantined_total");
    /// Systems rescued by the stability policy since start (local substeps or implicit).
    pub const RESCUED: DiagnosticPath = DiagnosticPath::const_new("hooke/rescued");
    /// Of those, the ones stepped by local substeps.
    pub const RESCUED_BY_SUBSTEPS: DiagnosticPath =
        DiagnosticPath::const_new("hooke/rescued_by_substeps");
    /// The energy the implicit schemes take from the motion (W): the rescue's price.
    pub const NUMERICAL_DAMPING: DiagnosticPath =
        DiagnosticPath::const_new("hooke/numerical_damping");
}

impl Plugin for PhysicsDiagnosticsPlugin {
    fn build(&self, app: &mut App) {
        app.register_diagnostic(Diagnostic::new(Self::STEP_TIME).with_suffix("ms"))
            .register_diagnostic(Diagnostic::new(Self::KINETIC_ENERGY).with_suffix("J"))
            .register_diagnostic(Diagnostic::new(Self::TOTAL_ENERGY).with_suffix("J"))
            .register_diagnostic(Diagnostic::new(Self::RIGID_BODIES))
            .register_diagnostic(Diagnostic::new(Self::QUARANTINED))
            .register_diagnostic(Diagnostic::new(Self::RESCUED))
            .register_diagnostic(Diagnostic::new(Self::RESCUED_BY_SUBSTEPS))
            .register_diagnostic(Diagnostic::new(Self::NUMERICAL_DAMPING).with_suffix("W"));
        let schedule = app
            .world()
            .get_resource::<AppSchedule>()
            .map_or_else(|| super::PhysicsSchedulePlugin::default().schedule, |s| s.0);
        app.add_systems(schedule, measure.after(PhysicsAppSystems::Step));
    }
}

fn measure(diag: Option<Res<PhysicsDiagnostics>>, mut out: Diagnostics) {
    let Some(d) = diag else {
        return;
    };
    out.add_measurement(&PhysicsDiagnosticsPlugin::STEP_TIME, || {
        d.step_time.as_secs_f64() * 1e3
    });
    out.add_measurement(&PhysicsDiagnosticsPlugin::KINETIC_ENERGY, || {
        d.kinetic_energy
    });
    out.add_measurement(&PhysicsDiagnosticsPlugin::TOTAL_ENERGY, || d.total_energy());
    out.add_measurement(&PhysicsDiagnosticsPlugin::RIGID_BODIES, || {
        d.counts.rigid_bodies as f64
    });
    out.add_measurement(&PhysicsDiagnosticsPlugin::QUARANTINED, || {
        d.quarantined_total as f64
    });
    out.add_measurement(&PhysicsDiagnosticsPlugin::RESCUED, || d.rescued as f64);
    out.add_measurement(&PhysicsDiagnosticsPlugin::RESCUED_BY_SUBSTEPS, || {
        d.rescued_by_substeps as f64
    });
    out.add_measurement(&PhysicsDiagnosticsPlugin::NUMERICAL_DAMPING, || {
        d.numerical_damping
    });
}
