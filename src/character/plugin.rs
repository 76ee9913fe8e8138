//! The controller's system: ride, move and slide, push.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};

use super::slide::{self, Obstacles};
use super::{CharacterController, CharacterHit, CharacterInput, CharacterState};
use crate::collision::{Collider, Hit, QueryFilter, ShapeContact, SpatialQuery};
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::Quarantined;
use crate::core::schedule::{PhysicsSchedule, PrepareSystems, add_own_systems};
use crate::core::time::PhysicsTime;
use crate::particles::{Gravity, LinearVelocity, Mass, Position};
use crate::rigid::{AngularMomentum, AngularVelocity, CenterOfMass, Inertia, RigidBody, Rotation};

/// Moves every [`CharacterController`] once per step. Its system runs only while one exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct CharacterControllerPlugin;

impl WorldPlugin for CharacterControllerPlugin {
    fn build(&self, world: &mut World) {
        crate::core::quarantine::validate_writes::<CharacterController>(world);
        crate::core::quarantine::validate_writes::<CharacterInput>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            move_characters
                .run_if(any_with_component::<CharacterController>)
                .in_set(PrepareSystems::Characters),
        );
    }
}

/// The world through a character's shape.
struct Sweeper<'a, 'w, 's> {
    query: &'a SpatialQuery<'w, 's>,
    shape: &'a Collider,
    rotation: Quat,
    filter: QueryFilter,
    skin: f32,
}

/// How far inside a hit point the ledge ray starts (m), and twice this above it.
const PROBE: f32 = 0.01;

impl Obstacles for Sweeper<'_, '_, '_> {
    fn cast(&self, from: Vec3, dir: Vec3, max: f32, skip: Option<Entity>) -> Option<Hit> {
        self.query.cast_shape_with_gap(
            self.shape,
            (from, self.rotation),
            dir,
            max,
            self.skin,
            &self.filter,
            &|e| Some(e) != skip,
        )
    }

    fn face_below(&self, entity: Entity, point: Vec3, inward: Vec3, up: Vec3) -> Option<Vec3> {
        let origin = point + inward * PROBE + up * (2.0 * PROBE);
        let hit = self
            .query
            .cast_ray_predicate(origin, -up, 4.0 * PROBE, &self.filter, &|e| e == entity)?;
        (hit.distance > 0.0 && hit.normal.length_squared() > 0.25).then_some(hit.normal)
    }

    fn face_at(&self, entity: Entity, point: Vec3, normal: Vec3) -> Option<Vec3> {
        let hit = self.query.cast_ray_predicate(
            point + normal * PROBE,
            -normal,
            2.0 * PROBE,
            &self.filter,
            &|e| e == entity,
        )?;
        (hit.distance > 0.0 && hit.normal.length_squared() > 0.25).then_some(hit.normal)
    }

    fn overlaps(&self, at: Vec3) -> Vec<ShapeContact> {
        self.query
            .shape_contacts(self.shape, (at, self.rotation), 0.0, &self.filter)
    }

    fn feet_depth(&self, up: Vec3) -> f32 {
        let down = self.rotation.inverse() * -up;
        if let Some(support) = self.shape.shape().as_support_map() {
            return support.local_support_point(down).dot(down);
        }
        let [min, max] = self.shape.local_bounds();
        (0..8)
            .map(|i| {
                let corner = Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                );
                corner.dot(down)
            })
            .fold(f32::MIN, f32::max)
    }
}

type Character<'a> = (
    Entity,
    &'a CharacterController,
    &'a mut CharacterInput,
    &'a mut CharacterState,
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a RigidBody,
);

type Moving<'a> = (
    &'a Position,
    &'a LinearVelocity,
    Option<&'a AngularVelocity>,
);

type Pushed<'a> = (
    &'a Position,
    &'a Rotation,
    Option<&'a Mass>,
    Option<&'a Inertia>,
    &'a mut LinearVelocity,
    Option<&'a mut AngularVelocity>,
    Option<&'a mut AngularMomentum>,
    Option<&'a crate::rigid::LockedAxes>,
);

