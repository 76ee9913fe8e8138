//! Collision systems: bounding boxes, broad phase, narrow phase, contact solver.

use bevy_ecs::prelude::*;

use super::solver::ContactSolver;
use super::{Collider, ContactEnded, ContactSettings, ContactStarted};
use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::Contacts;
use crate::core::plugin::WorldPlugin;
use crate::core::schedule::{
    CollisionSystems, PhysicsSchedule, StepSystems, SubstepSchedule, add_own_systems,
};

/// Colliders, contacts and the contact solver. Every system runs only while a collider
/// exists; the solver only while some contact does.
#[derive(Debug, Default, Clone, Copy)]
pub struct CollisionPlugin;

impl WorldPlugin for CollisionPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<ContactSettings>(world);
        crate::core::schedule::configure_sets(
            world,
            PhysicsSchedule,
            (
                super::hooks::CollisionHookSystems::FilterPairs,
                super::hooks::CollisionHookSystems::ModifyContacts,
            )
                .chain()
                .in_set(CollisionSystems::Detect),
        );
        crate::collision::solver::whole_step::install(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                correct_contact_settings,
                super::attach::refresh_written_parts,
                super::coincident::forget_recent_spawns,
            )
                .in_set(crate::core::schedule::PrepareSystems::Inputs),
        );
        crate::core::restore::init::<super::ColliderChanges>(world);
        crate::core::restore::init::<BroadPhase>(world);
        crate::core::restore::init::<super::PairExclusions>(world);
        crate::core::restore::init::<Contacts>(world);
        crate::core::restore::init::<ContactSolver>(world);
        crate::core::plugin::add_message::<ContactStarted>(world);
        crate::core::plugin::add_message::<ContactEnded>(world);
        crate::core::plugin::add_message::<super::ContactReport>(world);
        crate::core::quarantine::validate_writes::<super::ContactReporting>(world);
        // Impulses from mesh nodes (soft bodies, cloth) reach their bodies at the start of the
        // next substep, before the bodies' own integrators.
        add_own_systems(
            world,
            crate::core::schedule::SubstepSchedule,
            crate::collision::nodes::coupling::apply_node_impulses
                .run_if(any_with_component::<crate::collision::nodes::coupling::NodeImpulse>)
                .in_set(crate::core::schedule::StepSystems::AccumulateTorque)
                .before(crate::rigid::hold_locked_translations),
        );
        world.add_observer(crate::collision::broad_phase::on_body_inserted);
        world.add_observer(crate::collision::broad_phase::on_body_removed);
        world.add_observer(super::attach::on_body_inserted);
        crate::core::restore::init::<super::coincident::RecentSpawns>(world);
        world.add_observer(super::coincident::separate_coincident_spawns);
        world.add_observer(super::attach::on_child_of_discarded);
        world.add_observer(super::attach::on_child_of_inserted);
        // Casters after the step's poses are final (and child colliders placed).
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                super::casters::update_ray_hits.run_if(any_with_component::<super::RayCaster>),
                super::casters::update_shape_hits.run_if(any_with_component::<super::ShapeCaster>),
                super::reports::write_contact_reports
                    .run_if(any_with_component::<super::ContactReporting>),
            )
                .after(super::attach::place_attached_colliders)
                .in_set(crate::core::schedule::FinishSystems::Writeback),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            super::attach::place_attached_colliders
                .run_if(any_with_component::<super::ColliderOf>)
                .in_set(crate::core::schedule::FinishSystems::Writeback),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                (
                    clear_collider_changes,
                    super::broad_phase::plugin::update_moving_aabbs,
                    super::broad_phase::plugin::update_fixed_aabbs
                        .run_if(super::broad_phase::plugin::fixed_dirty),
                    super::broad_phase::plugin::run_broad_phase
                        .before(super::hooks::CollisionHookSystems::FilterPairs),
                    super::narrow_phase::plugin::update_contacts
                        .after(super::hooks::CollisionHookSystems::FilterPairs)
                        .before(super::hooks::CollisionHookSystems::ModifyContacts),
                    super::narrow_phase::plugin::trigger_contact_events
                        .run_if(any_with_component::<super::CollisionEventsEnabled>),
                )
                    .chain()
                    .in_set(CollisionSystems::Detect),
                crate::collision::solver::prepare::prepare_contacts
                    .in_set(CollisionSystems::Constraints),
            )
                .run_if(
                    any_with_component::<Collider>.or_else(super::solver::plugin::has_contacts),
                ),
        );
        add_own_systems(
            world,
            SubstepSchedule,
            (
                super::solver::plugin::solve_contacts
                    .run_if(super::solver::plugin::contacts_active)
                    .in_set(StepSystems::SolveConstraints),
                super::solver::plugin::relax_contacts
                    .run_if(super::solver::plugin::contacts_active)
                    .in_set(crate::core::schedule::RelaxSystems::Rigid),
            ),
        );
    }
}

/// Empties [`super::ColliderChanges`] once the step's inputs have read it (the sleep plugin
/// wakes the islands that touched a changed collider; their pairs then end through the
/// narrow phase like any other, with their messages).
fn clear_collider_changes(mut changes: ResMut<super::ColliderChanges>) {
    if !changes.0.is_empty() {
        changes.0.clear();
    }
}

/// Settings written with bad values (NaN, negative) are put back to their defaults, field by
/// field, each with an [`InvalidSetting`](crate::core::restore::InvalidSetting) message: a NaN
/// `max_push_velocity` or a negative `margin` dropped bodies through the ground, a negative
/// damping ratio exploded a stack. Runs only in a step after the resource changed.
fn correct_contact_settings(
    mut settings: ResMut<ContactSettings>,
    mut invalid: MessageWriter<crate::core::restore::InvalidSetting>,
    mut bp: ResMut<BroadPhase>,
) {
    if !settings.is_changed() {
        return;
    }
    // The boxes are grown by the margin: fixed colliders' boxes are only recomputed when
    // the lists are rebuilt (a new margin left them at the old one).
    bp.fixed_dirty = true;
    bp.moving_dirty = true;
    let d = ContactSettings::default();
    let current = *settings;
    // (`recycle_distance` and `max_rotation` are left alone: negative or NaN documentedly
    // means "no reuse" and "no limit". A hertz of zero or less means rigid contacts.)
    let ok = |v: f32, finite: bool| v >= 0.0 && (!finite || v.is_finite());
    let fields: [(&'static str, f32, f32, bool); 5] = [
        ("hertz", current.hertz.abs(), d.hertz, true),
        (
            "damping_ratio",
            current.damping_ratio,
            d.damping_ratio,
            true,
        ),
        (
            "max_push_velocity",
            current.max_push_velocity,
            d.max_push_velocity,
            false,
        ),
        (
            "restitution_threshold",
            current.restitution_threshold,
            d.restitution_threshold,
            false,
        ),
        ("margin", current.margin, d.margin, true),
    ];
    let mut fixed = current;
    let mut any = false;
    for (field, value, default, finite) in fields {
        if ok(value, finite) {
            continue;
        }
        any = true;
        invalid.write(crate::core::restore::InvalidSetting {
            resource: "ContactSettings",
            field,
            value,
        });
        match field {
            "hertz" => fixed.hertz = default,
            "damping_ratio" => fixed.damping_ratio = default,
            "max_push_velocity" => fixed.max_push_velocity = default,
            "restitution_threshold" => fixed.restitution_threshold = default,
            _ => fixed.margin = default,
        }
    }
    if any {
        *settings = fixed;
    }
}
