//! Building a file's entries through hooke's public constructors and scene builders, the
//! way game code spawns them.

use bevy_ecs::prelude::*;
use glam::{EulerRot, Quat};

use super::format::{BodyKind, Field, Shape, Spawn};
use crate::cloth::ClothBuilder;
use crate::collision::Collider;
use crate::collision::ColliderDensity;
use crate::collision::Friction;
use crate::collision::Restitution;
use crate::collision::RestitutionThreshold;
use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::Validate;
use crate::particles::LinearDamping;
use crate::particles::LinearVelocity;
use crate::particles::Mass;
use crate::particles::ParticleBundle;
use crate::particles::Position;
use crate::particles::Tracer;
use crate::particles::VelocityField;
use crate::rigid::AngularVelocity;
use crate::rigid::RigidBody;
use crate::rigid::Rotation;
use crate::springs::ChainBuilder;
use crate::springs::Spring;
use crate::tools::scenes;

/// Spawns `spawn`; `lookup` resolves the names a spring's ends use to one entity.
pub(super) fn spawn(
    world: &mut World,
    spawn: &Spawn,
    lookup: impl Fn(&str) -> Option<Entity>,
) -> Result<Vec<Entity>> {
    Ok(match spawn {
        Spawn::Ground => vec![scenes::ground(world)?],
        Spawn::Body {
            shape,
            at,
            rotation,
            velocity,
            angular_velocity,
            kind,
            density,
            mass,
            friction,
            restitution,
            restitution_threshold,
        } => {
            let collider = match *shape {
                Shape::Cuboid(x, y, z) => Collider::cuboid(x, y, z)?,
                Shape::Ball(r) => Collider::ball(r)?,
                Shape::Capsule(h, r) => Collider::capsule_y(h, r)?,
                Shape::Cylinder(h, r) => Collider::cylinder(h, r)?,
            };
            let r = finite_vec("rotation (degrees)", *rotation)?;
            let q = Quat::from_euler(
                EulerRot::XYZ,
                r.x.to_radians(),
                r.y.to_radians(),
                r.z.to_radians(),
            );
            let kind = match kind {
                BodyKind::Dynamic => RigidBody::Dynamic,
                BodyKind::Kinematic => RigidBody::Kinematic,
                BodyKind::Static => RigidBody::Static,
            };
            let mut e = world.spawn((
                kind,
                collider,
                Position::try_new(*at)?,
                Rotation::try_new(q)?,
            ));
            if let Some(d) = density {
                e.insert(ColliderDensity::try_new(*d)?);
            }
            if let Some(m) = mass {
                e.insert(Mass::new(*m)?);
            }
            if let Some(mu) = friction {
                e.insert(checked(Friction(*mu))?);
            }
            if let Some(r) = restitution {
                e.insert(checked(Restitution(*r))?);
            }
            if let Some(v) = restitution_threshold {
                e.insert(checked(RestitutionThreshold(*v))?);
            }
            if kind != RigidBody::Static {
                e.insert((
                    LinearVelocity::try_new(*velocity)?,
                    AngularVelocity::from(finite_vec("angular velocity", *angular_velocity)?),
                ));
            }
            vec![e.id()]
        }
        Spawn::Particle {
            at,
            velocity,
            mass,
            pinned,
            damping,
        } => {
            let bundle = if *pinned {
                ParticleBundle::pinned(*at)?
            } else {
                ParticleBundle::new(*at, *velocity, *mass)?
            };
            let mut e = world.spawn(bundle);
            if let Some(c) = damping {
                e.insert(checked(LinearDamping(*c))?);
            }
            vec![e.id()]
        }
        Spawn::Tracer { at } => vec![world.spawn((Position::try_new(*at)?, Tracer)).id()],
        Spawn::Field(field) => {
            let f = match *field {
                Field::Uniform { velocity } => VelocityField::uniform(velocity)?,
                Field::Vortex { center, axis, rate } => VelocityField::vortex(center, axis, rate)?,
            };
            vec![world.spawn(f).id()]
        }
        Spawn::Spring {
            a,
            b,
            stiffness,
            damping,
            rest,
            anchor_a,
            anchor_b,
        } => {
            // The loader checked both names are one live entity each.
            let end = |name: &String| lookup(name).ok_or(Error::MissingEntity(Entity::PLACEHOLDER));
            let (ea, eb) = (end(a)?, end(b)?);
            let at = |e: Entity| world.get::<Position>(e).map(Position::get);
            let (Some(xa), Some(xb)) = (at(ea), at(eb)) else {
                return Err(Error::MissingEntity(if at(ea).is_none() { ea } else { eb }));
            };
            // The default rest length is the anchors' distance as spawned.
            let turn = |e: Entity| world.get::<Rotation>(e).map_or(Quat::IDENTITY, |q| q.0);
            let rest = match rest {
                Some(r) => *r,
                None => (xa + turn(ea) * *anchor_a).distance(xb + turn(eb) * *anchor_b),
            };
            let spring = Spring::from_hooke(ea, eb, rest, *stiffness, *damping)?
                .with_anchors(*anchor_a, *anchor_b)?;
            vec![world.spawn(spring).id()]
        }
        Spawn::Rope {
            from,
            to,
            nodes,
            stiffness,
            damping,
            node_mass,
            pin_end,
            hair,
        } => {
            let mut b = if *hair {
                ChainBuilder::hair(*from, *to, *nodes)
            } else {
                ChainBuilder::rope(*from, *to, *nodes)
            };
            if let Some(k) = stiffness {
                b = b.stiffness(*k);
            }
            if let Some(c) = damping {
                b = b.damping(*c);
            }
            if let Some(m) = node_mass {
                b = b.node_mass(*m);
            }
            b.pin_end(*pin_end).spawn(world)?.nodes
        }
        Spawn::Cloth {
            corner,
            nx,
            nz,
            spacing,
            pin_corners,
            stiffness,
            node_mass,
            damping,
            pin,
        } => {
            let mut b = ClothBuilder::new(*corner, *nx, *nz, *spacing).pin_corners(*pin_corners);
            if let Some((s, sh, bend)) = stiffness {
                b = b.stiffness(*s, *sh, *bend);
            }
            if let Some(m) = node_mass {
                b = b.node_mass(*m);
            }
            if let Some(c) = damping {
                b = b.damping(*c);
            }
            let cloth = b.spawn(world)?;
            if let Some(mut nodes) = world.get_mut::<crate::particles::Nodes>(cloth) {
                for &i in pin {
                    nodes.pin(i)?;
                }
            }
            vec![cloth]
        }
        Spawn::Jelly { at, implicit } => vec![scenes::jelly(world, *at, *implicit)?],
        Spawn::Column { n } => scenes::box_column(world, *n)?,
        Spawn::Pyramid { layers } => scenes::pyramid(world, *layers)?,
    })
}

/// A material's value checked as its insert hook would, but refused here rather than
/// quarantining the body it lands on.
fn checked<T: Validate>(value: T) -> Result<T> {
    value.validate().map(|()| value)
}

/// A friction coefficient or restitution typed in an action, checked.
pub(super) fn material(what: &'static str, value: f32) -> Result<f32> {
    non_negative(what, finite(what, value)?)
}
