//! A course for the character controller, shared by `examples/character.rs` and
//! `examples/bevy_game`: two lanes along +x on a floor whose top is y = 0.
//!
//! - lane 1 (z = 0): a staircase of six 18 cm risers and 30 cm treads, a landing, a 30°
//!   ramp down, then a 10 kg crate to push;
//! - lane 2 (z = −3 m): a 60° ramp, steeper than the default 45° maximum: a wall.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::Result;
use crate::character::CharacterController;
use crate::collision::{Collider, ColliderDensity};
use crate::particles::Position;
use crate::rigid::{RigidBody, Rotation};

/// A static box of the course.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// Half extents (m).
    pub half: Vec3,
    /// Centre (m).
    pub position: Vec3,
    /// Orientation.
    pub rotation: Quat,
}

/// The course's dimensions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CharacterCourse {
    /// Stair riser (m).
    pub riser: f32,
    /// Stair tread (m).
    pub tread: f32,
    /// Number of steps.
    pub steps: usize,
    /// Slope of the ramp down from the landing (degrees).
    pub ramp_degrees: f32,
    /// Slope of lane 2's ramp (degrees).
    pub wall_degrees: f32,
    /// Mass of the crate (kg; a 1 m cube).
    pub crate_kg: f32,
    /// Capsule half height and radius of the characters (m).
    pub capsule: (f32, f32),
}

impl Default for CharacterCourse {
    fn default() -> Self {
        Self {
            riser: 0.18,
            tread: 0.3,
            steps: 6,
            ramp_degrees: 30.0,
            wall_degrees: 60.0,
            crate_kg: 10.0,
            capsule: (0.5, 0.3),
        }
    }
}

/// The spawned course.
#[derive(Debug, Clone)]
pub struct CharacterCourseParts {
    /// The character on lane 1 and the one on lane 2.
    pub characters: [Entity; 2],
    /// The crate.
    pub crate_: Entity,
    /// The static boxes.
    pub blocks: Vec<Entity>,
}

/// z of lane 2 (m).
pub const LANE_2: f32 = -3.0;
/// Where the stairs start (m).
const STAIRS: f32 = 2.0;
/// Length of the landing (m).
const LANDING: f32 = 1.5;
/// Half width of the lanes (m).
const HALF_WIDTH: f32 = 1.0;

impl CharacterCourse {
    /// The landing's height (m).
    #[must_use]
    pub fn landing_height(&self) -> f32 {
        self.riser * self.steps as f32
    }

    /// Where the ramp down from the landing starts and ends (x, m).
    #[must_use]
    pub fn ramp_span(&self) -> (f32, f32) {
        let start = STAIRS + self.tread * self.steps as f32 + LANDING;
        let run = self.landing_height() / self.ramp_degrees.to_radians().tan();
        (start, start + run)
    }

    /// Where lane 2's ramp starts (x, m).
    #[must_use]
    pub fn wall_start(&self) -> f32 {
        STAIRS
    }

    /// The crate's starting centre (m).
    #[must_use]
    pub fn crate_start(&self) -> Vec3 {
        Vec3::new(self.ramp_span().1 + 2.0, 0.5, 0.0)
    }

    /// The characters' starting centres (m): standing on the floor at x = 0.
    #[must_use]
    pub fn character_starts(&self) -> [Vec3; 2] {
        let (half, r) = self.capsule;
        let y = half + r + CharacterController::default().skin;
        [Vec3::new(0.0, y, 0.0), Vec3::new(0.0, y, LANE_2)]
    }

    /// The static boxes: stairs, landing, ramp down, and lane 2's steep ramp.
    #[must_use]
    pub fn blocks(&self) -> Vec<Block> {
        let mut out = Vec::new();
        let (ramp_start, _) = self.ramp_span();
        for i in 0..self.steps {
            let top = self.riser * (i + 1) as f32;
            let start = STAIRS + self.tread * i as f32;
            out.push(Block {
                half: Vec3::new((ramp_start - start) / 2.0, top / 2.0, HALF_WIDTH),
                position: Vec3::new((start + ramp_start) / 2.0, top / 2.0, 0.0),
                rotation: Quat::IDENTITY,
            });
        }
        let thickness = 0.25;
        let slope = |degrees: f32, top_start: Vec3, length: f32, z: f32, rising: bool| {
            let theta = degrees.to_radians() * if rising { 1.0 } else { -1.0 };
            let rotation = Quat::from_rotation_z(theta);
            let corner = Vec3::new(-length / 2.0, thickness, 0.0);
            Block {
                half: Vec3::new(length / 2.0, thickness, HALF_WIDTH),
                position: top_start - rotation * corner + Vec3::Z * z,
                rotation,
            }
        };
        let h = self.landing_height();
        out.push(slope(
            self.ramp_degrees,
            Vec3::new(ramp_start, h, 0.0),
            h / self.ramp_degrees.to_radians().sin(),
            0.0,
            false,
        ));
        out.push(slope(
            self.wall_degrees,
            Vec3::new(self.wall_start(), 0.0, 0.0),
            3.0,
            LANE_2,
            true,
        ));
        out
    }

    /// Spawns the course (not the floor) on a `World`.
    ///
    /// # Errors
    /// Bad dimensions, as the shapes' typed errors.
    pub fn spawn(&self, world: &mut World) -> Result<CharacterCourseParts> {
        let mut blocks = Vec::new();
        for b in self.blocks() {
            blocks.push(
                world
                    .spawn((
                        RigidBody::Static,
                        Collider::cuboid(b.half.x, b.half.y, b.half.z)?,
                        Position::from(b.position),
                        Rotation(b.rotation),
                    ))
                    .id(),
            );
        }
        let crate_ = world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.5, 0.5, 0.5)?,
                ColliderDensity::try_new(self.crate_kg)?,
                Position::from(self.crate_start()),
            ))
            .id();
        let (half, r) = self.capsule;
        let starts = self.character_starts();
        let mut characters = [Entity::PLACEHOLDER; 2];
        for (slot, start) in characters.iter_mut().zip(starts) {
            *slot = world
                .spawn((
                    CharacterController::default(),
                    Collider::capsule_y(half, r)?,
                    Position::from(start),
                ))
                .id();
        }
        Ok(CharacterCourseParts {
            characters,
            crate_,
            blocks,
        })
    }
}
