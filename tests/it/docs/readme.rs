//! The README's quick start, compiled and run as written (with a frame time filled in).

use bevy_ecs::prelude::*;
use hooke::prelude::*;

#[test]
fn readme_quick_start_runs() -> Result<(), hooke::Error> {
    let frame_seconds = 1.0;
    let mut world = World::new();
    world.add_physics(PhysicsPlugins); // or only the effects you need
    world.insert_resource(PhysicsTime::new(1.0 / 60.0, 4)?); // 60 Hz, 4 substeps (the default)
    let ball = world
        .spawn(ParticleBundle::new(Vec3::Y * 10.0, Vec3::ZERO, 1.0)?)
        .id();
    ChainBuilder::rope(Vec3::ZERO, Vec3::X, 20).spawn(&mut world)?;
    // A rigid box that collides: mass and inertia from the collider at 1000 kg/m³.
    let crate_ = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5)?,
            Position::from(Vec3::Y * 3.0),
        ))
        .id();
    world.advance_physics(frame_seconds)?; // fixed steps through an accumulator
    let y = world.get::<Position>(ball).unwrap().0.y;
    // A frame of 1 s runs only max_steps_per_frame (4) steps of 1/60 s: 1/15 s of fall.
    assert!(y < 10.0 && y > 9.9, "{y}");
    let box_y = world.get::<Position>(crate_).unwrap().0.y;
    assert!(box_y < 3.0 && box_y > 2.9, "the box falls too: {box_y}");
    Ok(())
}
