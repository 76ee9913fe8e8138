//! The headless runner: build, then per step: step the world, apply that step's actions,
//! check that step's expectations, record traces.

use std::collections::HashMap;
use std::time::Instant;

use bevy_ecs::message::{MessageCursor, Messages};
use bevy_ecs::prelude::*;
use glam::Vec3;

use super::check::{Kin, Moment, Probe, Track, evaluate, finish};
use super::format::{Action, PluginName};
use super::report::{Outcome, Report, Trace};
use super::select::{Names, group, members};
use super::{Scenario, ScenarioError, ScenarioErrorKind, Selector, spawn};
use crate::collision::Friction;
use crate::collision::Restitution;
use crate::core::error::{Error, finite_vec};
use crate::core::quarantine::BodyQuarantined;
use crate::core::time::PhysicsTime;
use crate::particles::ExternalForce;
use crate::particles::ExternalImpulse;
use crate::particles::Gravity;
use crate::particles::LinearVelocity;
use crate::particles::Mass;
use crate::particles::Nodes;
use crate::particles::Position;
use crate::plugins::PhysicsPlugins;
use crate::plugins::PhysicsWorldExt;
use crate::rigid::AngularVelocity;
use crate::rigid::ExternalTorque;
use crate::rigid::RigidBody;
use crate::sleep::SleepSettings;

/// How to run: traces and progress.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Trace every named entity when the file names none in `trace`.
    pub trace_all: bool,
    /// Called with (step, steps) every 16 steps and at the end.
    pub progress: Option<&'a mut dyn FnMut(u64, u64)>,
}

fn add_plugin(world: &mut World, p: PluginName) {
    match p {
        PluginName::Gravity => world.add_physics(crate::particles::GravityPlugin),
        PluginName::Damping => world.add_physics(crate::particles::DampingPlugin),
        PluginName::VelocityField => world.add_physics(crate::particles::VelocityFieldPlugin),
        PluginName::Springs => world.add_physics(crate::springs::SpringPlugin),
        PluginName::RigidBody => world.add_physics(crate::rigid::RigidBodyPlugin),
        PluginName::Collision => world.add_physics(crate::collision::CollisionPlugin),
        PluginName::Sleep => world.add_physics(crate::sleep::SleepPlugin),
        PluginName::Joints => world.add_physics(crate::joints::JointPlugin),
        PluginName::SoftBody => world.add_physics(crate::soft::SoftBodyPlugin),
        PluginName::Cloth => world.add_physics(crate::cloth::ClothPlugin),
    };
}

pub(super) fn build(s: &Scenario) -> Result<(World, Names), ScenarioError> {
    let build_err = |line: usize, e: Error| s.error(line, ScenarioErrorKind::Build(e));
    let mut world = World::new();
    let has = |p: PluginName| s.settings.plugins.as_ref().is_none_or(|l| l.contains(&p));
    match &s.settings.plugins {
        None => {
            world.add_physics(PhysicsPlugins);
        }
        Some(list) => list.iter().for_each(|p| add_plugin(&mut world, *p)),
    }
    let time = PhysicsTime::new(s.settings.dt, s.settings.substeps).map_err(|e| build_err(1, e))?;
    world.insert_resource(time);
    world.insert_resource(s.settings.integrator);
    world.insert_resource(s.settings.advection);
    // Without the gravity plugin nothing pulls, and the energy books must agree.
    let g = if has(PluginName::Gravity) {
        s.settings.gravity
    } else {
        Vec3::ZERO
    };
    world.insert_resource(Gravity::new(g).map_err(|e| build_err(1, e))?);
    if let Some(mut sleep) = world.get_resource_mut::<SleepSettings>() {
        sleep.enabled = s.settings.sleep;
    }
    let mut names = Names::new();
    for e in &s.entities {
        let spawned = spawn::spawn(&mut world, &e.item.spawn, |n| single(&names, n))
            .map_err(|err| build_err(e.line, err))?;
        names.insert(e.item.name.clone(), spawned);
    }
    world.flush();
    Ok((world, names))
}

