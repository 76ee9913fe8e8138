//! The random worlds of the fuzz: the things a world holds and what game code does to it
//! mid-run, as proptest strategies, and how each is spawned or applied through the public
//! API. Shared by `harness` (which runs them) and `file_harness` (which saves them).
#![allow(dead_code)]

use bevy_ecs::prelude::*;
use hooke::collision::RestitutionThreshold;
use hooke::integrator::ImplicitEuler;
use hooke::particles::ExternalImpulse;
use hooke::prelude::*;
use hooke::rigid::AngularVelocity;
use hooke::rigid::KinematicTarget;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;
use proptest::prelude::*;

use super::harness::{wild, wild_vec};

/// One thing in a fuzzed world.
#[derive(Debug, Clone)]
pub enum Thing {
    Particle(Vec3, Vec3, f32),
    Ball(Vec3, Vec3, f32),
    Crate(Vec3, Vec3, Vec3),
    Spinner(Vec3, Vec3),
    Kinematic(Vec3, Vec3),
    Rope(Vec3, Vec3, usize, f32, f32),
    Cloth(Vec3, usize, f32),
    Jelly(Vec3, f32, bool),
    /// A static bumpy triangle-mesh floor (8 × 8 m, bumps of the given height) at a height.
    MeshFloor(f32, f32),
}

/// Something game code does in the middle of a run.
#[derive(Debug, Clone)]
pub enum Meddle {
    Despawn(usize),
    SetVelocity(usize, Vec3),
    SetSpin(usize, Vec3),
    Kick(usize, Vec3),
    SetFriction(usize, f32),
    SetRestitution(usize, f32),
    Target(usize, Vec3),
    Settings(f32),
    /// Game code empties a mesh's nodes.
    EmptyNodes(usize),
    /// Game code replaces a mesh's nodes with `n` others (fewer or more).
    ResizeNodes(usize, usize),
    /// Game code inserts a soft body of another mesh (8 cells) on an entity.
    SwapSoftBody(usize),
    /// Game code inserts a spring between two picked entities on a third.
    Respring(usize, usize, usize),
}

