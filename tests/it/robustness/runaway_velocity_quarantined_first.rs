//! Found by the scenario corpus (`scenarios/quarantine_caught.ron`): game code set one
//! crate's velocity to an absurd value, and in that same step a crate 30 m away, resting on
//! the ground and nowhere near its path, was flung to 1e27 m. The contacts ran before the
//! integrators' divergence check, and the runaway's sweep box covered the world. A written
//! velocity past the guard is now quarantined before the step uses it.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::scenes;
use hooke::tools::testing::PhysicsTestExt;

fn crate_at(world: &mut World, x: Vec3) -> Entity {
    scenes::dynamic_box(world, Vec3::splat(0.5), x).unwrap()
}

#[test]
fn a_runaway_velocity_is_quarantined_before_it_reaches_anyone() {
    for speed in [1e5f32, 1e9, 1e30, f32::MAX] {
        for (runaway_at, bystander_at) in [
            (Vec3::new(-3.0, 0.5, 0.0), Vec3::new(3.0, 0.5, 4.0)),
            (Vec3::new(-3.0, 10.0, 0.0), Vec3::new(3.0, 0.5, 30.0)),
        ] {
            let mut world = World::new();
            world.add_physics(PhysicsPlugins);
            scenes::ground(&mut world).unwrap();
            let runaway = crate_at(&mut world, runaway_at);
            let bystander = crate_at(&mut world, bystander_at);
            world.run_for_seconds(0.5).unwrap();
            world.get_mut::<LinearVelocity>(runaway).unwrap().0 = Vec3A::new(speed, 0.0, 0.0);
            world.run_for_seconds(1.0).unwrap();
            assert!(
                world.get::<Quarantined>(runaway).is_some(),
                "{speed} m/s: the runaway is not quarantined"
            );
            assert!(
                world.get::<Quarantined>(bystander).is_none(),
                "{speed} m/s from {runaway_at}: the bystander was quarantined"
            );
            let x = world.position_of(bystander).unwrap();
            assert!(
                (x - bystander_at).length() < 0.01,
                "{speed} m/s from {runaway_at}: the bystander moved to {x}"
            );
        }
    }
}

#[test]
fn a_fast_but_sane_velocity_is_left_alone() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    scenes::ground(&mut world).unwrap();
    let bullet = crate_at(&mut world, Vec3::new(0.0, 5.0, 0.0));
    world.get_mut::<LinearVelocity>(bullet).unwrap().0 = Vec3A::new(900.0, 0.0, 0.0);
    world.step_physics();
    assert!(world.get::<Quarantined>(bullet).is_none());
}
