//! Spring systems.

use bevy_ecs::prelude::*;

use super::{Spring, SpringNetwork, spring_force};
use crate::particles::{Force, LinearVelocity, Nodes, Position};
use crate::quarantine::{QuarantineReason, Quarantined};
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

fn apply_spring_forces(
    springs: Query<&Spring, Live>,
    states: Query<(&Position, &LinearVelocity), Live>,
    mut forces: Query<&mut Force, Live>,
) {
    for s in &springs {
        // A quarantined or missing endpoint drops out of the query, so NaN can't cross.
        let (Ok((xa, va)), Ok((xb, vb))) = (states.get(s.a), states.get(s.b)) else {
            continue;
        };
        let f = spring_force(
            xa.0,
            xb.0,
            va.0,
            vb.0,
            s.rest_length,
            s.stiffness,
            s.damping,
        );
        if !f.is_finite() {
            continue;
        }
        if let Ok(mut fa) = forces.get_mut(s.a) {
            fa.bypass_change_detection().0 += f;
        }
        if let Ok(mut fb) = forces.get_mut(s.b) {
            fb.bypass_change_detection().0 -= f;
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
