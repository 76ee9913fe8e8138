//! Joints on kinematic bodies: the side the game moves carries its joints' anchors along.

use hooke::prelude::*;

use crate::common::{default_world, dynamic, point_of};

#[test]
fn a_body_hung_from_a_turning_kinematic_arm_keeps_to_its_anchor() {
    let mut w = default_world();
    let arm = w
        .spawn((
            RigidBody::Kinematic,
            Collider::cuboid(1.0, 0.05, 0.05).unwrap(),
            Position(Vec3A::new(0.0, 3.0, 0.0)),
            AngularVelocity(Vec3A::new(0.0, 2.0, 0.0)),
        ))
        .id();
    let bob = dynamic(
        &mut w,
        Collider::cuboid(0.1, 0.5, 0.1).unwrap(),
        Vec3::new(1.0, 2.5, 0.0),
    );
    let (anchor_a, anchor_b) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    w.spawn(SphericalJoint::new(arm, bob).with_anchors(anchor_a, anchor_b));
    let mut widest = 0.0_f32;
    for _ in 0..180 {
        w.step_physics();
        widest = widest.max((point_of(&w, arm, anchor_a) - point_of(&w, bob, anchor_b)).length());
    }
    println!("turning arm: joint parted by at most {widest} m");
    // The arm's tip moves at 2 m/s: a step's travel is 33 mm.
    assert!(widest < 1e-3, "parted {widest} m");
    assert!(w.get::<Quarantined>(bob).is_none());
}
