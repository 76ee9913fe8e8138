//! The schedules and system sets. **This is the only file that chains run order.**
//!
//! ```text
//! PhysicsSchedule            one fixed step of length dt
//!   PhysicsSystems::Restore    re-create removed resources
//!   PhysicsSystems::Prepare    drop broken springs, derived data
//!   PhysicsSystems::Step       runs SubstepSchedule `substeps` times, h = dt / substeps
//!   PhysicsSystems::Finish     attached colliders' poses, then diagnostics
//!
//! SubstepSchedule            one substep of length h
//!   StepSystems::ClearForces        f ← constant forces: external + m g s
//!   StepSystems::ApplyForces        damping, springs, elasticity, user forces
//!   StepSystems::AccumulateTorque   forces at points → torque (rigid bodies)
//!   StepSystems::IntegrateVelocities
//!   StepSystems::SolveConstraints   contacts and joints act on velocities here
//!   StepSystems::IntegratePositions
//!   StepSystems::RelaxConstraints   contacts again without position bias (soft step)
//!     RelaxSystems::Rigid             rigid contacts
//!     RelaxSystems::Soft              soft-body attachments, then node contacts
//!     RelaxSystems::Cloth             cloth strain limiting, then node contacts
//!   StepSystems::CompleteStages     extra force evaluations of Verlet and RK4
//!   StepSystems::Renormalize        unit quaternions
//!   StepSystems::LimitSpeeds        speed caps
//!
//! ForceSchedule              the three force sets alone, re-run at stage states
//! ```
//!
//! Effect plugins only place systems `.in_set(...)`; force systems go through
//! [`add_force_systems`] so that the substep and the stage re-evaluations run the same code.
//! Every schedule is built with ambiguity detection set to error, and runs single-threaded so
//! that the same inputs give bit-identical results.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::{
    IntoScheduleConfigs, LogLevel, ScheduleBuildSettings, ScheduleConfigs, ScheduleLabel,
    SingleThreadedExecutor,
};
use bevy_ecs::system::ScheduleSystem;

/// One fixed physics step. Run it with [`crate::plugins::PhysicsWorldExt::step_physics`].
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct PhysicsSchedule;

/// One substep; run `substeps` times per [`PhysicsSchedule`].
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct SubstepSchedule;

/// The force sets alone, re-run by multi-stage integrators at stage states.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct ForceSchedule;

/// The sets of [`PhysicsSchedule`], in run order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhysicsSystems {
    /// Resources game code removed are re-created (see [`crate::core::restore`]).
    Restore,
    /// Derived data and bookkeeping before the substeps.
    Prepare,
    /// Runs the substeps.
    Step,
    /// Diagnostics after the substeps.
    Finish,
}

/// The sets of [`SubstepSchedule`] (and, for the first three, [`ForceSchedule`]), in run order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StepSystems {
    /// Force accumulators start at the constant forces: external force plus gravity.
    ClearForces,
    /// Every state-dependent force effect adds into the accumulators.
    ApplyForces,
    /// Forces applied at points become torques on rigid bodies.
    AccumulateTorque,
    /// Velocities advance from forces (and impulses).
    IntegrateVelocities,
    /// Contacts and joints correct velocities.
    SolveConstraints,
    /// Positions advance from velocities; tracers are advected.
    IntegratePositions,
    /// Contacts are solved once more without position bias, so that the push-out velocity
    /// used to resolve penetration does not stay in the bodies (Box2D's soft step "relax").
    RelaxConstraints,
    /// Verlet's second kick and RK4's stages, which re-run [`ForceSchedule`].
    CompleteStages,
    /// Orientations are renormalised to unit quaternions.
    Renormalize,
    /// Speeds are capped ([`crate::rigid::MaxLinearSpeed`], [`crate::rigid::MaxAngularSpeed`]).
    LimitSpeeds,
}

