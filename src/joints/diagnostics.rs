//! How well the joints hold: the widest any joint's anchors stand apart and the largest
//! angular error, measured after each step.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use super::{FixedJoint, JointBodies, RevoluteJoint, SphericalJoint};
use crate::core::quarantine::Quarantined;
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// How well the joints held in the last step. A resource, measured after each step while a
/// joint exists (with [`crate::core::diagnostics::DiagnosticsSettings::energy`]).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Default)]
pub struct JointDiagnostics {
    /// Joints measured (those not quarantined, with both bodies present).
    pub joints: usize,
    /// The widest any joint's two anchors stand apart (m).
    pub largest_gap: f32,
    /// The joint with that gap.
    pub widest: Option<Entity>,
    /// The largest angular error (rad): a hinge's axes apart, a fixed joint's turn away
    /// from its relative rotation.
    pub largest_angle: f32,
}

type Pose<'a> = (&'a Position, &'a Rotation, Option<&'a CenterOfMass>);

type Kinds<'a> = AnyOf<(&'a SphericalJoint, &'a RevoluteJoint, &'a FixedJoint)>;

/// A body's shape-frame point `local` in the world; a world side's anchor as it is.
fn world_point(bodies: &Query<Pose>, e: Option<Entity>, local: Vec3) -> Option<Vec3A> {
    let Some(e) = e else {
        return Some(local.into());
    };
    let (x, q, com) = bodies.get(e).ok()?;
    let from_centre = local - com.map_or(Vec3::ZERO, |c| c.0);
    Some(x.0 + q.0 * Vec3A::from(from_centre))
}

fn turn(bodies: &Query<Pose>, e: Option<Entity>) -> Option<glam::Quat> {
    match e {
        None => Some(glam::Quat::IDENTITY),
        Some(e) => bodies.get(e).ok().map(|b| b.1.0),
    }
}

/// Measures every joint into [`JointDiagnostics`].
pub(super) fn measure_joints(
    joints: Query<(Entity, Kinds), Without<Quarantined>>,
    bodies: Query<Pose>,
    mut out: ResMut<JointDiagnostics>,
) {
    let mut d = JointDiagnostics::default();
    for (entity, kinds) in &joints {
        let ends: &JointBodies = match kinds {
            (Some(j), _, _) => &j.bodies,
            (_, Some(j), _) => &j.bodies,
            (_, _, Some(j)) => &j.bodies,
            (None, None, None) => continue,
        };
        let (Some(pa), Some(pb)) = (
            world_point(&bodies, ends.a, ends.anchor_a),
            world_point(&bodies, Some(ends.b), ends.anchor_b),
        ) else {
            continue;
        };
        let (Some(qa), Some(qb)) = (turn(&bodies, ends.a), turn(&bodies, Some(ends.b))) else {
            continue;
        };
        d.joints += 1;
        let gap = (pb - pa).length();
        if gap > d.largest_gap || d.widest.is_none() {
            d.largest_gap = gap;
            d.widest = Some(entity);
        }
        let angle = match kinds {
            (_, Some(h), _) => (qa * h.axis_a).angle_between(qb * h.axis_b),
            (_, _, Some(f)) => (qa * f.relative).angle_between(qb),
            _ => 0.0,
        };
        if angle.is_finite() {
            d.largest_angle = d.largest_angle.max(angle);
        }
    }
    *out = d;
}
