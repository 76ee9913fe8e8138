//! The kinematic character controller at its defaults: stairs, slopes, platforms, pushing,
//! jumps and walls, each against the geometry's closed form, over frame rates.

mod climbs_stairs_up_to_the_step_height;
mod moving_platforms_carry_the_character;
mod pushes_with_a_force_limit;
mod slopes_past_the_maximum_are_walls;
mod walls_slide_and_jumps_follow_the_parabola;

use bevy_ecs::prelude::*;
use hooke::character::CharacterState;
use hooke::core::time::PhysicsTime;
use hooke::prelude::*;

/// Capsule half height and radius (m): a 1.6 m character.
pub const HALF: f32 = 0.5;
/// Capsule radius (m).
pub const RADIUS: f32 = 0.3;
/// The centre's height above a floor the character stands on (m): half height, radius,
/// and the controller's default skin of 1 cm.
pub const STANDING: f32 = HALF + RADIUS + 0.01;

/// A world at the defaults, stepping at `hz`, with a 100 m floor whose top is y = 0.
pub fn world(hz: f32) -> World {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    world.insert_resource(PhysicsTime::new(1.0 / hz, 4).unwrap());
    fixed_box(
        &mut world,
        Vec3::new(50.0, 0.5, 50.0),
        Vec3::new(0.0, -0.5, 0.0),
        Quat::IDENTITY,
    );
    world
}

/// A static box of half extents `half` at `at`.
pub fn fixed_box(world: &mut World, half: Vec3, at: Vec3, rotation: Quat) -> Entity {
    world
        .spawn((
            RigidBody::Static,
            Collider::cuboid(half.x, half.y, half.z).unwrap(),
            Position::from(at),
            Rotation(rotation),
        ))
        .id()
}

/// A default character whose feet are at `feet`.
pub fn character(world: &mut World, feet: Vec3) -> Entity {
    world
        .spawn((
            CharacterController::default(),
            Collider::capsule_y(HALF, RADIUS).unwrap(),
            Position::from(feet + Vec3::Y * STANDING),
        ))
        .id()
}

/// Steps `seconds` with the character walking at `velocity`; calls `each` after every step.
pub fn walk(
    world: &mut World,
    who: Entity,
    velocity: Vec3,
    seconds: f32,
    mut each: impl FnMut(&World),
) {
    let steps = (seconds / world.resource::<PhysicsTime>().dt()).round() as usize;
    for _ in 0..steps {
        world.get_mut::<CharacterInput>(who).unwrap().velocity = velocity;
        world.step_physics();
        each(world);
    }
}

pub fn at(world: &World, e: Entity) -> Vec3 {
    world.get::<Position>(e).unwrap().get()
}

pub fn state(world: &World, e: Entity) -> &CharacterState {
    world.get::<CharacterState>(e).unwrap()
}

/// The deepest overlap (m, ≥ 0) of the character's capsule with anything else.
pub fn overlap(world: &mut World, who: Entity) -> f32 {
    let x = at(world, who);
    let mut state: bevy_ecs::system::SystemState<SpatialQuery> =
        bevy_ecs::system::SystemState::new(world);
    let query = state.get(world).unwrap();
    let capsule = Collider::capsule_y(HALF, RADIUS).unwrap();
    query
        .shape_contacts(
            &capsule,
            (x, Quat::IDENTITY),
            0.0,
            &hooke::collision::QueryFilter::excluding(who),
        )
        .iter()
        .map(|c| -c.distance)
        .fold(0.0, f32::max)
}
