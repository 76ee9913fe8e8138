//! Cloth systems: wind on triangles, strain limiting, node contacts, vertex normals.

use bevy_ecs::prelude::*;
use glam::Vec3A;

use super::Cloth;
use crate::core::error::Error;
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::{QuarantineReason, Quarantined};
use crate::core::rest::Simulated;
use crate::core::schedule::{
    FinishSystems, ForceSystems, PhysicsSchedule, RelaxSystems, SubstepSchedule,
    add_own_force_systems, add_own_systems,
};
use crate::core::time::PhysicsTime;
use crate::particles::{Nodes, VelocityField};
use crate::springs::SpringNetwork;

/// Gauss–Seidel passes of strain limiting per substep at most; they stop once no spring is
/// more than 0.1 % past its limit. A long chain of over-stretched springs needs about as
/// many passes as it has links squared over a few (a 12 × 12 cloth whose springs alone would
/// stretch 53-fold needs about 150); a cloth near its limit, one or two.
const LIMIT_PASSES: usize = 200;

/// Wind, strain limiting, collisions and normals for [`Cloth`] meshes. Each system runs only
/// while a cloth exists (the wind only while one has drag, the contacts only while there are
/// colliders).
#[derive(Debug, Default, Clone, Copy)]
pub struct ClothPlugin;

impl WorldPlugin for ClothPlugin {
    fn build(&self, world: &mut World) {
        crate::core::whole_step::block_on::<Cloth>(world);
        add_own_force_systems(world, || {
            apply_wind
                .run_if(any_with_component::<Cloth>)
                .in_set(ForceSystems::Damping)
        });
        add_own_systems(
            world,
            SubstepSchedule,
            (
                limit_strain.run_if(any_with_component::<Cloth>),
                crate::collision::nodes::collide_nodes::<Cloth>
                    .run_if(any_with_component::<Cloth>)
                    .run_if(any_with_component::<crate::collision::Collider>),
            )
                .chain()
                .in_set(RelaxSystems::Cloth),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            update_normals
                .run_if(any_with_component::<Cloth>)
                .in_set(FinishSystems::Writeback),
        );
    }
}

/// f = −c_d A ((v − u)·n̂) n̂ per triangle, a third to each corner.
fn apply_wind(
    mut commands: Commands,
    time: Res<PhysicsTime>,
    fields: Query<&VelocityField>,
    mut cloths: Query<(Entity, &mut Nodes, &Cloth), Simulated>,
) {
    let t = time.elapsed() as f32;
    for (e, mut nodes, cloth) in &mut cloths {
        if cloth.drag == 0.0 {
            continue;
        }
        let n = nodes.bypass_change_detection();
        if !cloth.fits(n) {
            quarantine_misfit(&mut commands, e, n.len());
            continue;
        }
        let Nodes { x, v, f, .. } = n;
        for &[a, b, c] in &cloth.triangles {
            let (a, b, c) = (a as usize, b as usize, c as usize);
            let twice = (x[b] - x[a]).cross(x[c] - x[a]);
            let len = twice.length();
            // NaN fails the comparison too: such a triangle gets no wind.
            if len.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
                continue;
            }
            let normal = twice / len;
            let centroid = (x[a] + x[b] + x[c]) / 3.0;
            let air: Vec3A = fields.iter().map(|u| u.velocity(centroid, t)).sum();
            let rel = (v[a] + v[b] + v[c]) / 3.0 - air;
            // A = len / 2, shared by three corners.
            let share = (-cloth.drag * len / 6.0 * rel.dot(normal)) * normal;
            if share.is_finite() {
                f[a] += share;
                f[b] += share;
                f[c] += share;
            }
        }
    }
}

fn quarantine_misfit(commands: &mut Commands, e: Entity, len: usize) {
    commands.entity(e).insert(Quarantined {
        reason: QuarantineReason::InvalidInput(Error::IndexOutOfRange {
            what: "cloth triangle corner",
            index: len,
            len,
        }),
    });
}

/// Shortens structural springs stretched past (1 + s_max) r, removing their ends' relative
/// velocity along them (see the module docs).
fn limit_strain(mut cloths: Query<(&mut Nodes, &SpringNetwork, &Cloth), Simulated>) {
    for (mut nodes, net, cloth) in &mut cloths {
        let Some(limit) = cloth.strain_limit else {
            continue;
        };
        let n = nodes.bypass_change_detection();
        // A network swapped for a smaller one would index past its springs: no limiting.
        if !(net.fits(n) && cloth.fits_springs(net)) {
            continue;
        }
        let Nodes { x, v, inv_mass, .. } = n;
        for _ in 0..LIMIT_PASSES {
            let mut worst = 0.0f32;
            for &s in &cloth.structural {
                let s = s as usize;
                let [a, b] = net.ends[s];
                let (a, b) = (a as usize, b as usize);
                let (wa, wb) = (inv_mass[a], inv_mass[b]);
                let w = wa + wb;
                let longest = (1.0 + limit) * net.rest[s];
                let d = x[b] - x[a];
                let l = d.length();
                if l.partial_cmp(&longest) != Some(core::cmp::Ordering::Greater) || w == 0.0 {
                    continue;
                }
                worst = worst.max(l / longest - 1.0);
                let dir = d / l;
                let excess = l - longest;
                x[a] += (wa / w * excess) * dir;
                x[b] -= (wb / w * excess) * dir;
                // Only a separating relative velocity is removed; the ends keep their mean.
                let separating = (v[b] - v[a]).dot(dir);
                if separating > 0.0 {
                    v[a] += (wa / w * separating) * dir;
                    v[b] -= (wb / w * separating) * dir;
                }
            }
            if worst < 1e-3 {
                break;
            }
        }
    }
}

/// Area-weighted unit vertex normals, for rendering.
fn update_normals(mut cloths: Query<(&Nodes, &mut Cloth), Without<Quarantined>>) {
    for (nodes, mut cloth) in &mut cloths {
        let cloth = cloth.bypass_change_detection();
        if !cloth.fits(nodes) {
            continue;
        }
        let x = nodes.positions();
        cloth.normals.iter_mut().for_each(|n| *n = Vec3A::ZERO);
        for &[a, b, c] in &cloth.triangles {
            let (a, b, c) = (a as usize, b as usize, c as usize);
            let twice = (x[b] - x[a]).cross(x[c] - x[a]);
            for i in [a, b, c] {
                cloth.normals[i] += twice;
            }
        }
        for n in &mut cloth.normals {
            *n = n.normalize_or_zero();
        }
    }
}