fn single(names: &Names, text: &str) -> Option<Entity> {
    match group(names, text) {
        [e] => Some(*e),
        _ => None,
    }
}

/// What actions changed that later actions undo.
#[derive(Default)]
struct Undo {
    pinned: HashMap<Entity, Pinned>,
    gravity_off: Option<Vec3>,
}

enum Pinned {
    Mass(Mass),
    Kind(RigidBody),
}

pub(super) fn run(s: &Scenario, options: &mut RunOptions) -> Result<Report, ScenarioError> {
    let start = Instant::now();
    let (mut world, mut names) = build(s)?;
    let dt = f64::from(s.settings.dt);
    let g = f64::from(s.settings.gravity.length());
    let mut tracks: Vec<Track> = s.expectations.iter().map(|_| Track::default()).collect();
    let mut undo = Undo::default();
    let mut probe = Probe::new(&mut world);
    let traced: Vec<Selector> = if s.trace.is_empty() && options.trace_all {
        let mut all: Vec<_> = s
            .entities
            .iter()
            .map(|e| &e.item.name)
            .filter(|n| {
                names
                    .get(*n)
                    .is_some_and(|v| v.iter().any(|e| probe.get(&world, *e).is_some()))
            })
            .map(|n| Selector {
                name: n.clone(),
                index: None,
                text: n.clone(),
            })
            .collect();
        all.sort_by(|a, b| a.name.cmp(&b.name));
        all
    } else {
        s.trace.clone()
    };
    let rows = (traced.len() as u64).saturating_mul(s.steps.saturating_add(1));
    if rows > super::MAX_TRACE_ROWS {
        return Err(s.error(
            0,
            ScenarioErrorKind::BadValue(format!(
                "tracing every name ({}) over {} steps is {rows} rows, more than {}",
                traced.len(),
                s.steps + 1,
                super::MAX_TRACE_ROWS
            )),
        ));
    }
    let mut traces: Vec<Trace> = traced
        .iter()
        .map(|t| Trace {
            name: t.text.clone(),
            rows: Vec::with_capacity(s.steps as usize + 1),
        })
        .collect();
    let mut cursor: MessageCursor<BodyQuarantined> = world
        .get_resource::<Messages<BodyQuarantined>>()
        .map(Messages::get_cursor)
        .unwrap_or_default();
    let mut quarantined_now: Vec<(Entity, String)> = Vec::new();
    let mut next_action = 0;
    for step in 0..=s.steps {
        quarantined_now.clear();
        if step > 0 {
            world.step_physics();
            if let Some(m) = world.get_resource::<Messages<BodyQuarantined>>() {
                quarantined_now.extend(cursor.read(m).map(|q| (q.entity, q.reason.to_string())));
            }
        }
        while let Some(a) = s.timeline.get(next_action).filter(|a| a.step == step) {
            act(&mut world, &mut names, &a.item, &mut undo)
                .map_err(|e| s.error(a.line, ScenarioErrorKind::Build(e)))?;
            next_action += 1;
        }
        probe.refresh(&world);
        let t = step as f64 * dt;
        let moment = Moment {
            world: &world,
            probe: &probe,
            names: &names,
            t,
            g,
            quarantined: &quarantined_now,
        };
        for (x, track) in s.expectations.iter().zip(&mut tracks) {
            if (x.window.first..=x.window.last).contains(&step) {
                evaluate(&moment, x, track);
            }
        }
        for (sel, trace) in traced.iter().zip(&mut traces) {
            if let Some(k) = mean_kinematics(&world, &probe, members(&names, sel)) {
                trace
                    .rows
                    .push([t, k.x.x, k.x.y, k.x.z, k.v.x, k.v.y, k.v.z, k.v.length()]);
            }
        }
        if let Some(p) = options.progress.as_mut()
            && (step % 16 == 0 || step == s.steps)
        {
            p(step, s.steps);
        }
    }
    let mut outcomes: Vec<Outcome> = s
        .expectations
        .iter()
        .zip(tracks)
        .map(|(x, track)| finish(x, track, dt))
        .collect();
    let hash = crate::snapshot::Snapshot::capture(&world)
        .map(|snap| snap.digest())
        .map_err(|e| s.error(s.hash_line, ScenarioErrorKind::Snapshot(e)))?;
    if let Some(expected) = s.hash {
        outcomes.push(Outcome {
            line: s.hash_line,
            expected: format!("final state hash {expected:016x}"),
            passed: expected == hash,
            time: s.steps as f64 * dt,
            measured: format!("{hash:016x}"),
        });
    }
    Ok(Report {
        name: s.name.clone(),
        file: s.file.clone(),
        steps: s.steps,
        seconds: s.steps as f64 * dt,
        outcomes,
        hash,
        expected_hash: s.hash,
        traces,
        wall: start.elapsed(),
    })
}

