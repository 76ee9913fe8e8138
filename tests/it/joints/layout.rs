//! The same jointed scene gives the same bits whatever the archetype layout of its joints
//! and whatever order component types were registered in: the joints are solved in the
//! order of their entities, not in the order a query happens to visit them (a restored
//! snapshot builds its archetypes in an order of its own).

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::joint_scenes::RagdollPile;

#[derive(Component)]
struct Tag;

#[derive(Resource, Default)]
struct Unrelated;

/// Drops three ragdolls; with `rearranged`, every other joint carries a marker component
/// (so the joints sit in two archetypes, the marked ones visited last) and an unrelated
/// resource is registered first (shifting every component id after it). The parts'
/// positions and rotations after 2 s, as bits.
fn drop(rearranged: bool) -> Vec<u32> {
    let mut world = World::new();
    if rearranged {
        world.init_resource::<Unrelated>();
        world.register_component::<Tag>();
    }
    world.add_physics(PhysicsPlugins);
    let (parts, joints) = RagdollPile { ragdolls: 3 }.spawn(&mut world).unwrap();
    if rearranged {
        for &j in joints.iter().step_by(2) {
            world.entity_mut(j).insert(Tag);
        }
    }
    for _ in 0..120 {
        world.step_physics();
    }
    parts
        .iter()
        .flat_map(|&e| {
            let x = world.get::<Position>(e).unwrap().0;
            let q = world.get::<Rotation>(e).unwrap().0;
            [x.x, x.y, x.z, q.x, q.y, q.z, q.w].map(f32::to_bits)
        })
        .collect()
}

#[test]
fn joints_give_the_same_bits_whatever_their_archetypes_and_component_ids() {
    let (plain, rearranged) = (drop(false), drop(true));
    assert_eq!(plain.len(), rearranged.len());
    let first = plain.iter().zip(&rearranged).position(|(a, b)| a != b);
    assert!(
        first.is_none(),
        "first differing word {first:?} of {}",
        plain.len()
    );
}
