//! Helpers shared by the integration tests.
#![allow(dead_code)]

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::scenes;

pub const TWO_PI: f32 = std::f32::consts::TAU;

/// An oscillator world: m = 1, k = 4π² (period 1 s), x0 = 1, no gravity.
pub fn oscillator(dt: f32, integrator: Integrator, c: f32) -> (World, Entity) {
    let mut world = scenes::world_with(dt, 1, integrator, Vec3::ZERO).unwrap();
    let body = scenes::oscillator(&mut world, 1.0, TWO_PI * TWO_PI, c, 1.0).unwrap();
    (world, body)
}

pub fn x(world: &World, e: Entity) -> Vec3 {
    world.get::<Position>(e).unwrap().get()
}

pub fn v(world: &World, e: Entity) -> Vec3 {
    world.get::<LinearVelocity>(e).unwrap().get()
}

/// Energy ½v² + ½kx² of the unit oscillator, in f64.
pub fn oscillator_energy(world: &World, e: Entity) -> f64 {
    let (x, v) = (f64::from(x(world, e).x), f64::from(v(world, e).x));
    let k = std::f64::consts::TAU.powi(2);
    0.5 * v * v + 0.5 * k * x * x
}

/// A world of falling things: dt 1/60 s, symplectic Euler, g = 9.81 m/s² down, default
/// sleeping.
pub fn gravity_world(substeps: u32) -> World {
    scenes::world_with(
        1.0 / 60.0,
        substeps,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )
    .unwrap()
}

/// A world with every plugin at its defaults, as a game starts.
pub fn default_world() -> World {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w
}

/// A world of step `dt`, `substeps`, symplectic Euler and gravity `g`, with sleeping off (so
/// that nothing the test watches stops moving on its own).
pub fn awake_world(dt: f32, substeps: u32, g: Vec3) -> World {
    let mut w = scenes::world_with(dt, substeps, Integrator::SymplecticEuler, g).unwrap();
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    w
}

/// A contact test's world: [`gravity_world`] with sleeping off (so that nothing the test
/// watches stops moving on its own).
pub fn contact_world(substeps: u32) -> World {
    awake_world(1.0 / 60.0, substeps, Vec3::new(0.0, -9.81, 0.0))
}

/// A dynamic body of `collider` (1000 kg/m³) at `x`, spawned as game code does.
pub fn dynamic(world: &mut World, collider: Collider, x: Vec3) -> Entity {
    world
        .spawn((RigidBody::Dynamic, collider, Position(x.into())))
        .id()
}

/// Where the point `local` of body `e` (its shape frame) stands (m).
pub fn point_of(world: &World, e: Entity, local: Vec3) -> Vec3A {
    world.get::<Position>(e).unwrap().0 + world.get::<Rotation>(e).unwrap().0 * Vec3A::from(local)
}
