//! `Reflect` for every public component and resource (feature `bevy`), registered with the
//! App so that an inspector and Bevy scenes see them.
//!
//! Internal caches inside them (a contact pair table, a factorisation, a response matrix)
//! are left out of the reflected fields; a collider's shape, a velocity field's closure
//! and a quarantine's reason are reflected as opaque values.

use bevy_app::App;

/// Registers hooke's components, resources and the value types inside them.
pub(super) fn register_types(app: &mut App) {
    macro_rules! register {
        ($($ty:ty),* $(,)?) => {
            $(app.register_type::<$ty>();)*
        };
    }
    register!(
        // The Bevy layer.
        super::PoseHistory,
        super::TransformExtrapolation,
        super::TransformInterpolation,
        super::SyncedTransform,
        // Kernel.
        crate::core::diagnostics::BodyCounts,
        crate::core::diagnostics::DiagnosticsSettings,
        crate::core::diagnostics::PhysicsDiagnostics,
        crate::core::quarantine::DivergenceGuard,
        crate::core::quarantine::QuarantineReason,
        crate::core::quarantine::Quarantined,
        crate::core::rest::SleepTimer,
        crate::core::rest::Sleeping,
        crate::core::rest::SleepingDisabled,
        crate::core::time::PhysicsTime,
        crate::core::time::SubstepTime,
        crate::core::whole_step::WholeStep,
        crate::sleep::SleepSettings,
        // Character controllers.
        crate::character::CharacterController,
        crate::character::CharacterInput,
        crate::character::CharacterState,
        // Particles and fields.
        crate::particles::Position,
        crate::particles::LinearVelocity,
        crate::particles::ExternalForce,
        crate::particles::ExternalImpulse,
        crate::particles::Force,
        crate::particles::GravityScale,
        crate::particles::LinearDamping,
        crate::particles::Mass,
        crate::particles::Tracer,
        crate::particles::Nodes,
        crate::particles::Advection,
        crate::particles::Gravity,
        crate::particles::VelocityField,
        // Integrators.
        crate::integrator::ImplicitEuler,
        crate::integrator::ImplicitReport,
        crate::integrator::ImplicitScheme,
        crate::integrator::ImplicitState,
        crate::integrator::Integrator,
        crate::integrator::IntegratorOverride,
        crate::integrator::ConstraintsActive,
        crate::integrator::LocalSubsteps,
        crate::integrator::StabilityPolicy,
        // Rigid bodies.
        crate::rigid::AngularDamping,
        crate::rigid::AngularMomentum,
        crate::rigid::AngularVelocity,
        crate::rigid::CenterOfMass,
        crate::rigid::ExternalForceAtPoint,
        crate::rigid::ExternalImpulseAtPoint,
        crate::rigid::ExternalTorque,
        crate::rigid::Inertia,
        crate::rigid::KinematicTarget,
        crate::rigid::MaxLinearSpeed,
        crate::rigid::Dominance,
        crate::rigid::LockedAxes,
        crate::rigid::MaxAngularSpeed,
        crate::rigid::OrientationUpdate,
        crate::rigid::Renormalization,
        crate::rigid::RigidBody,
        crate::rigid::Rotation,
        crate::rigid::SkipRenormalization,
        crate::rigid::Torque,
        // Collision.
        crate::collision::Collider,
        crate::collision::ColliderAabb,
        crate::collision::ColliderChanges,
        crate::collision::ColliderDensity,
        crate::collision::ColliderOf,
        crate::collision::ColliderOffset,
        crate::collision::CollisionEventsEnabled,
        crate::collision::ActiveCollisionHooks,
        crate::collision::ContactReporting,
        crate::collision::CollisionLayers,
        crate::collision::CombineRule,
        crate::collision::ContactSettings,
        crate::collision::Contacts,
        crate::collision::Friction,
        crate::collision::PairExclusions,
        crate::collision::Restitution,
        crate::collision::RestitutionThreshold,
        crate::collision::Sensor,
        crate::collision::RayCaster,
        crate::collision::RayHits,
        crate::collision::ShapeCaster,
        crate::collision::ShapeHits,
        crate::collision::QueryFilter,
        crate::collision::Hit,
        // Joints.
        crate::joints::AngularMotor,
        crate::joints::DistanceJoint,
        crate::joints::FixedJoint,
        crate::joints::JointBodies,
        crate::joints::JointBreakForce,
        crate::joints::JointDiagnostics,
        crate::joints::JointImpulse,
        crate::joints::JointLimits,
        crate::joints::JointSettings,
        crate::joints::LinearMotor,
        crate::joints::MotorSpring,
        crate::joints::PrismaticJoint,
        crate::joints::RevoluteJoint,
        crate::joints::SphericalJoint,
        // Springs, cloth, soft bodies.
        crate::springs::Spring,
        crate::springs::SpringNetwork,
        crate::springs::EntitySpringStability,
        crate::springs::SpringStability,
        crate::cloth::Cloth,
        crate::soft::Lame,
        crate::soft::Material,
        crate::soft::NodeAttachments,
        crate::soft::NodeTargets,
        crate::soft::SoftBody,
        crate::soft::SoftBodyStats,
        crate::soft::SoftStability,
        crate::soft::StrainModel,
    );
}
