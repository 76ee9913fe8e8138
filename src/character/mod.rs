//! A kinematic character controller: move-and-slide against the colliders, with a maximum
//! slope, stepping up stairs, snapping to the ground, riding moving platforms and pushing
//! dynamic bodies with a force limit.
//!
//! Give a kinematic body a [`Collider`](crate::collision::Collider) (a capsule is the usual
//! choice) and a [`CharacterController`]; write the walk you want into its
//! [`CharacterInput`] each frame and read [`CharacterState`] for the result:
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! world.spawn((RigidBody::Static, Collider::cuboid(20.0, 0.5, 20.0).unwrap(),
//!     Position::from(Vec3::new(0.0, -0.5, 0.0))));
//! let player = world
//!     .spawn((
//!         CharacterController::default(),
//!         Collider::capsule_y(0.5, 0.3).unwrap(), // 1.6 m tall
//!         Position::from(Vec3::new(0.0, 1.0, 0.0)),
//!     ))
//!     .id();
//! world.get_mut::<CharacterInput>(player).unwrap().velocity = Vec3::new(2.0, 0.0, 0.0);
//! for _ in 0..60 {
//!     world.step_physics();
//! }
//! let state = world.get::<CharacterState>(player).unwrap();
//! assert!(state.grounded);
//! let x = world.get::<Position>(player).unwrap().get();
//! assert!((x.x - 2.0).abs() < 0.1 && (x.y - 0.81).abs() < 0.02, "{x}");
//! ```
//!
//! **Each step** (in [`crate::core::schedule::PrepareSystems::Characters`], after kinematic
//! platforms are driven and before collision detection):
//! 1. the character rides the body it stands on: it moves by that body's velocity at its
//!    feet (casts ignore that body, so a descending lift does not block it);
//! 2. out of any overlap, along the contact normals;
//! 3. the walk plus its own fall (gravity while airborne, [`CharacterInput::jump_speed`] once)
//!    is swept as the collider's shape, kept [`CharacterController::skin`] away from
//!    everything. At each hit the rest of the move slides along the surface; a surface
//!    steeper than [`CharacterController::max_slope`] acts as a wall (no climbing it), unless
//!    it is a ledge no higher than [`CharacterController::step_height`] with walkable ground
//!    on top, which the character steps onto. A dynamic body hit is pushed with at most
//!    [`CharacterController::max_push_force`];
//! 4. grounded if walkable ground lies within the skin below; if it was grounded and is not
//!    now (walking down a slope or a stair), it snaps down by up to
//!    [`CharacterController::snap_distance`];
//! 5. its velocity becomes the move over the step, so the integrator carries it there and
//!    the contact solver sees a body moving at that velocity.
//!
//! A ledge is recognised by the face under the hit point (a short ray down from just
//! inside it), not by the shape's normal at an edge, which for a round shape on a stair nose
//! points sideways.
//!
//! The shape casts are [`SpatialQuery::cast_shape_with_gap`](crate::collision::SpatialQuery::cast_shape_with_gap):
//! O(colliders) each, a handful per character per step.
//!
//! Units: m, s, N, rad.

mod plugin;
mod slide;

pub use plugin::CharacterControllerPlugin;

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::collision::QueryFilter;
use crate::core::error::{Error, Result, finite, finite_vec, non_negative};
use crate::core::quarantine::{Validate, validate_on_insert};
use crate::rigid::RigidBody;

/// A kinematic character moved by [`CharacterInput`] with move-and-slide. Needs a
/// [`Collider`](crate::collision::Collider) on the same entity; brings
/// [`RigidBody::Kinematic`] along (on a body given another kind it does not move it).
#[derive(Component, Debug, Clone, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(RigidBody = RigidBody::Kinematic, CharacterInput, CharacterState)]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct CharacterController {
    /// Unit vector pointing up (default +y): what "ground", "slope" and "step" are measured
    /// against.
    pub up: Vec3,
    /// Steepest walkable slope (rad, default 45°). Steeper surfaces are walls: the
    /// character slides down them and cannot walk up them.
    pub max_slope: f32,
    /// Highest ledge stepped onto while walking (m, default 0.25; 0 turns stepping off).
    pub step_height: f32,
    /// How far down a grounded character follows the ground when it drops away (m,
    /// default 0.2; 0 turns snapping off).
    pub snap_distance: f32,
    /// Gap kept between the shape and everything (m, default 0.01).
    pub skin: f32,
    /// Largest force the character pushes a dynamic body with (N, default 500: a
    /// 10 kg crate slides, a 200 kg one does not at friction 0.5).
    pub max_push_force: f32,
    /// Multiplies [`crate::particles::Gravity`] for the character's fall (default 1).
    pub gravity_scale: f32,
    /// Most surfaces slid along in one step (default 4).
    pub max_slides: u32,
    /// Which colliders the character collides with (it never collides with itself).
    pub filter: QueryFilter,
}

impl Default for CharacterController {
    fn default() -> Self {
        Self {
            up: Vec3::Y,
            max_slope: std::f32::consts::FRAC_PI_4,
            step_height: 0.25,
            snap_distance: 0.2,
            skin: 0.01,
            max_push_force: 500.0,
            gravity_scale: 1.0,
            max_slides: 4,
            filter: QueryFilter::default(),
        }
    }
}

impl Validate for CharacterController {
    fn validate(&self) -> Result<()> {
        let up = finite_vec("character up", self.up)?;
        if (up.length() - 1.0).abs() > 1e-3 {
            return Err(Error::NonFinite {
                what: "character up (a unit vector)",
                value: format!("{up}"),
            });
        }
        let slope = finite("character max slope", self.max_slope)?;
        if !(0.0..=std::f32::consts::FRAC_PI_2).contains(&slope) {
            return Err(Error::NonFinite {
                what: "character max slope (0 to π/2 rad)",
                value: format!("{slope}"),
            });
        }
        non_negative("character step height", self.step_height)?;
        non_negative("character snap distance", self.snap_distance)?;
        non_negative("character skin", self.skin)?;
        non_negative("character push force", self.max_push_force)?;
        finite("character gravity scale", self.gravity_scale)?;
        Ok(())
    }
}

impl CharacterController {
    /// Whether a surface with outward normal `normal` is walkable ground.
    #[must_use]
    pub fn is_walkable(&self, normal: Vec3) -> bool {
        normal.dot(self.up) >= self.max_slope.cos() - 1e-4
    }
}

/// What the character wants to do this step: write it each frame.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct CharacterInput {
    /// Walking velocity (m/s, world frame). Its part along `up` moves the character up or
    /// down too (ladders, flying); gravity is added by the controller.
    pub velocity: Vec3,
    /// An upward speed to leave the ground with (m/s): used by the next step, then reset
    /// to 0. The game decides when a jump is allowed (usually while
    /// [`CharacterState::grounded`]).
    pub jump_speed: f32,
}