/// The mean position and velocity of a group (one entity: its own).
fn mean_kinematics(world: &World, probe: &Probe, group: &[Entity]) -> Option<Kin> {
    let mut sum = Kin::default();
    let mut n = 0.0;
    for e in group {
        if let Some(k) = probe.get(world, *e) {
            sum.x += k.x;
            sum.v += k.v;
            sum.w += k.w;
            n += 1.0;
        }
    }
    (n > 0.0).then(|| Kin {
        x: sum.x / n,
        v: sum.v / n,
        w: sum.w / n,
    })
}

fn act(
    world: &mut World,
    names: &mut Names,
    action: &Action,
    undo: &mut Undo,
) -> Result<(), Error> {
    let group = |names: &Names, text: &str| group(names, text).to_vec();
    match action {
        Action::Impulse { entity, impulse } => {
            let j = finite_vec("impulse", *impulse)?;
            for e in group(names, entity) {
                if let Some(mut nodes) = world.get_mut::<Nodes>(e) {
                    let total: f32 = (0..nodes.len())
                        .filter_map(|i| nodes.mass(i))
                        .filter(|m| m.is_finite())
                        .sum();
                    if total > 0.0 {
                        let dv = j / total;
                        for i in 0..nodes.len() {
                            if nodes.mass(i).is_some_and(f32::is_finite) {
                                let v = Vec3::from(nodes.velocities()[i]) + dv;
                                nodes.set_velocity(i, v)?;
                            }
                        }
                    }
                } else {
                    // Impulses given in one moment add up, as game code's would.
                    let before = world
                        .get::<ExternalImpulse>(e)
                        .map_or(Vec3::ZERO, ExternalImpulse::get);
                    world
                        .entity_mut(e)
                        .insert(ExternalImpulse::try_new(before + j)?);
                }
            }
        }
        Action::Force { entity, force } => {
            let f = ExternalForce::try_new(*force)?;
            for e in group(names, entity) {
                world.entity_mut(e).insert(f);
            }
        }
        Action::Torque { entity, torque } => {
            let tau = ExternalTorque::from(finite_vec("torque", *torque)?);
            for e in group(names, entity) {
                world.entity_mut(e).insert(tau);
            }
        }
        Action::SetMotor {
            joint,
            target_velocity,
            max,
        } => {
            for e in group(names, joint) {
                spawn::set_motor(world, e, *target_velocity, *max)?;
            }
        }
        Action::SetServo {
            joint,
            target,
            stiffness,
            damping,
            max,
        } => {
            for e in group(names, joint) {
                spawn::set_servo(world, e, *target, (*stiffness, *damping, *max))?;
            }
        }
        Action::SetVelocity { entity, velocity } => {
            let v = finite_vec("velocity", *velocity)?;
            for e in group(names, entity) {
                if let Some(mut nodes) = world.get_mut::<Nodes>(e) {
                    for i in 0..nodes.len() {
                        if nodes.mass(i).is_some_and(f32::is_finite) {
                            nodes.set_velocity(i, v)?;
                        }
                    }
                } else {
                    world.entity_mut(e).insert(LinearVelocity::from(v));
                }
            }
        }
        Action::SetAngularVelocity {
            entity,
            angular_velocity,
        } => {
            let w = AngularVelocity::from(finite_vec("angular velocity", *angular_velocity)?);
            for e in group(names, entity) {
                world.entity_mut(e).insert(w);
            }
        }
        Action::Teleport { entity, to } => {
            let to = finite_vec("teleport target", *to)?;
            for e in group(names, entity) {
                if let Some(mut nodes) = world.get_mut::<Nodes>(e) {
                    let n = nodes.len().max(1) as f32;
                    let mean: Vec3 = nodes
                        .positions()
                        .iter()
                        .map(|x| Vec3::from(*x))
                        .sum::<Vec3>()
                        / n;
                    for i in 0..nodes.len() {
                        let x = Vec3::from(nodes.positions()[i]) + (to - mean);
                        nodes.set_position(i, x)?;
                    }
                } else {
                    world.entity_mut(e).insert(Position::from(to));
                }
            }
        }
        Action::Spawn { name, spawn } => {
            let spawned = spawn::spawn(world, spawn, |n| single(names, n))?;
            world.flush();
            names.insert(name.clone(), spawned);
        }
        Action::Despawn { entity } => {
            for e in group(names, entity) {
                world.despawn(e);
            }
            if let (name, Ok(None)) = super::split_selector(entity) {
                names.remove(name);
            }
        }
        Action::Pin { entity } => {
            for e in group(names, entity) {
                if let Some(kind) = world.get::<RigidBody>(e).copied() {
                    undo.pinned.entry(e).or_insert(Pinned::Kind(kind));
                    world.entity_mut(e).insert(RigidBody::Static);
                } else if let Some(m) = world.get::<Mass>(e).copied() {
                    undo.pinned.entry(e).or_insert(Pinned::Mass(m));
                    world
                        .entity_mut(e)
                        .insert((Mass::PINNED, LinearVelocity::default()));
                } else {
                    return Err(Error::MissingEntity(e));
                }
            }
        }
        Action::Release { entity } => {
            for e in group(names, entity) {
                match undo.pinned.remove(&e) {
                    Some(Pinned::Kind(k)) => {
                        world.entity_mut(e).insert(k);
                    }
                    Some(Pinned::Mass(m)) => {
                        world.entity_mut(e).insert(m);
                    }
                    None => {}
                }
            }
        }
        Action::SetGravity { gravity } => {
            let g = Gravity::new(*gravity)?;
            if undo.gravity_off.is_some() {
                undo.gravity_off = Some(g.get());
            } else {
                world.insert_resource(g);
            }
        }
        Action::SetFriction { entity, value } => {
            let mu = Friction(spawn::material("friction", *value)?);
            for e in group(names, entity) {
                world.entity_mut(e).insert(mu);
            }
        }
        Action::SetRestitution { entity, value } => {
            let r = Restitution(spawn::material("restitution", *value)?);
            for e in group(names, entity) {
                world.entity_mut(e).insert(r);
            }
        }
        Action::Enable(p) | Action::Disable(p) => {
            let on = matches!(action, Action::Enable(_));
            match p {
                PluginName::Gravity => {
                    if on {
                        if let Some(g) = undo.gravity_off.take() {
                            world.insert_resource(Gravity::new(g)?);
                        }
                    } else if undo.gravity_off.is_none() {
                        let g = world
                            .get_resource::<Gravity>()
                            .map_or(Vec3::ZERO, Gravity::get);
                        undo.gravity_off = Some(g);
                        world.insert_resource(Gravity::new(Vec3::ZERO)?);
                    }
                }
                PluginName::Sleep => {
                    if let Some(mut s) = world.get_resource_mut::<SleepSettings>() {
                        s.enabled = on;
                    }
                    if !on {
                        let sleepers: Vec<Entity> = world
                            .query_filtered::<Entity, With<crate::core::rest::Sleeping>>()
                            .iter(world)
                            .collect();
                        for e in sleepers {
                            world.entity_mut(e).remove::<crate::core::rest::Sleeping>();
                        }
                    }
                }
                // The loader refuses the rest.
                _ => {}
            }
        }
    }
    world.flush();
    Ok(())
}
