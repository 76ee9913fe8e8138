//! Rigid-body systems: user inputs, torques, renormalisation. The angular half of each
//! integrator is the integrators' (`integrator::rotation`).

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3A};

use super::{
    AngularDamping, AngularMomentum, AngularVelocity, CenterOfMass, ExternalForceAtPoint, Inertia,
    KinematicTarget, OrientationUpdate, Renormalization, Rotation, SkipRenormalization, Torque,
    free_rotation_split, integrate_rotation, omega_of, world_point,
};
use crate::core::plugin::WorldPlugin;
use crate::core::rest::Simulated;
use crate::core::schedule::{
    ForceSystems, PhysicsSchedule, PrepareSystems, StepSystems, SubstepSchedule,
    add_own_force_systems, add_own_systems,
};
use crate::core::time::PhysicsTime;
use crate::particles::{Force, LinearVelocity, Position};

/// Rotation, angular momentum, torque and renormalisation for bodies with [`Inertia`]. Every
/// system runs only while such a body exists (or, for the optional inputs, while one has
/// them).
#[derive(Debug, Default, Clone, Copy)]
pub struct RigidBodyPlugin;

impl WorldPlugin for RigidBodyPlugin {
    fn build(&self, world: &mut World) {
        world
            .get_resource_or_init::<crate::particles::MassOptional>()
            .0
            .push(|e| e.get::<super::RigidBody>() == Some(&super::RigidBody::Static));
        crate::core::restore::init::<OrientationUpdate>(world);
        crate::core::quarantine::validate_writes::<super::AngularDamping>(world);
        crate::core::quarantine::validate_writes::<super::KinematicTarget>(world);
        crate::core::quarantine::validate_writes::<super::MaxLinearSpeed>(world);
        crate::core::quarantine::validate_writes::<super::MaxAngularSpeed>(world);
        crate::core::restore::init::<Renormalization>(world);
        crate::core::whole_step::block_on::<AngularDamping>(world);
        crate::core::whole_step::block_on::<ExternalForceAtPoint>(world);
        crate::core::whole_step::block_on::<SkipRenormalization>(world);
        crate::core::whole_step::block_on::<super::MaxLinearSpeed>(world);
        crate::core::whole_step::block_on::<super::MaxAngularSpeed>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                drive_kinematic_targets.run_if(any_with_component::<KinematicTarget>),
                sync_angular_inputs.run_if(any_with_component::<Inertia>),
            )
                .chain()
                .in_set(PrepareSystems::Inputs),
        );
        add_own_force_systems(world, || {
            (
                apply_angular_damping
                    .run_if(any_with_component::<AngularDamping>)
                    .in_set(ForceSystems::Damping),
                apply_forces_at_points
                    .run_if(any_with_component::<ExternalForceAtPoint>)
                    .in_set(StepSystems::AccumulateTorque),
                super::locked::hold_locked_translations
                    .run_if(any_with_component::<super::LockedAxes>)
                    .in_set(StepSystems::AccumulateTorque)
                    .after(apply_forces_at_points),
            )
        });
        add_own_systems(
            world,
            SubstepSchedule,
            (
                renormalize_rotations
                    .run_if(any_with_component::<Inertia>)
                    .in_set(StepSystems::Renormalize),
                super::limits::limit_speeds
                    .run_if(
                        any_with_component::<super::MaxLinearSpeed>
                            .or_else(any_with_component::<super::MaxAngularSpeed>),
                    )
                    .in_set(StepSystems::LimitSpeeds),
            ),
        );
    }
}

type AngularInputs<'a> = (
    &'a Rotation,
    &'a Inertia,
    &'a mut AngularVelocity,
    &'a mut AngularMomentum,
);
type WrittenByUser = Or<(Changed<AngularVelocity>, Changed<AngularMomentum>)>;

