//! Spring systems.

use bevy_ecs::prelude::*;

use super::{Spring, SpringNetwork, spring_force};
use glam::Vec3A;

use crate::particles::{Force, LinearVelocity, Nodes, Position};
use crate::quarantine::{QuarantineReason, Quarantined};
use crate::rigid::{AngularVelocity, CenterOfMass, Rotation, Torque};
use crate::schedule::{
    ForceSystems, PhysicsSchedule, PhysicsSystems, add_force_systems, add_systems,
};
use crate::{Error, Plugin};

type Live = Without<Quarantined>;

/// Spring forces for [`Spring`] entities and [`SpringNetwork`] meshes. Each system runs only
/// while its kind of spring exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct SpringPlugin;

impl Plugin for SpringPlugin {
    fn build(&self, world: &mut World) {
        add_force_systems(world, || {
            (
                apply_spring_forces.run_if(any_with_component::<Spring>),
                apply_network_forces.run_if(any_with_component::<SpringNetwork>),
            )
                .chain()
                .in_set(ForceSystems::Springs)
        });
        add_systems(
            world,
            PhysicsSchedule,
            remove_broken_springs
                .run_if(any_with_component::<Spring>)
                .in_set(PhysicsSystems::Prepare),
        );
    }
}

/// The spring's view of one endpoint: the world anchor, its velocity and the lever arm.
pub(crate) type Endpoint<'a> = (
    &'a Position,
    &'a LinearVelocity,
    Option<&'a Rotation>,
    Option<&'a AngularVelocity>,
    Option<&'a CenterOfMass>,
);

/// World anchor p, its velocity v + ω × r and the lever arm r = p − x.
#[inline]
pub(crate) fn anchor_state(e: Endpoint, anchor: glam::Vec3) -> (Vec3A, Vec3A, Vec3A) {
    let (x, v, q, w, com) = e;
    let r = match (q, anchor == glam::Vec3::ZERO && com.is_none()) {
        (_, true) => Vec3A::ZERO,
        (Some(q), _) => q.0 * Vec3A::from(anchor - com.map_or(glam::Vec3::ZERO, |c| c.0)),
        (None, _) => Vec3A::from(anchor),
    };
    let vel = match w {
        Some(w) if r != Vec3A::ZERO => v.0 + w.0.cross(r),
        _ => v.0,
    };
    (x.0 + r, vel, r)
}

fn apply_spring_forces(
    springs: Query<&Spring, Live>,
    states: Query<Endpoint, Live>,
    mut forces: Query<(&mut Force, Option<&mut Torque>), Live>,
) {
    for s in &springs {
        // A quarantined or missing endpoint drops out of the query, so NaN can't cross.
        let (Ok(ea), Ok(eb)) = (states.get(s.a), states.get(s.b)) else {
            continue;
        };
        let (pa, va, ra) = anchor_state(ea, s.anchor_a);
        let (pb, vb, rb) = anchor_state(eb, s.anchor_b);
        let f = spring_force(pa, pb, va, vb, s.rest_length, s.stiffness, s.damping);
        if !f.is_finite() {
            continue;
        }
        if let Ok((mut fa, ta)) = forces.get_mut(s.a) {
            fa.bypass_change_detection().0 += f;
            if let Some(mut t) = ta {
                t.bypass_change_detection().0 += ra.cross(f);
            }
        }
        if let Ok((mut fb, tb)) = forces.get_mut(s.b) {
            fb.bypass_change_detection().0 -= f;
            if let Some(mut t) = tb {
                t.bypass_change_detection().0 -= rb.cross(f);
            }
        }
    }
}

fn apply_network_forces(
    mut commands: Commands,
    mut meshes: Query<(Entity, &mut Nodes, &SpringNetwork), Live>,
) {
    for (e, mut nodes, network) in &mut meshes {
        if !network.accumulate(nodes.bypass_change_detection()) {
            let len = nodes.len();
            commands.entity(e).insert(Quarantined {
                reason: QuarantineReason::InvalidInput(Error::IndexOutOfRange {
                    what: "spring network endpoint",
                    index: network.max_index as usize,
                    len,
                }),
            });
        }
    }
}

/// Despawns springs whose endpoint was despawned (or lost its `Position`). Scans only in a
/// step after some `Position` was removed.
fn remove_broken_springs(
    mut commands: Commands,
    mut removed: RemovedComponents<Position>,
    springs: Query<(Entity, &Spring)>,
    bodies: Query<(), With<Position>>,
) {
    if removed.read().next().is_none() {
        return;
    }
    removed.clear();
    for (e, s) in &springs {
        if !(bodies.contains(s.a) && bodies.contains(s.b)) {
            commands.entity(e).despawn();
        }
    }
}
