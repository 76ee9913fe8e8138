//! The README's bare-`World` block, run as written and compared with the README.

use bevy_ecs::prelude::*;
use hooke::prelude::*;

fn readme_world() -> Result<(World, Entity), hooke::Error> {
    // README-WORLD
    let mut world = World::new();
    world.add_physics(PhysicsPlugins); // or only the effects you need
    world.insert_resource(PhysicsTime::new(1.0 / 60.0, 4)?); // 60 Hz, 4 substeps (the default)
    let ball = world
        .spawn(ParticleBundle::new(Vec3::Y * 10.0, Vec3::ZERO, 1.0)?)
        .id();
    ChainBuilder::rope(Vec3::ZERO, Vec3::X, 20).spawn(&mut world)?;
    world.spawn((
        RigidBody::Dynamic, // mass and inertia from the collider at 1000 kg/m³
        Collider::cuboid(0.5, 0.5, 0.5)?,
        Position::from(Vec3::Y * 3.0),
    ));
    for _ in 0..60 {
        world.step_physics(); // one fixed step of 1/60 s
    }
    println!(
        "the ball fell to {} m",
        world.get::<Position>(ball).unwrap().get().y
    );
    // README-WORLD-END
    Ok((world, ball))
}

#[test]
fn the_readme_world_block_is_this_code() {
    let me = include_str!("readme.rs");
    let readme = include_str!("../../../README.md");
    let block = |text: &'static str| {
        let begin = text.find("// README-WORLD\n").unwrap() + "// README-WORLD\n".len();
        let end = text.find("// README-WORLD-END").unwrap();
        text[begin..end].split_whitespace().collect::<String>()
    };
    assert_eq!(block(readme), block(me), "README and test differ");
}

#[test]
fn the_readme_world_block_runs_and_the_ball_falls_half_g_t_squared() {
    let (world, ball) = readme_world().unwrap();
    let y = world.get::<Position>(ball).unwrap().get().y;
    // 1 s of fall at 60 Hz × 4 substeps: 10 − ½ g t² = 5.095 m, symplectic Euler's
    // g h t / 2 lower (h = 1/240 s).
    let expected = 10.0 - 0.5 * 9.81 - 9.81 * (1.0 / 240.0) / 2.0;
    assert!((y - expected).abs() < 1e-3, "{y} vs {expected}");
}
