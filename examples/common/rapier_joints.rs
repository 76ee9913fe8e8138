//! hooke's jointed scenes (`hooke::tools::joint_scenes`) built in rapier 0.36 with its impulse
//! joints: 1/60 s, 4 solver iterations (rapier's substeps, as hooke's 4), gravity −9.81 m/s²,
//! the same boxes at 1000 kg/m³ and the same anchors.
#![allow(dead_code)]

use hooke::tools::joint_scenes::HangingChain;
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
