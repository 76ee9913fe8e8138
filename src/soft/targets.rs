//! Kinematic node targets: nodes of a mesh driven to positions the game sets (a grab, a
//! hand, a moving anchor).

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Vec3, Vec3A};

use crate::core::error::{Error, Result, finite_vec};
use crate::core::time::PhysicsTime;
use crate::particles::Nodes;

/// Drives some nodes of the [`Nodes`] on the same entity to target positions (m): each step a
/// targeted node is pinned (infinite mass: the mesh cannot push it) and given the velocity
/// (target − x)/dt, so it arrives at the end of the step under any integrator, explicit or
/// implicit. Removing the component, or a node's target, gives the node its mass back.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_remove = release_all)]
pub struct NodeTargets {
    targets: Vec<(u32, Vec3)>,
    /// The masses of the nodes held, to give back.
    held: Vec<(u32, f32)>,
}

impl NodeTargets {
    /// Whether every node index is within a mesh of `nodes` nodes.
    pub(crate) fn fits(&self, nodes: usize) -> bool {
        self.targets
            .iter()
            .map(|t| t.0)
            .chain(self.held.iter().map(|h| h.0))
            .all(|i| (i as usize) < nodes)
    }

    /// Targets for `(node, position)` pairs.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a bad position; [`Error::IndexOutOfRange`] for an index past
    /// `u32` (indices past the mesh's nodes are reported when the step meets them).
    pub fn new(pairs: impl IntoIterator<Item = (usize, Vec3)>) -> Result<Self> {
        let mut t = Self::default();
        for (i, p) in pairs {
            t.set(i, p)?;
        }
        Ok(t)
    }

    /// Sets (or moves) node `i`'s target.
    ///
    /// # Errors
    /// As [`NodeTargets::new`].
    pub fn set(&mut self, i: usize, target: Vec3) -> Result<()> {
        let target = finite_vec("node target", target)?;
        let i = u32::try_from(i).map_err(|_| Error::IndexOutOfRange {
            what: "node target",
            index: i,
            len: u32::MAX as usize,
        })?;
        match self.targets.iter_mut().find(|t| t.0 == i) {
            Some(t) => t.1 = target,
            None => self.targets.push((i, target)),
        }
        Ok(())
    }

    /// Stops driving node `i` (its mass comes back at the next step).
    pub fn release(&mut self, i: usize) {
        self.targets.retain(|t| t.0 as usize != i);
    }

    /// The targets, as (node, position).
    #[must_use]
    pub fn targets(&self) -> &[(u32, Vec3)] {
        &self.targets
    }
}

/// Before each step: hold and steer the targeted nodes, give released ones their mass back.
pub(crate) fn drive_node_targets(
    time: Res<PhysicsTime>,
    mut meshes: Query<(&mut Nodes, &mut NodeTargets)>,
) {
    let dt = time.dt();
    for (mut nodes, mut t) in &mut meshes {
        let t = &mut *t;
        let len = nodes.len();
        // Released: mass back.
        let targets = &t.targets;
        t.held.retain(|&(i, m)| {
            let keep = targets.iter().any(|x| x.0 == i);
            if !keep {
                let _ = nodes.set_mass(i as usize, m);
            }
            keep
        });
        for &(i, target) in &t.targets {
            let i = i as usize;
            if i >= len {
                continue;
            }
            if !t.held.iter().any(|h| h.0 as usize == i) {
                let m = nodes.mass(i).unwrap_or(f32::INFINITY);
                if m.is_finite() {
                    t.held.push((i as u32, m));
                }
                let _ = nodes.pin(i);
            }
            let x = nodes.positions()[i];
            // Steering a held node is part of the step, not a change from outside it (which
            // would restart BDF2's history); pinning and releasing above are.
            let _ = nodes
                .bypass_change_detection()
                .set_velocity(i, Vec3::from((Vec3A::from(target) - x) / dt));
        }
    }
}

fn release_all(mut world: DeferredWorld, ctx: HookContext) {
    let Some(held) = world.get::<NodeTargets>(ctx.entity).map(|t| t.held.clone()) else {
        return;
    };
    if let Some(mut nodes) = world.get_mut::<Nodes>(ctx.entity) {
        for (i, m) in held {
            let _ = nodes.set_mass(i as usize, m);
        }
    }
}
