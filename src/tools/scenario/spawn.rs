//! Building a file's entries through hooke's public constructors and scene builders, the
//! way game code spawns them.

use bevy_ecs::prelude::*;
use glam::{EulerRot, Quat, Vec3};

use super::format::{BodyKind, Field, JointKind, Shape, Spawn};
use crate::cloth::ClothBuilder;
use crate::collision::Collider;
use crate::collision::ColliderDensity;
use crate::collision::Friction;
use crate::collision::Restitution;
use crate::collision::RestitutionThreshold;
use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::Validate;
use crate::joints::{
    DistanceJoint, FixedJoint, JointBreakForce, PrismaticJoint, RevoluteJoint, SphericalJoint,
};
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
            let spring = Spring::new(ea, eb, rest, *stiffness, *damping)?
                .with_anchors(*anchor_a, *anchor_b)?;
            vec![world.spawn(spring).id()]
        }
        Spawn::Joint {
            kind,
            a,
            b,
            anchor_a,
            anchor_b,
            collide,
            break_force,
        } => {
            // The loader checked the names are one live entity each.
            let end = |name: &String| lookup(name).ok_or(Error::MissingEntity(Entity::PLACEHOLDER));
            let ea = a.as_ref().map(end).transpose()?;
            let eb = end(b)?;
            let sides = Sides {
                a: ea,
                b: eb,
                anchor_a: *anchor_a,
                anchor_b: *anchor_b,
                collide: *collide,
            };
            let mut e = joint(world, kind, &sides)?;
            if let Some(f) = break_force {
                let f = JointBreakForce::new(*f);
                f.validate()?;
                e.insert(f);
            }
            vec![e.id()]
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

/// A joint entry's two sides and anchors.
struct Sides {
    a: Option<Entity>,
    b: Entity,
    anchor_a: Vec3,
    anchor_b: Vec3,
    collide: bool,
}

/// Spawns the joint of `kind` between `sides`, checked first: a bad axis or limit is the
/// file's error, not a quarantined joint.
fn joint<'w>(world: &'w mut World, kind: &JointKind, sides: &Sides) -> Result<EntityWorldMut<'w>> {
    let &Sides { a, b, .. } = sides;
    let pose = |world: &World, e: Option<Entity>| {
        e.map_or((Vec3::ZERO, Quat::IDENTITY), |e| {
            let x = world.get::<Position>(e).map_or(Vec3::ZERO, Position::get);
            let q = world.get::<Rotation>(e).map_or(Quat::IDENTITY, |q| q.0);
            (x, q)
        })
    };
    let ((xa, qa), (xb, qb)) = (pose(world, a), pose(world, Some(b)));
    let relative = qa.inverse() * qb;
    fn place<J: Component + Validate>(world: &mut World, joint: J) -> Result<EntityWorldMut<'_>> {
        joint.validate()?;
        Ok(world.spawn(joint))
    }
    macro_rules! placed {
        ($joint:expr) => {
            place(
                world,
                $joint
                    .with_anchors(sides.anchor_a, sides.anchor_b)
                    .with_collision(sides.collide),
            )
        };
    }
    match *kind {
        JointKind::Ball => placed!(match a {
            Some(a) => SphericalJoint::new(a, b),
            None => SphericalJoint::to_world(b),
        }),
        JointKind::LimitedBall {
            axis,
            swing,
            twist,
            friction,
        } => {
            let mut j = match a {
                Some(a) => SphericalJoint::new(a, b),
                None => SphericalJoint::to_world(b),
            }
            .with_axis(axis);
            if let Some(max) = swing {
                j = j.with_swing_limit(max.to_radians());
            }
            if let Some((min, max)) = twist {
                j = j.with_twist_limits(min.to_radians(), max.to_radians());
            }
            if let Some(torque) = friction {
                j = j.with_friction(torque);
            }
            placed!(j)
        }
        JointKind::Hinge {
            axis,
            limits,
            motor,
            servo,
        } => {
            let mut j = match a {
                Some(a) => RevoluteJoint::new(a, b, axis),
                None => RevoluteJoint::to_world(b, axis),
            };
            if let Some((min, max)) = limits {
                j = j.with_limits(min.to_radians(), max.to_radians());
            }
            if let Some((speed, torque)) = motor {
                j = j.with_motor(speed, torque);
            }
            if let Some((target, stiffness, damping, torque)) = servo {
                j = j.with_position_motor(target.to_radians(), stiffness, damping, torque);
            }
            placed!(j)
        }
        JointKind::Slider {
            axis,
            limits,
            motor,
            servo,
        } => {
            let mut j = match a {
                Some(a) => PrismaticJoint::new(a, b, axis).with_relative(relative),
                None => PrismaticJoint::to_world(b, axis).with_relative(qb),
            };
            if let Some((min, max)) = limits {
                j = j.with_limits(min, max);
            }
            if let Some((speed, force)) = motor {
                j = j.with_motor(speed, force);
            }
            if let Some((target, stiffness, damping, force)) = servo {
                j = j.with_position_motor(target, stiffness, damping, force);
            }
            placed!(j)
        }
        JointKind::Distance { length, rope } => {
            let at = |x: Vec3, q: Quat, local: Vec3, world_side: bool| {
                if world_side { local } else { x + q * local }
            };
            let spawned =
                at(xa, qa, sides.anchor_a, a.is_none()).distance(at(xb, qb, sides.anchor_b, false));
            let l = length.unwrap_or(spawned);
            let mut j = match a {
                Some(a) => DistanceJoint::new(a, b, l),
                None => DistanceJoint::to_world(b, l),
            };
            if rope {
                j = j.with_limits(0.0, l);
            }
            placed!(j)
        }
        JointKind::Fixed => placed!(match a {
            Some(a) => FixedJoint::new(a, b, relative),
            None => FixedJoint::to_world(b, qb),
        }),
    }
}

/// Sets the motor of the hinge or slider `e`.
/// Sets joint `e`'s position motor (servo): `target` in degrees for a hinge, m for a slider.
pub(super) fn set_servo(
    world: &mut World,
    e: Entity,
    target: f32,
    (stiffness, damping, max): (f32, f32, f32),
) -> Result<()> {
    finite("servo target", target)?;
    non_negative("servo stiffness", stiffness)?;
    non_negative("servo damping", damping)?;
    non_negative("servo maximum", max)?;
    if let Some(mut j) = world.get_mut::<RevoluteJoint>(e) {
        *j = j.with_position_motor(target.to_radians(), stiffness, damping, max);
    } else if let Some(mut j) = world.get_mut::<PrismaticJoint>(e) {
        *j = j.with_position_motor(target, stiffness, damping, max);
    } else {
        // The loader checked it was spawned a hinge or a slider: it broke or was taken off.
        return Err(Error::NoMotor(e));
    }
    Ok(())
}

pub(super) fn set_motor(
    world: &mut World,
    e: Entity,
    target_velocity: f32,
    max: f32,
) -> Result<()> {
    finite("motor target velocity", target_velocity)?;
    non_negative("motor maximum", max)?;
    if let Some(mut j) = world.get_mut::<RevoluteJoint>(e) {
        *j = j.with_motor(target_velocity, max);
    } else if let Some(mut j) = world.get_mut::<PrismaticJoint>(e) {
        *j = j.with_motor(target_velocity, max);
    } else {
        // The loader checked it was spawned a hinge or a slider: it broke or was taken off.
        return Err(Error::NoMotor(e));
    }
    Ok(())
}
