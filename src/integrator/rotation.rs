//! The angular half of each integrator for rigid bodies: L advances from τ, q from ω.

use bevy_ecs::prelude::*;
use glam::Vec3A;

use super::stages::Rk4TurnStarts;
use super::{Integrator, IntegratorOverride};
use crate::core::quarantine::{
    DivergenceGuard, QuarantineReason, Quarantined, quarantine_non_finite,
};
use crate::core::rest::Simulated;
use crate::core::time::SubstepTime;
use crate::rigid::turn;
use crate::rigid::{
    AngularMomentum, AngularVelocity, Inertia, OrientationUpdate, Rotation, Torque,
};

type AngularState<'a> = (
    Entity,
    &'a mut Rotation,
    &'a mut AngularMomentum,
    &'a AngularVelocity,
    &'a Torque,
    &'a Inertia,
    Option<&'a IntegratorOverride>,
);

/// The angular half of the velocity phase: L advances from τ (explicit Euler also turns q
/// with the start-of-step ω here). An RK4 body takes symplectic Euler's kick for the
/// constraint solve, its start kept in [`Rk4TurnStarts`] for its stages.
pub(super) fn integrate_angular_momenta(
    global: Res<Integrator>,
    update: Res<OrientationUpdate>,
    time: Res<SubstepTime>,
    mut bodies: Query<AngularState, Simulated>,
    mut starts: ResMut<Rk4TurnStarts>,
) {
    let h = time.h;
    starts.0.clear();
    for (e, mut q, mut l, w, t, inertia, o) in &mut bodies {
        let method = o.map_or(*global, |o| o.0);
        let kick = |l: Vec3A, scale: f32| {
            if inertia.is_infinite() {
                l
            } else {
                l + (scale * h) * t.0
            }
        };
        match method {
            Integrator::ExplicitEuler => {
                q.0 = turn(q.0, l.0, w.0, inertia, h, *update, false);
                l.bypass_change_detection().0 = kick(l.0, 1.0);
            }
            Integrator::SymplecticEuler | Integrator::ImplicitEuler => {
                l.bypass_change_detection().0 = kick(l.0, 1.0);
            }
            Integrator::VelocityVerlet => l.bypass_change_detection().0 = kick(l.0, 0.5),
            Integrator::Rk4 => {
                let predicted = kick(l.0, 1.0);
                starts.0.push((e, q.0, l.0, predicted));
                l.bypass_change_detection().0 = predicted;
            }
        }
    }
}

type OrientationState<'a> = (
    Entity,
    &'a mut Rotation,
    &'a AngularMomentum,
    &'a AngularVelocity,
    &'a Inertia,
    Option<&'a IntegratorOverride>,
);

/// The angular half of the position phase: q advances with ω = I(q)⁻¹ L of the new L.
pub(super) fn integrate_orientations(
    mut commands: Commands,
    global: Res<Integrator>,
    update: Res<OrientationUpdate>,
    time: Res<SubstepTime>,
    guard: Res<DivergenceGuard>,
    mut bodies: Query<OrientationState, Simulated>,
) {
    let h = time.h;
    let spin_limit = guard.max_angular_speed * guard.max_angular_speed;
    for (e, mut q, l, w, inertia, o) in &mut bodies {
        let method = o.map_or(*global, |o| o.0);
        if matches!(
            method,
            Integrator::SymplecticEuler
                | Integrator::VelocityVerlet
                | Integrator::ImplicitEuler
                | Integrator::Rk4
        ) {
            let strang = method == Integrator::VelocityVerlet;
            q.0 = turn(q.0, l.0, w.0, inertia, h, *update, strang);
        }

        if !(q.0.is_finite() && l.0.is_finite()) {
            quarantine_non_finite(&mut commands, e);
        } else if w.0.length_squared() > spin_limit {
            commands.entity(e).insert(Quarantined {
                reason: QuarantineReason::SpunOut {
                    angular_speed: w.0.length(),
                },
            });
        }
    }
}