impl StepSystems {
    /// Every set in run order.
    pub const ORDER: [StepSystems; 10] = [
        StepSystems::ClearForces,
        StepSystems::ApplyForces,
        StepSystems::AccumulateTorque,
        StepSystems::IntegrateVelocities,
        StepSystems::SolveConstraints,
        StepSystems::IntegratePositions,
        StepSystems::RelaxConstraints,
        StepSystems::CompleteStages,
        StepSystems::Renormalize,
        StepSystems::LimitSpeeds,
    ];
}

/// The force effects inside [`StepSystems::ApplyForces`], in run order. Forces add into
/// the same accumulators, and floating-point addition is not associative, so a fixed order
/// is what makes results bit-identical from run to run.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ForceSystems {
    /// Drag and damping.
    Damping,
    /// Spring forces.
    Springs,
    /// Elastic forces of deformable meshes.
    Elasticity,
    /// Forces added by game code.
    User,
    /// Spring entities solved by backward Euler, last: every other force is their f_ext.
    ImplicitSprings,
}

/// The two stages inside [`StepSystems::IntegrateVelocities`]: impulses first (they change
/// v and L), then the integrators.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IntegrationSystems {
    /// One-shot impulses.
    Impulses,
    /// The velocity phase of each integrator, linear and angular.
    Integrate,
}

/// The implicit solves inside [`IntegrationSystems::Integrate`], one per kind of mesh, in a
/// fixed order (each solves its own meshes; the order only makes the schedule unambiguous).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImplicitSystems {
    /// Soft bodies' tetrahedra.
    SoftBodies,
    /// Spring networks.
    Springs,
}

/// The stages inside [`StepSystems::IntegratePositions`]: the integrators' position phase,
/// then corrections that systems stepped on their own hand to their bodies (a locally
/// substepped spring's end lands where its own steps took it).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PositionSystems {
    /// Positions and orientations advance from velocities.
    Integrate,
    /// Poses corrected by the systems that stepped them.
    Correct,
}

/// The stages inside [`StepSystems::RelaxConstraints`]: the rigid contacts' relax pass, then
/// the soft bodies' attachments (which move rigid bodies too) and node contacts, which have
/// the last word on where a node may be.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RelaxSystems {
    /// Rigid contacts without bias.
    Rigid,
    /// Soft-body attachments, then soft-body node contacts.
    Soft,
    /// Cloth strain limiting, then cloth node contacts.
    Cloth,
}

/// The stages of [`PhysicsSystems::Prepare`]: user inputs first (kinematic targets, written
/// velocities, broken springs), then collision detection, which reads the settled inputs.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PrepareSystems {
    /// Inputs and bookkeeping.
    Inputs,
    /// Character controllers move and slide against the world as the inputs left it (kinematic
    /// platforms already driven), and push what they walk into.
    Characters,
    /// Velocities game code wrote past the [`crate::core::quarantine::DivergenceGuard`] are quarantined before
    /// the contacts use them.
    Guard,
    /// Islands fall asleep or wake.
    Sleep,
    /// Bounding boxes, broad phase, narrow phase, contact constraints.
    Collision,
}

/// The stages of [`PrepareSystems::Collision`]: contacts are found, sleeping islands that
/// are about to be hit wake (the sleep plugin's), then the step's contact constraints are
/// built from the bodies as they now are.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CollisionSystems {
    /// Bounding boxes, broad phase, narrow phase, contact messages.
    Detect,
    /// Islands about to be hit wake.
    Wake,
    /// Contact constraints.
    Constraints,
}

/// The stages of [`PhysicsSystems::Finish`]: derived poses first (colliders attached to
/// bodies), then diagnostics, which read them.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FinishSystems {
    /// Poses derived from the step's result.
    Writeback,
    /// Energies, momenta, counts, timings.
    Diagnostics,
}

/// Where each effect measures its own energy, momentum and counts into
/// [`crate::core::diagnostics::PhysicsDiagnostics`], inside [`FinishSystems::Diagnostics`]
/// after the kernel's timings. Each effect writes fields of its own, so these systems may run
/// in any order among themselves: add them with [`MeasureSystems::configure`].
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MeasureSystems;

