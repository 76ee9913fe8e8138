//! How well the joints hold: the widest any joint's anchors stand apart and the largest
//! angular error, measured after each step.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use super::axial;
use super::kinds::{Kinds, describe};
use super::solve::{Angular, Axis, Linear, Rows, Side};
use crate::core::quarantine::Quarantined;
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// How well the joints held in the last step. A resource, measured after each step while a
/// joint exists (with [`crate::core::diagnostics::DiagnosticsSettings::energy`]).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct JointDiagnostics {
    /// Joints measured (those not quarantined, with both bodies present).
    pub joints: usize,
    /// The widest any joint's two anchors stand apart across what it holds (m): the whole
    /// separation of a ball, hinge or weld, a slider's off its rail, and how far a slider
    /// or a distance joint stands past a limit.
    pub largest_gap: f32,
    /// The joint with that gap.
    pub widest: Option<Entity>,
    /// The largest angular error (rad): a hinge's axes apart (and past its angle limits), a
    /// fixed joint's or a slider's turn away from its relative rotation.
    pub largest_angle: f32,
}

type Pose<'a> = (&'a Position, &'a Rotation, Option<&'a CenterOfMass>);

/// A side's pose as the solver sees it, and its anchor from its centre of mass; a world
/// side at the origin with its anchor as it is.
fn pose(bodies: &Query<Pose>, e: Option<Entity>, anchor: Vec3) -> Option<(Side, Vec3A)> {
    let Some(e) = e else {
        return Some((Side::WORLD, anchor.into()));
    };
    let (x, q, com) = bodies.get(e).ok()?;
    let side = Side {
        x: x.0,
        q: q.0,
        ..Side::WORLD
    };
    Some((side, Vec3A::from(anchor - com.map_or(Vec3::ZERO, |c| c.0))))
}

/// How far a joint stands from what it holds: (the anchors' separation across its locked
/// rows and past its length or slide limits (m), the turn across its locked rows and past
/// its angle limits (rad)).
#[must_use]
fn errors(rows: &Rows, a: &Side, b: &Side) -> (f32, f32) {
    let r_a = a.q * rows.local_a;
    let r_b = b.q * rows.local_b;
    let d = (b.x + r_b) - (a.x + r_a);
    let mut gap = match rows.linear {
        Linear::Point => d.length(),
        Linear::Slide { axis_a } => {
            let n = a.q * Vec3A::from(axis_a);
            (d - n * n.dot(d)).length()
        }
        Linear::Free => 0.0,
    };
    let apart = |u: Vec3A, v: Vec3A| u.cross(v).length().atan2(u.dot(v));
    let mut angle = match rows.angular {
        Angular::Free => 0.0,
        Angular::Hinge { axis_a, axis_b } => {
            apart(a.q * Vec3A::from(axis_a), b.q * Vec3A::from(axis_b))
        }
        Angular::Weld { relative } => {
            let e = b.q * (a.q * relative).inverse();
            2.0 * Vec3::new(e.x, e.y, e.z).length().atan2(e.w.abs())
        }
    };
    if let (Some(axis), Some((min, max)), Some(value)) =
        (rows.axial.axis, rows.axial.limits, axial::value(rows, a, b))
    {
        let past = (min - value).max(value - max).max(0.0);
        match axis {
            Axis::Turn { .. } | Axis::Twist { .. } => angle += past,
            Axis::Slide { .. } | Axis::Length => gap += past,
        }
    }
    if let Some((swing, max)) = axial::measure_swing(rows, a, b) {
        angle += (swing.value - max).max(0.0);
    }
    (gap, angle)
}

/// Measures every joint into [`JointDiagnostics`].
pub(super) fn measure_joints(
    joints: Query<(Entity, Kinds), Without<Quarantined>>,
    bodies: Query<Pose>,
    mut out: ResMut<JointDiagnostics>,
) {
    let mut d = JointDiagnostics::default();
    for (entity, kinds) in &joints {
        let Some(joint) = describe(kinds) else {
            continue;
        };
        let ends = joint.bodies();
        let (Some((a, local_a)), Some((b, local_b))) = (
            pose(&bodies, ends.a, ends.anchor_a),
            pose(&bodies, Some(ends.b), ends.anchor_b),
        ) else {
            continue;
        };
        let (gap, angle) = errors(&joint.rows_at(local_a, local_b), &a, &b);
        d.joints += 1;
        if gap > d.largest_gap || d.widest.is_none() {
            d.largest_gap = gap;
            d.widest = Some(entity);
        }
        if angle.is_finite() {
            d.largest_angle = d.largest_angle.max(angle);
        }
    }
    *out = d;
}
