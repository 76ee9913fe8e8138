//! The contact solver's systems: the biased pass after the velocity kick, the relax pass
//! after the drift.

use bevy_ecs::prelude::*;

use crate::collision::ContactFilter;
use crate::collision::ContactSettings;
use crate::collision::narrow_phase::{ContactImpulse, Contacts};
use crate::collision::solver::exchange::{SolvedBody, gather, scatter};
use crate::collision::solver::{ContactSolver, Softness};
use crate::core::time::SubstepTime;

pub(crate) fn contacts_active(solver: Res<ContactSolver>) -> bool {
    !solver.manifolds.is_empty()
}

/// Contacts or constraints are left from a step that had colliders: the collision systems
/// run once more after the last collider goes, so that its pairs end (with their events)
/// and the solver drops their constraints.
pub(crate) fn has_contacts(solver: Res<ContactSolver>, contacts: Res<Contacts>) -> bool {
    !solver.manifolds.is_empty() || !contacts.pairs.is_empty()
}

fn softness(settings: &ContactSettings, h: f32) -> (Softness, Softness) {
    // An eighth of the substep rate, not Box2D's quarter: at a quarter (60 Hz with 4 substeps
    // of 60 Hz) a 20-row pyramid crept 8–16 cm in 10 s; at an eighth it holds (measured).
    let hertz = settings.hertz.min(0.125 / h);
    (
        Softness::new(hertz, settings.damping_ratio, h),
        Softness::new(2.0 * hertz, settings.damping_ratio, h),
    )
}

/// Warm start, then one biased pass.
pub(crate) fn solve_contacts(
    mut solver: ResMut<ContactSolver>,
    time: Res<SubstepTime>,
    settings: Res<ContactSettings>,
    mut bodies: Query<SolvedBody, ContactFilter>,
) {
    gather(&mut solver, &bodies);
    biased_pass(&mut solver, &time, &settings);
    scatter(&mut solver, &mut bodies);
}

/// The solver's work in [`solve_contacts`], between its gather and its scatter.
pub(crate) fn biased_pass(
    solver: &mut ContactSolver,
    time: &SubstepTime,
    settings: &ContactSettings,
) {
    solver.limit_rotation(settings.max_rotation / time.h);
    solver.record_speeds();
    let (soft, fixed) = softness(settings, time.h);
    solver.warm_start();
    solver.solve(time.h, soft, fixed, true, settings.max_push_velocity);
    solver.solve_grounded(time.h, soft, fixed, true, settings.max_push_velocity);
    solver.limit_deep_speed(settings.max_push_velocity);
}

/// One pass without bias; after the last substep, restitution and the impulses kept for
/// the next step's warm start.
pub(crate) fn relax_contacts(
    mut solver: ResMut<ContactSolver>,
    mut contacts: ResMut<Contacts>,
    time: Res<SubstepTime>,
    settings: Res<ContactSettings>,
    mut bodies: Query<SolvedBody, ContactFilter>,
) {
    gather(&mut solver, &bodies);
    relax_pass(&mut solver, &mut contacts, &time, &settings);
    scatter(&mut solver, &mut bodies);
}

/// The solver's work in [`relax_contacts`], between its gather and its scatter.
pub(crate) fn relax_pass(
    solver: &mut ContactSolver,
    contacts: &mut Contacts,
    time: &SubstepTime,
    settings: &ContactSettings,
) {
    let (soft, fixed) = softness(settings, time.h);
    solver.solve(time.h, soft, fixed, false, settings.max_push_velocity);
    solver.solve_grounded(time.h, soft, fixed, false, settings.max_push_velocity);
    if time.is_last() {
        solver.restitution();
    }
    solver.limit_deep_speed(settings.max_push_velocity);
    if solver.reporting {
        solver.add_substep_totals();
    }
    if time.is_last() {
        solver.for_each_solved(|solved, ahead| {
            if let Some(slot) = ahead {
                contacts.pairs.prefetch(slot);
            }
            let m = solved.constraint;
            let Some(tracked) = contacts
                .pairs
                .at_mut(m.pair)
                .and_then(|s| s.manifolds.get_mut(m.manifold as usize))
            else {
                return;
            };
            // (The time-of-impact manifold, after parry's, is not found here: it is not
            // warm-started.)
            // Points the solver left out (beyond four) start from zero if kept later.
            for p in &mut tracked.points {
                p.data = ContactImpulse::default();
            }
            for &(k, normal) in &solved.normals[..solved.count] {
                if let Some(p) = tracked.points.get_mut(k as usize) {
                    p.data = ContactImpulse { normal };
                }
            }
            tracked.data.tangent = solved.tangent.into();
            tracked.data.twist = solved.twist;
        });
    }
}
