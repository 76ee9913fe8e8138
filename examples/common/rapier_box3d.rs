//! Box3D's benchmark scenes (`hooke::tools::box3d`) built in rapier 0.36 with Box3D's
//! settings where rapier has the concept: 1/60 s, 4 solver iterations (rapier's substeps),
//! gravity −10 m/s², friction 0.6, contact softness 30 Hz at damping ratio 10 (rapier's
//! default, and 60 Hz against fixed bodies, as Box3D's static softness), push-out 3 m/s,
//! sleeping as the scene says. The same cuboids and the same hull points as hooke's.
#![allow(dead_code)]

use hooke::tools::box3d::{FRICTION, JointGridSpec, Scene, SceneBodies};
use rapier3d::prelude as rp;

/// A rapier world holding `bodies` of `scene`; returns it and the dynamic bodies' handles.
pub fn rapier_scene(
    scene: Scene,
    bodies: &SceneBodies,
) -> (rp::PhysicsWorld, Vec<rp::RigidBodyHandle>) {
    let mut world = rp::PhysicsWorld::new();
    world.gravity = glam::Vec3::new(0.0, -10.0, 0.0);
    let p = &mut world.integration_parameters;
    p.dt = 1.0 / 60.0;
    p.num_solver_iterations = 4;
    p.contact_softness.natural_frequency = 30.0;
    p.contact_softness.damping_ratio = 10.0;
    p.normalized_max_corrective_velocity = 3.0;
    let density = scene.density();
    let sleeps = scene.sleeping();
    let mut handles = Vec::new();
    let mut put = |world: &mut rp::PhysicsWorld, collider: rp::ColliderBuilder, at, fixed| {
        let body = if fixed {
            rp::RigidBodyBuilder::fixed()
        } else {
            rp::RigidBodyBuilder::dynamic().can_sleep(sleeps)
        }
        .translation(at);
        let (h, _) = world.insert(body, collider.density(density).friction(FRICTION));
        if !fixed {
            handles.push(h);
        }
        h
    };
    match bodies {
        SceneBodies::Boxes(specs) => {
            for b in specs {
                let c = rp::ColliderBuilder::cuboid(b.half.x, b.half.y, b.half.z);
                put(&mut world, c, b.position, b.fixed);
            }
        }
        SceneBodies::Hulls(pile) => {
            let g = pile.ground;
            let c = rp::ColliderBuilder::cuboid(g.half.x, g.half.y, g.half.z);
            put(&mut world, c, g.position, true);
            let hull = rp::ColliderBuilder::convex_hull(&pile.points).expect("a valid hull");
            for &at in &pile.positions {
                put(&mut world, hull.clone(), at, false);
            }
        }
        SceneBodies::JointGrid(grid) => {
            // Box3D's filter: category 2, colliding with everything but category 2.
            let groups = rp::InteractionGroups::new(
                rp::Group::GROUP_2,
                !rp::Group::GROUP_2,
                rp::InteractionTestMode::And,
            );
            let spheres: Vec<_> = (0..grid.side * grid.side)
                .map(|index| {
                    let (at, fixed) = grid.sphere(index);
                    let c =
                        rp::ColliderBuilder::ball(JointGridSpec::RADIUS).collision_groups(groups);
                    put(&mut world, c, at, fixed)
                })
                .collect();
            for (a, b, anchor_a, anchor_b) in grid.joints() {
                let joint = rp::SphericalJointBuilder::new()
                    .local_anchor1(anchor_a)
                    .local_anchor2(anchor_b);
                world.insert_impulse_joint(spheres[a], spheres[b], joint);
            }
        }
        SceneBodies::Washer(washer) => {
            let g = washer.ground;
            let c = rp::ColliderBuilder::cuboid(g.half.x, g.half.y, g.half.z);
            put(&mut world, c, g.position, true);
            let drum = world.insert_body(
                rp::RigidBodyBuilder::kinematic_velocity_based()
                    .translation(washer.centre)
                    .linvel(washer.velocity)
                    .angvel(washer.spin),
            );
            for part in &washer.parts {
                let c = rp::ColliderBuilder::convex_hull(part)
                    .expect("a valid hull")
                    .friction(FRICTION);
                world.insert_collider(c, Some(drum));
            }
            let h = washer.cube_half;
            for &at in &washer.cubes {
                put(&mut world, rp::ColliderBuilder::cuboid(h, h, h), at, false);
            }
        }
    }
    (world, handles)
}