impl MeasureSystems {
    /// `system` in this set, declared free of order among the other measurements.
    pub fn configure<M>(
        system: impl IntoScheduleConfigs<ScheduleSystem, M>,
    ) -> ScheduleConfigs<ScheduleSystem> {
        system.in_set(MeasureSystems).ambiguous_with(MeasureSystems)
    }
}

/// Timing probes between the step sets; probe k runs just before `StepSystems::ORDER[k]`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct ProbeSystems(pub u8);

/// `sync_points: false` leaves deferred commands (only quarantines use them in the step
/// schedules) to the end of each run, which is before the next substep or stage reads them,
/// and saves a sync system per commands-using system.
fn new_schedule(label: impl ScheduleLabel, sync_points: bool) -> Schedule {
    let mut schedule = Schedule::new(label);
    schedule.set_executor(SingleThreadedExecutor::new());
    schedule.set_build_settings(ScheduleBuildSettings {
        ambiguity_detection: LogLevel::Error,
        auto_insert_apply_deferred: sync_points,
        ..Default::default()
    });
    schedule
}

/// Creates the three schedules with their sets chained. Called once by the core plugin.
pub(crate) fn init_schedules(world: &mut World) {
    let mut physics = new_schedule(PhysicsSchedule, true);
    physics.configure_sets(
        (
            PhysicsSystems::Restore,
            PhysicsSystems::Prepare,
            PhysicsSystems::Step,
            PhysicsSystems::Finish,
        )
            .chain(),
    );
    physics.configure_sets(
        (
            PrepareSystems::Inputs,
            PrepareSystems::Characters,
            PrepareSystems::Guard,
            PrepareSystems::Sleep,
            PrepareSystems::Collision,
        )
            .chain()
            .in_set(PhysicsSystems::Prepare),
    );
    physics.configure_sets(
        (
            CollisionSystems::Detect,
            CollisionSystems::Wake,
            CollisionSystems::Constraints,
        )
            .chain()
            .in_set(PrepareSystems::Collision),
    );
    physics.configure_sets(
        (FinishSystems::Writeback, FinishSystems::Diagnostics)
            .chain()
            .in_set(PhysicsSystems::Finish),
    );
    physics.configure_sets(MeasureSystems.in_set(FinishSystems::Diagnostics));

    let mut substep = new_schedule(SubstepSchedule, false);
    substep.configure_sets(
        (
            ProbeSystems(0),
            StepSystems::ClearForces,
            ProbeSystems(1),
            StepSystems::ApplyForces,
            ProbeSystems(2),
            StepSystems::AccumulateTorque,
            ProbeSystems(3),
            StepSystems::IntegrateVelocities,
            ProbeSystems(4),
            StepSystems::SolveConstraints,
            ProbeSystems(5),
            StepSystems::IntegratePositions,
            ProbeSystems(6),
            StepSystems::RelaxConstraints,
            ProbeSystems(7),
            StepSystems::CompleteStages,
            ProbeSystems(8),
            StepSystems::Renormalize,
            ProbeSystems(9),
        )
            .chain(),
    );
    substep.configure_sets((ProbeSystems(9), StepSystems::LimitSpeeds, ProbeSystems(10)).chain());

    substep.configure_sets(
        (IntegrationSystems::Impulses, IntegrationSystems::Integrate)
            .chain()
            .in_set(StepSystems::IntegrateVelocities),
    );
    substep.configure_sets(
        (ImplicitSystems::SoftBodies, ImplicitSystems::Springs)
            .chain()
            .in_set(IntegrationSystems::Integrate),
    );
    substep.configure_sets(
        (PositionSystems::Integrate, PositionSystems::Correct)
            .chain()
            .in_set(StepSystems::IntegratePositions),
    );
    substep.configure_sets(
        (RelaxSystems::Rigid, RelaxSystems::Soft, RelaxSystems::Cloth)
            .chain()
            .in_set(StepSystems::RelaxConstraints),
    );

    let mut forces = new_schedule(ForceSchedule, false);
    for schedule in [&mut substep, &mut forces] {
        schedule.configure_sets(
            (
                ForceSystems::Damping,
                ForceSystems::Springs,
                ForceSystems::Elasticity,
                ForceSystems::User,
                ForceSystems::ImplicitSprings,
            )
                .chain()
                .in_set(StepSystems::ApplyForces),
        );
    }
    forces.configure_sets(
        (
            StepSystems::ClearForces,
            StepSystems::ApplyForces,
            StepSystems::AccumulateTorque,
        )
            .chain(),
    );

    let mut schedules = world.get_resource_or_init::<Schedules>();
    schedules.insert(physics);
    schedules.insert(substep);
    schedules.insert(forces);
}

