//! hooke's jointed scenes (`hooke::tools::joint_scenes`) built in rapier 0.36 with its impulse
//! joints: 1/60 s, 4 solver iterations (rapier's substeps, as hooke's 4), gravity −9.81 m/s²,
//! the same boxes at 1000 kg/m³ and the same anchors.
#![allow(dead_code)]

use hooke::tools::joint_scenes::{HangingChain, RagdollPile};
use rapier3d::prelude as rp;

/// A rapier world holding `chain`; returns it and the bodies' handles from the top.
pub fn rapier_chain(chain: HangingChain) -> (rp::PhysicsWorld, Vec<rp::RigidBodyHandle>) {
    let mut world = rp::PhysicsWorld::new();
    world.gravity = glam::Vec3::new(0.0, -9.81, 0.0);
    let p = &mut world.integration_parameters;
    p.dt = 1.0 / 60.0;
    p.num_solver_iterations = 4;
    let (ground, _) = world.insert(
        rp::RigidBodyBuilder::fixed(),
        rp::ColliderBuilder::ball(0.01).sensor(true),
    );
    let bodies = chain.bodies();
    let handles: Vec<_> = bodies
        .iter()
        .map(|b| {
            let body = rp::RigidBodyBuilder::dynamic().translation(b.position);
            let c = rp::ColliderBuilder::cuboid(b.half.x, b.half.y, b.half.z).density(1000.0);
            world.insert(body, c).0
        })
        .collect();
    if let Some(&load) = handles.last() {
        world.bodies[load].set_linvel(HangingChain::KICK, true);
    }
    for (a, b, anchor_a, anchor_b) in chain.joints() {
        let joint = rp::SphericalJointBuilder::new()
            .local_anchor1(anchor_a)
            .local_anchor2(anchor_b);
        world.insert_impulse_joint(a.map_or(ground, |a| handles[a]), handles[b], joint);
    }
    (world, handles)
}

/// The widest any impulse joint's anchors stand apart (m).
pub fn widest_gap(world: &rp::PhysicsWorld) -> f32 {
    world
        .impulse_joints
        .iter()
        .map(|(_, j)| {
            let (b1, b2) = (&world.bodies[j.body1()], &world.bodies[j.body2()]);
            let a1 = b1.position() * j.data.local_frame1.translation;
            let a2 = b2.position() * j.data.local_frame2.translation;
            (a1 - a2).length()
        })
        .fold(0.0, f32::max)
}

/// A rapier world holding `pile` ([`RagdollPile`]) on a fixed ground box: the same capsules
/// at 1000 kg/m³ and the same anchors. rapier's ball joint takes limits per axis of its
/// frame, not a cone: the frame's x axis is laid along the limb, x takes the twist range and
/// y, z each ± the cone's half-angle (a square pyramid around the cone). Joint friction is
/// a velocity motor towards zero on each free angular axis with its force capped at
/// [`Ragdoll::FRICTION`]. Jointed parts do not collide with each other, as in hooke.
pub fn rapier_ragdoll_pile(pile: RagdollPile) -> rp::PhysicsWorld {
    use hooke::tools::joint_scenes::{Ragdoll, RagdollTurn};
    use rp::JointAxis;
    let mut world = rp::PhysicsWorld::new();
    world.gravity = glam::Vec3::new(0.0, -9.81, 0.0);
    let p = &mut world.integration_parameters;
    p.dt = 1.0 / 60.0;
    p.num_solver_iterations = 4;
    world.insert(
        rp::RigidBodyBuilder::fixed().translation(glam::Vec3::new(0.0, -0.5, 0.0)),
        rp::ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
    // The motors' gain: high enough that the cap, not the gain, sets the friction.
    let gain = 100.0;
    for k in 0..pile.ragdolls {
        let (origin, turn) = RagdollPile::placement(k);
        let parts: Vec<_> = Ragdoll::PARTS
            .iter()
            .map(|part| {
                let body = rp::RigidBodyBuilder::dynamic()
                    .translation(origin + turn * part.centre)
                    .rotation(turn.to_scaled_axis());
                let c =
                    rp::ColliderBuilder::capsule_y(part.half_height, part.radius).density(1000.0);
                world.insert(body, c).0
            })
            .collect();
        for j in &Ragdoll::JOINTS {
            let (pa, pb) = (&Ragdoll::PARTS[j.parent], &Ragdoll::PARTS[j.child]);
            let (anchor_a, anchor_b) = (j.at - pa.centre, j.at - pb.centre);
            let (a, b) = (parts[j.parent], parts[j.child]);
            match j.turn {
                RagdollTurn::Ball { axis, swing, twist } => {
                    let frame = glam::Quat::from_rotation_arc(glam::Vec3::X, axis);
                    let mut joint = rp::SphericalJointBuilder::new()
                        .local_frame1(rp::Pose::from_parts(anchor_a, frame))
                        .local_frame2(rp::Pose::from_parts(anchor_b, frame))
                        .contacts_enabled(false)
                        .limits(JointAxis::AngX, [-twist, twist])
                        .limits(JointAxis::AngY, [-swing, swing])
                        .limits(JointAxis::AngZ, [-swing, swing]);
                    for axis in [JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ] {
                        joint = joint
                            .motor_velocity(axis, 0.0, gain)
                            .motor_max_force(axis, Ragdoll::FRICTION);
                    }
                    world.insert_impulse_joint(a, b, joint);
                }
                RagdollTurn::Hinge { axis, min, max } => {
                    let joint = rp::RevoluteJointBuilder::new(axis)
                        .local_anchor1(anchor_a)
                        .local_anchor2(anchor_b)
                        .contacts_enabled(false)
                        .limits([min, max])
                        .motor_velocity(0.0, gain)
                        .motor_max_force(Ragdoll::FRICTION);
                    world.insert_impulse_joint(a, b, joint);
                }
            }
        }
    }
    world
}