/// Rides, moves and slides each character, then gives what it walked into its push.
#[allow(clippy::type_complexity)]
fn move_characters(
    time: Res<PhysicsTime>,
    gravity: Option<Res<Gravity>>,
    query: SpatialQuery,
    mut characters: Query<Character, Without<Quarantined>>,
    mut bodies: ParamSet<(
        Query<Moving, Without<Quarantined>>,
        Query<Pushed, Without<Quarantined>>,
    )>,
) {
    let dt = time.dt();
    let g = gravity.map_or(Vec3::ZERO, |g| g.get());
    for (entity, c, mut input, mut state, shape, x, q, com, kind) in &mut characters {
        if *kind != RigidBody::Kinematic {
            continue;
        }
        let up = c.up;
        let offset = q.0 * com.map_or(Vec3::ZERO, |c| c.0);
        let origin = Vec3::from(x.0) - offset;
        let mut filter = c.filter.clone();
        filter.exclude.push(entity);
        let world = Sweeper {
            query: &query,
            shape,
            rotation: q.0,
            filter,
            skin: c.skin,
        };

        // A character spawned, or landed on by a rising platform, finds its ground before
        // it moves, so it rides from the first step.
        if !state.grounded
            && state.vertical_speed <= 0.0
            && let Some((ground, _)) = slide::ground_below(&world, c, origin, c.skin)
        {
            state.grounded = true;
            state.ground = Some(ground);
        }
        let mut vertical = state.vertical_speed;
        if input.jump_speed != 0.0 {
            vertical = input.jump_speed;
            input.jump_speed = 0.0;
        } else if state.grounded && vertical < 0.0 {
            vertical = 0.0;
        }
        let on_ground = state.grounded && vertical <= 0.0;
        if !on_ground {
            vertical += g.dot(up) * c.gravity_scale * dt;
        }
        let mut motion = (input.velocity + up * vertical) * dt;
        if on_ground && let Some(ground) = state.ground {
            // Walk along the ground's plane, not into it.
            let into = motion.dot(ground.normal);
            if into < 0.0 {
                motion -= ground.normal * into;
            }
        }

        // The move is made in the frame of the ground (its pose at the step's start, which
        // it keeps relative to the character), then the ride is added.
        let mut moved = slide::move_and_slide(&world, c, origin, motion, on_ground, dt);
        if let Some(ground) = state.ground.filter(|_| state.grounded)
            && let Ok((gx, gv, gw)) = bodies.p0().get(ground.entity)
        {
            let arm = ground.point - Vec3::from(gx.0);
            let w = gw.map_or(Vec3::ZERO, |w| Vec3::from(w.0));
            let ride = (Vec3::from(gv.0) + w.cross(arm)) * dt;
            let length = ride.length();
            if length > 1e-6 {
                // Casts ignore the ground, which moves with the character.
                let dir = ride / length;
                let free = world
                    .cast(moved.position, dir, length, Some(ground.entity))
                    .map_or(length, |h| h.distance.min(length));
                moved.position += dir * free;
            }
        }
        let landed = moved.ground.is_some();
        let ceiling = moved.contacts.iter().any(|k| k.hit.normal.dot(up) < -0.5);
        if (landed && vertical < 0.0) || (ceiling && vertical > 0.0) {
            vertical = 0.0;
        }

        let mut hits = Vec::with_capacity(moved.contacts.len());
        for contact in &moved.contacts {
            let impulse = if c.is_walkable(contact.hit.normal) {
                Vec3::ZERO
            } else {
                push(&mut bodies.p1(), contact, c.max_push_force * dt)
            };
            hits.push(CharacterHit {
                entity: contact.hit.entity,
                point: contact.hit.point,
                normal: contact.hit.normal,
                impulse,
            });
        }

        let translation = moved.position - origin;
        if let Ok((_, _, _, _, mut v, w, ..)) = bodies.p1().get_mut(entity) {
            v.0 = Vec3A::from(translation / dt);
            if let Some(mut w) = w.filter(|w| w.0 != Vec3A::ZERO) {
                w.0 = Vec3A::ZERO;
            }
        }
        *state = CharacterState {
            grounded: landed,
            ground: moved.ground,
            vertical_speed: vertical,
            translation,
            stepped: moved.stepped,
            hits,
        };
    }
}

/// Pushes a dynamic body the character ran into: the impulse that brings the body's
/// speed at the contact, along the push, up to what the character wanted, at most
/// `max_impulse` (N·s).
fn push(
    bodies: &mut Query<Pushed, Without<Quarantined>>,
    contact: &slide::Contact,
    max_impulse: f32,
) -> Vec3 {
    let Ok((x, q, mass, inertia, mut v, w, l, locks)) = bodies.get_mut(contact.hit.entity) else {
        return Vec3::ZERO;
    };
    let inverse = mass.map_or(0.0, Mass::inverse);
    if inverse == 0.0 {
        return Vec3::ZERO;
    }
    let inverse_mass = Vec3::from(crate::rigid::LockedAxes::inverse_mass_of(locks, inverse));
    let d = -contact.hit.normal;
    let wanted = contact.wanted.dot(d);
    if wanted <= 0.0 {
        return Vec3::ZERO;
    }
    let arm = contact.hit.point - Vec3::from(x.0);
    let spin = w.as_ref().map_or(Vec3::ZERO, |w| Vec3::from(w.0));
    let now = (Vec3::from(v.0) + spin.cross(arm)).dot(d);
    let shortfall = wanted - now;
    if shortfall <= 0.0 {
        return Vec3::ZERO;
    }
    let inverse_tensor = inertia.map(|i| i.world_inverse_tensor(q.0));
    let turn = arm.cross(d);
    let angular = inverse_tensor.map_or(0.0, |t| turn.dot(t * turn));
    let linear = d.dot(inverse_mass * d);
    if linear + angular <= 0.0 {
        return Vec3::ZERO;
    }
    let j = (shortfall / (linear + angular)).min(max_impulse);
    let impulse = d * j;
    v.0 += Vec3A::from(impulse * inverse_mass);
    if let (Some(inertia), Some(mut w), Some(mut l)) = (inertia, w, l) {
        l.0 += Vec3A::from(arm.cross(impulse));
        w.0 = inertia.angular_velocity(q.0, l.0);
    }
    impulse
}
