//! Contact reports: each step, for the pairs of colliders that ask, where they touch and
//! the impulse that passed between them.

use bevy_ecs::prelude::*;
use bevy_platform::collections::HashMap;
use glam::{Vec3, Vec3A};

use crate::collision::narrow_phase::Contacts;
use crate::collision::solver::ContactSolver;
use crate::collision::{part_pose, shape_pose};
use crate::core::error::Result;
use crate::core::quarantine::{Validate, validate_on_insert};
use crate::core::time::PhysicsTime;
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// Opts a collider in to a [`ContactReport`] every step for each pair it is in that the
/// contact solver worked on (touching, or closing within the contact margin). Reports cost
/// a pass over the contacts per substep while any collider has this.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct ContactReporting {
    /// The smallest total normal impulse over a step that is reported (N·s; 0, the
    /// default, reports every solved pair, a speculative one with no impulse included).
    /// With both colliders reporting, the lower threshold applies.
    pub min_impulse: f32,
}

impl Default for ContactReporting {
    fn default() -> Self {
        Self { min_impulse: 0.0 }
    }
}

impl ContactReporting {
    /// Reports of pairs whose normal impulse over a step reaches `min_impulse` (N·s): impacts
    /// and heavy loads, not every touch.
    #[must_use]
    pub fn above(min_impulse: f32) -> Self {
        Self { min_impulse }
    }
}

impl Validate for ContactReporting {
    fn validate(&self) -> Result<()> {
        crate::core::error::non_negative("contact report threshold", self.min_impulse).map(|_| ())
    }
}

/// One contact point of a [`ContactReport`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReportedPoint {
    /// The point on `a`'s surface where the step began (m, world frame).
    pub position: Vec3,
    /// Unit normal from `a` to `b` the impulse acted along (world frame).
    pub normal: Vec3,
    /// Separation when the step began (m; negative when overlapping).
    pub separation: f32,
    /// Normal impulse this point gave over the whole step, all substeps (N·s).
    pub normal_impulse: f32,
}

/// Written after each step for a pair of colliders, one of which has [`ContactReporting`]:
/// where they touch and what passed between them over the step.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct ContactReport {
    /// The lower entity.
    pub a: Entity,
    /// The higher entity.
    pub b: Entity,
    /// Unit normal from `a` to `b` of the manifold that carried the most impulse.
    pub normal: Vec3,
    /// The points the solver worked on.
    pub points: Vec<ReportedPoint>,
    /// Total normal impulse over the step (N·s): the sum of the points'.
    pub normal_impulse: f32,
    /// Total impulse on `b` over the step, normal and friction (N·s, world frame; `a` took
    /// the opposite). The twist friction about the normal is not in it.
    pub impulse: Vec3,
    /// The step's length (s).
    pub dt: f32,
}

impl ContactReport {
    /// The mean force on `b` over the step (N, world frame): [`Self::impulse`] / dt.
    #[must_use]
    pub fn force(&self) -> Vec3 {
        if self.dt > 0.0 {
            self.impulse / self.dt
        } else {
            Vec3::ZERO
        }
    }

    /// The friction part of [`Self::impulse`] (N·s): what is left after the normal
    /// impulses, point by point.
    #[must_use]
    pub fn friction_impulse(&self) -> Vec3 {
        self.points
            .iter()
            .fold(self.impulse, |f, p| f - p.normal * p.normal_impulse)
    }
}

type Placed<'a> = (&'a Position, &'a Rotation, Option<&'a CenterOfMass>);

/// Writes the step's [`ContactReport`]s, in the contact solver's order (the broad phase's,
/// which does not depend on when the colliders were spawned beyond their entity ids).
pub(crate) fn write_contact_reports(
    solver: Res<ContactSolver>,
    contacts: Res<Contacts>,
    time: Res<PhysicsTime>,
    reporting: Query<&ContactReporting>,
    poses: Query<Placed>,
    mut out: MessageWriter<ContactReport>,
) {
    if !solver.reporting {
        return;
    }
    let mut keys: HashMap<u32, (Entity, Entity)> = HashMap::default();
    for p in &contacts.active {
        if reporting.contains(p.a) || reporting.contains(p.b) {
            keys.insert(p.slot, (p.a, p.b));
        }
    }
    for &(a, b) in &contacts.woken {
        if (reporting.contains(a) || reporting.contains(b))
            && let Some(slot) = contacts.pairs.slot(&(a, b))
        {
            keys.insert(slot, (a, b));
        }
    }
    if keys.is_empty() {
        return;
    }
    let manifolds = &solver.manifolds;
    let mut i = 0;
    while i < manifolds.len() {
        let slot = manifolds[i].pair;
        let end = manifolds[i..]
            .iter()
            .position(|m| m.pair != slot)
            .map_or(manifolds.len(), |k| i + k);
        let range = i..end;
        i = end;
        let Some(&(a, b)) = keys.get(&slot) else {
            continue;
        };
        let Some(state) = contacts.pairs.at(slot) else {
            continue;
        };
        let min = [a, b]
            .into_iter()
            .filter_map(|e| reporting.get(e).ok())
            .map(|r| r.min_impulse)
            .fold(f32::INFINITY, f32::min);
        // The manifolds are in `a`'s frame where the step began: a moving `a` is placed
        // there, a static one where it stands.
        let pose = poses.get(a).ok().map(|(x, q, c)| {
            let start = manifolds[range.start].a;
            match solver.bodies.get(start as usize) {
                Some(body) => shape_pose(body.x0, body.q0, c),
                None => shape_pose(x.0, q.0, c),
            }
        });
        let mut report = ContactReport {
            a,
            b,
            normal: Vec3::ZERO,
            points: Vec::new(),
            normal_impulse: 0.0,
            impulse: Vec3::ZERO,
            dt: time.dt(),
        };
        let mut largest = -1.0;
        for k in range {
            let m = &manifolds[k];
            let Some((normals, friction)) = solver.step_totals(k) else {
                continue;
            };
            let Some(found) = state.solved().nth(m.manifold as usize) else {
                continue;
            };
            let inputs = &solver.inputs[m.first as usize..(m.first + m.count) as usize];
            let part = pose.map(|p| part_pose(&p, found.subshape_pos1()));
            // The normal the impulses acted along.
            let normal = Vec3::from(m.n);
            let mut sum = 0.0;
            for (input, &lambda) in inputs.iter().zip(&normals) {
                let Some(p) = found.points.get(input.source as usize) else {
                    continue;
                };
                report.points.push(ReportedPoint {
                    position: part.map_or(Vec3::NAN, |part| part * p.local_p1),
                    normal,
                    separation: p.dist,
                    normal_impulse: lambda,
                });
                sum += lambda;
            }
            report.impulse += Vec3::from(Vec3A::from(normal) * sum + friction);
            report.normal_impulse += sum;
            if sum > largest {
                largest = sum;
                report.normal = normal;
            }
        }
        if !report.points.is_empty() && report.normal_impulse >= min {
            out.write(report);
        }
    }
}