fn sane_vec(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn thing() -> impl Strategy<Value = Thing> {
    let at = || sane_vec(4.0).prop_map(|v| v + Vec3::Y * 4.0);
    let speed = || prop_oneof![4 => sane_vec(10.0), 1 => sane_vec(3000.0)];
    prop_oneof![
        (at(), speed(), prop_oneof![0.001f32..10.0, Just(1e6f32)])
            .prop_map(|(x, v, m)| Thing::Particle(x, v, m)),
        (at(), speed(), 0.02f32..1.5).prop_map(|(x, v, r)| Thing::Ball(x, v, r)),
        (
            at(),
            speed(),
            sane_vec(1.0).prop_map(|h| h.abs() + Vec3::splat(0.02))
        )
            .prop_map(|(x, v, h)| Thing::Crate(x, v, h)),
        (at(), sane_vec(200.0)).prop_map(|(x, w)| Thing::Spinner(x, w)),
        (at(), speed()).prop_map(|(x, v)| Thing::Kinematic(x, v)),
        (
            at(),
            sane_vec(3.0),
            2usize..12,
            prop_oneof![1.0f32..1e3, 1e6f32..1e9],
            0.0f32..10.0
        )
            .prop_map(|(x, d, n, k, c)| Thing::Rope(x, d, n, k, c)),
        (at(), 2usize..7, 0.05f32..0.5).prop_map(|(x, n, s)| Thing::Cloth(x, n, s)),
        (at(), prop_oneof![1e3f32..1e6, 1e8f32..1e10], any::<bool>())
            .prop_map(|(x, e, i)| Thing::Jelly(x, e, i)),
        (-1.0f32..2.0, 0.0f32..0.5).prop_map(|(y, b)| Thing::MeshFloor(y, b)),
    ]
}

fn meddle() -> impl Strategy<Value = Meddle> {
    prop_oneof![
        any::<usize>().prop_map(Meddle::Despawn),
        (any::<usize>(), wild_vec()).prop_map(|(i, v)| Meddle::SetVelocity(i, v)),
        (any::<usize>(), wild_vec()).prop_map(|(i, v)| Meddle::SetSpin(i, v)),
        (any::<usize>(), wild_vec()).prop_map(|(i, v)| Meddle::Kick(i, v)),
        (any::<usize>(), wild()).prop_map(|(i, f)| Meddle::SetFriction(i, f)),
        (any::<usize>(), wild()).prop_map(|(i, f)| Meddle::SetRestitution(i, f)),
        (any::<usize>(), wild_vec()).prop_map(|(i, v)| Meddle::Target(i, v)),
        wild().prop_map(Meddle::Settings),
        any::<usize>().prop_map(Meddle::EmptyNodes),
        (any::<usize>(), 0usize..40).prop_map(|(i, n)| Meddle::ResizeNodes(i, n)),
        any::<usize>().prop_map(Meddle::SwapSoftBody),
        (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(i, a, b)| Meddle::Respring(i, a, b)),
    ]
}

/// A fuzzed world: settings, things, and meddling at given steps.
#[derive(Debug, Clone)]
pub struct WorldCase {
    pub integrator: usize,
    pub substeps: u32,
    pub things: Vec<Thing>,
    pub meddles: Vec<(usize, Meddle)>,
    pub steps: usize,
}

pub fn world_case() -> impl Strategy<Value = WorldCase> {
    (
        0usize..5,
        prop_oneof![Just(4u32), 1u32..9],
        prop::collection::vec(thing(), 0..7),
        prop::collection::vec((0usize..60, meddle()), 0..5),
        30usize..70,
    )
        .prop_map(|(integrator, substeps, things, meddles, steps)| WorldCase {
            integrator,
            substeps,
            things,
            meddles,
            steps,
        })
}

pub fn spawn(world: &mut World, thing: &Thing) -> hooke::Result<Vec<Entity>> {
    Ok(match *thing {
        Thing::Particle(x, v, m) => vec![world.spawn(ParticleBundle::new(x, v, m)?).id()],
        Thing::Ball(x, v, r) => {
            let e = scenes::dynamic_ball(world, r, x)?;
            if let Some(mut l) = world.get_mut::<LinearVelocity>(e) {
                l.0 = v.into();
            }
            vec![e]
        }
        Thing::Crate(x, v, h) => {
            let e = scenes::dynamic_box(world, h, x)?;
            if let Some(mut l) = world.get_mut::<LinearVelocity>(e) {
                l.0 = v.into();
            }
            vec![e]
        }
        Thing::Spinner(x, w) => {
            let e = scenes::dynamic_box(world, Vec3::new(0.8, 0.05, 0.3), x)?;
            world.entity_mut(e).insert(AngularVelocity::from(w));
            vec![e]
        }
        Thing::Kinematic(x, v) => vec![
            world
                .spawn((
                    RigidBody::Kinematic,
                    Collider::cuboid(0.5, 0.2, 0.5)?,
                    Position::from(x),
                    LinearVelocity::from(v),
                ))
                .id(),
        ],
        Thing::Rope(x, d, n, k, c) => {
            ChainBuilder::rope(x, x + d + Vec3::X * 0.1, n)
                .stiffness(k)
                .damping(c)
                .spawn(world)?
                .nodes
        }
        Thing::Cloth(x, n, s) => vec![ClothBuilder::new(x, n, n, s).spawn(world)?],
        Thing::MeshFloor(y, bump) => {
            let n = 9u32;
            let vertices: Vec<Vec3> = (0..n * n)
                .map(|k| {
                    let (i, j) = ((k % n) as f32, (k / n) as f32);
                    let h = bump * ((i * 1.7).sin() * (j * 2.3).cos());
                    Vec3::new(i - 4.0, y + h, j - 4.0)
                })
                .collect();
            let indices = (0..(n - 1) * (n - 1))
                .flat_map(|c| {
                    let (i, j) = (c % (n - 1), c / (n - 1));
                    let k = j * n + i;
                    [[k, k + n, k + 1], [k + 1, k + n, k + n + 1]]
                })
                .collect();
            let floor = Collider::trimesh(vertices, indices)?;
            vec![
                world
                    .spawn((RigidBody::Static, floor, Position::default()))
                    .id(),
            ]
        }
        Thing::Jelly(x, young, implicit) => {
            let mesh = TetMesh::cuboid(Vec3::splat(0.4), [1, 1, 1], CellSplit::Six)?;
            let (nodes, body) = SoftBody::build(
                &mesh,
                x,
                Material::new(young, 0.3, 1000.0)?,
                StrainModel::Corotated,
            )?;
            let mut e = world.spawn((nodes, body));
            if implicit {
                e.insert(ImplicitEuler::default());
            }
            vec![e.id()]
        }
    })
}

pub fn apply(world: &mut World, all: &[Entity], m: &Meddle) {
    let pick = |i: usize| all.get(i % all.len().max(1)).copied();
    let Some(e) = (match m {
        Meddle::Settings(_) => all.first().copied().or(Some(Entity::PLACEHOLDER)),
        Meddle::Despawn(i)
        | Meddle::SetVelocity(i, _)
        | Meddle::SetSpin(i, _)
        | Meddle::Kick(i, _)
        | Meddle::SetFriction(i, _)
        | Meddle::SetRestitution(i, _)
        | Meddle::Target(i, _)
        | Meddle::EmptyNodes(i)
        | Meddle::ResizeNodes(i, _)
        | Meddle::SwapSoftBody(i)
        | Meddle::Respring(i, _, _) => pick(*i),
    }) else {
        return;
    };
    match *m {
        Meddle::Despawn(_) => {
            world.try_despawn(e).ok();
        }
        Meddle::SetVelocity(_, v) => {
            if let Some(mut l) = world.get_mut::<LinearVelocity>(e) {
                l.0 = v.into();
            }
        }
        Meddle::SetSpin(_, w) => {
            if let Some(mut l) = world.get_mut::<AngularVelocity>(e) {
                l.0 = w.into();
            }
        }
        Meddle::Kick(_, j) => {
            if let Ok(mut r) = world.get_entity_mut(e) {
                r.insert(ExternalImpulse(j));
            }
        }
        Meddle::SetFriction(_, f) => {
            if let Some(mut c) = world.get_mut::<Friction>(e) {
                c.0 = f;
            }
        }
        Meddle::SetRestitution(_, f) => {
            if let Some(mut c) = world.get_mut::<Restitution>(e) {
                c.0 = f;
            }
        }
        Meddle::Target(_, x) => {
            if world.get::<RigidBody>(e) == Some(&RigidBody::Kinematic)
                && let Ok(mut r) = world.get_entity_mut(e)
            {
                r.insert(KinematicTarget {
                    position: x,
                    rotation: Quat::IDENTITY,
                });
            }
        }
        Meddle::Settings(v) => {
            let mut s = world.resource_mut::<hooke::collision::ContactSettings>();
            s.margin = v;
            if let Ok(mut t) = world.get_entity_mut(e) {
                t.insert(RestitutionThreshold(v));
            }
        }
        Meddle::EmptyNodes(_) => {
            if let Some(mut n) = world.get_mut::<Nodes>(e) {
                *n = Nodes::new();
            }
        }
        Meddle::ResizeNodes(_, count) => {
            if let Some(mut n) = world.get_mut::<Nodes>(e) {
                let mut other = Nodes::with_capacity(count);
                for i in 0..count {
                    let x = n
                        .positions()
                        .get(i)
                        .map_or(Vec3::Y * i as f32 * 0.1, |&x| x.into());
                    let _ = other.push(x, Vec3::ZERO, 0.1);
                }
                *n = other;
            }
        }
        Meddle::SwapSoftBody(_) => {
            let built = TetMesh::cuboid(Vec3::new(0.8, 0.4, 0.4), [2, 2, 2], CellSplit::Six)
                .and_then(|mesh| {
                    SoftBody::build(
                        &mesh,
                        Vec3::Y * 3.0,
                        Material::new(1e5, 0.3, 1000.0)?,
                        StrainModel::Corotated,
                    )
                });
            if let (Ok((_, body)), Ok(mut r)) = (built, world.get_entity_mut(e)) {
                r.insert(body);
            }
        }
        Meddle::Respring(_, a, b) => {
            if let (Some(a), Some(b)) = (pick(a), pick(b))
                && let Ok(spring) = Spring::new(a, b, 1.0, 100.0, 1.0)
                && let Ok(mut r) = world.get_entity_mut(e)
            {
                r.insert(spring);
            }
        }
    }
}