/// How many of [`SubstepSchedule`]'s systems hooke's own plugins added. A schedule holding
/// more has game systems in its substeps, which the whole-step path (see
/// [`crate::core::whole_step`]) would skip.
#[derive(Resource, Debug, Default)]
pub(crate) struct OwnSubstepSystems(pub usize);

fn substep_systems(world: &World) -> usize {
    world
        .get_resource::<Schedules>()
        .and_then(|s| s.get(SubstepSchedule))
        .map_or(0, Schedule::systems_len)
}

/// [`add_systems`] for hooke's own plugins: systems put into [`SubstepSchedule`] are counted
/// in [`OwnSubstepSystems`].
pub(crate) fn add_own_systems<M>(
    world: &mut World,
    label: impl ScheduleLabel,
    systems: impl IntoScheduleConfigs<ScheduleSystem, M>,
) {
    let counted = label.intern() == SubstepSchedule.intern();
    let before = substep_systems(world);
    add_systems(world, label, systems);
    if counted {
        let added = substep_systems(world).saturating_sub(before);
        world.get_resource_or_init::<OwnSubstepSystems>().0 += added;
    }
}

/// [`add_force_systems`] for hooke's own plugins (counted like [`add_own_systems`]).
pub(crate) fn add_own_force_systems<M, S>(world: &mut World, systems: impl Fn() -> S)
where
    S: IntoScheduleConfigs<ScheduleSystem, M>,
{
    let before = substep_systems(world);
    add_force_systems(world, systems);
    let added = substep_systems(world).saturating_sub(before);
    world.get_resource_or_init::<OwnSubstepSystems>().0 += added;
}

/// Adds force systems to both the substep and the stage re-evaluation schedule.
///
/// `systems` is called once per schedule, so each schedule owns its own system state. Place
/// the systems in [`StepSystems::ClearForces`], one of the [`ForceSystems`] or
/// [`StepSystems::AccumulateTorque`].
pub fn add_force_systems<M, S>(world: &mut World, systems: impl Fn() -> S)
where
    S: IntoScheduleConfigs<ScheduleSystem, M>,
{
    let mut schedules = world.get_resource_or_init::<Schedules>();
    schedules.add_systems(SubstepSchedule, systems());
    schedules.add_systems(ForceSchedule, systems());
}

/// Adds systems to one schedule.
pub fn add_systems<M>(
    world: &mut World,
    label: impl ScheduleLabel,
    systems: impl IntoScheduleConfigs<ScheduleSystem, M>,
) {
    world
        .get_resource_or_init::<Schedules>()
        .add_systems(label, systems);
}

/// Configures system sets of one schedule (an effect's own sets, placed inside the
/// kernel's).
pub(crate) fn configure_sets<M>(
    world: &mut World,
    label: impl ScheduleLabel,
    sets: impl IntoScheduleConfigs<bevy_ecs::schedule::InternedSystemSet, M>,
) {
    world
        .get_resource_or_init::<Schedules>()
        .configure_sets(label, sets);
}