impl Validate for CharacterInput {
    fn validate(&self) -> Result<()> {
        finite_vec("character velocity", self.velocity)?;
        finite("character jump speed", self.jump_speed).map(|_| ())
    }
}

/// The ground a character stands on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct Ground {
    /// The collider.
    pub entity: Entity,
    /// The point under the character (m, world).
    pub point: Vec3,
    /// The ground's face normal there.
    pub normal: Vec3,
}

/// A surface the character's move ran into.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct CharacterHit {
    /// The collider hit.
    pub entity: Entity,
    /// Point of contact (m, world).
    pub point: Vec3,
    /// Normal out of the collider, towards the character.
    pub normal: Vec3,
    /// Impulse the character gave it (N·s, world; zero unless it is a dynamic body).
    pub impulse: Vec3,
}

/// The result of the last step's move. Written by the controller.
#[derive(Component, Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct CharacterState {
    /// Whether the character stands on walkable ground.
    pub grounded: bool,
    /// The ground it stands on.
    pub ground: Option<Ground>,
    /// Its own speed along `up` from gravity and jumps (m/s; falling is negative).
    pub vertical_speed: f32,
    /// How far it moved in the last step (m, world).
    pub translation: Vec3,
    /// Whether it stepped up a ledge in the last step.
    pub stepped: bool,
    /// The surfaces its last move ran into, in order.
    pub hits: Vec<CharacterHit>,
}