/// Makes user writes consistent: a written ω sets L = I ω, a written L sets ω = I⁻¹ L. At
/// spawn both count as written; a non-zero ω wins.
fn sync_angular_inputs(mut bodies: Query<AngularInputs, WrittenByUser>) {
    for (q, inertia, mut w, mut l) in &mut bodies {
        let (w_changed, l_changed) = (w.is_changed(), l.is_changed());
        if w_changed && (!l_changed || w.0 != Vec3A::ZERO) {
            if inertia.is_locked() {
                // A spin written about a locked axis is dropped; the free ones are kept.
                w.bypass_change_detection().0 = inertia.drop_locked_spin(w.0);
            }
            l.bypass_change_detection().0 = inertia.angular_momentum(q.0, w.0);
        } else if l_changed && !inertia.is_infinite() {
            w.bypass_change_detection().0 = inertia.angular_velocity(q.0, l.0);
        }
    }
}

type KinematicDrive<'a> = (
    &'a Position,
    &'a Rotation,
    &'a KinematicTarget,
    &'a mut LinearVelocity,
    &'a mut AngularVelocity,
);

/// v = (target − x)/dt and ω = log(q_target q⁻¹)/dt, so the pose is reached at the step's end.
fn drive_kinematic_targets(time: Res<PhysicsTime>, mut bodies: Query<KinematicDrive, Simulated>) {
    let dt = time.dt();
    for (x, q, target, mut v, mut w) in &mut bodies {
        v.0 = (Vec3A::from(target.position) - x.0) / dt;
        let mut dq = target.rotation.normalize() * q.0.inverse();
        if dq.w < 0.0 {
            dq = -dq;
        }
        w.0 = Vec3A::from(dq.to_scaled_axis()) / dt;
    }
}

/// τ −= c L.
fn apply_angular_damping(
    mut bodies: Query<(&mut Torque, &AngularMomentum, &AngularDamping), Simulated>,
) {
    for (mut t, l, c) in &mut bodies {
        t.bypass_change_detection().0 -= c.0 * l.0;
    }
}

type PointForce<'a> = (
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a ExternalForceAtPoint,
    &'a mut Force,
    &'a mut Torque,
);

/// f += F, τ += (p − x) × F.
fn apply_forces_at_points(mut bodies: Query<PointForce, Simulated>) {
    for (x, q, com, ext, mut f, mut t) in &mut bodies {
        let p = if ext.local {
            world_point(x.0, q.0, com.map_or(glam::Vec3::ZERO, |c| c.0), ext.point)
        } else {
            ext.point.into()
        };
        let force = Vec3A::from(ext.force);
        f.bypass_change_detection().0 += force;
        t.bypass_change_detection().0 += (p - x.0).cross(force);
    }
}

/// One orientation step with L held: splitting for bodies with finite inertia, otherwise
/// the chosen ω-held update (kinematic bodies turn at their set ω).
#[inline]
pub(crate) fn turn(
    q: Quat,
    l: Vec3A,
    stored: Vec3A,
    inertia: &Inertia,
    h: f32,
    update: OrientationUpdate,
    strang: bool,
) -> Quat {
    if update == OrientationUpdate::Splitting && !inertia.is_infinite() {
        free_rotation_split(q, inertia, l, h, strang)
    } else {
        integrate_rotation(q, omega_of(inertia, q, l, stored), h, update)
    }
}

/// q ← q / |q| (unless renormalisation is off for the world or the body), then
/// ω = I(q)⁻¹ L for everything that reads ω: springs at anchors, diagnostics, game code. One
/// pass; neither write ticks change detection (the orientation system already marked q).
fn renormalize_rotations(
    on: Res<Renormalization>,
    mut bodies: Query<
        (
            &mut Rotation,
            &AngularMomentum,
            &Inertia,
            &mut AngularVelocity,
            Has<SkipRenormalization>,
        ),
        Simulated,
    >,
) {
    for (mut q, l, inertia, mut w, skip) in &mut bodies {
        if on.0 && !skip {
            let n = q.0.normalize();
            if n.is_finite() {
                q.bypass_change_detection().0 = n;
            }
        }
        if !inertia.is_infinite() {
            w.bypass_change_detection().0 = inertia.angular_velocity(q.0, l.0);
        }
    }
}
