//! The contact scenes built in rapier 0.36 from the same specs hooke spawns, for the
//! side-by-side examples.

use hooke::tools::scenes::BoxSpec;
use rapier3d::prelude as rp;

/// A rapier world at dt = 1/60 and its defaults, with `specs` as cuboids of density
/// `density(i)` (kg/m³) for spec `i`, sleeping off. Returns the world and the dynamic bodies
/// in order.
pub fn rapier_boxes(
    specs: &[BoxSpec],
    density: impl Fn(usize) -> f32,
) -> (rp::PhysicsWorld, Vec<rp::RigidBodyHandle>) {
    let mut world = rp::PhysicsWorld::new();
    world.integration_parameters.dt = 1.0 / 60.0;
    let mut handles = Vec::new();
    for (i, b) in specs.iter().enumerate() {
        let collider =
            rp::ColliderBuilder::cuboid(b.half.x, b.half.y, b.half.z).density(density(i));
        let body = if b.fixed {
            rp::RigidBodyBuilder::fixed()
        } else {
            rp::RigidBodyBuilder::dynamic().can_sleep(false)
        }
        .translation(b.position)
        .rotation(b.rotation.to_scaled_axis());
        let (h, _) = world.insert(body, collider);
        if !b.fixed {
            handles.push(h);
        }
    }
    (world, handles)
}
