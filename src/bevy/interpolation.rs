//! Smooth rendering between fixed steps.
//!
//! A game's frames rarely line up with physics steps: at 144 Hz frames and 64 Hz steps, a
//! body's `Transform` would move on two frames of three and stand still on the third. With
//! [`TransformInterpolation`], the `Transform` shown each frame is the pose between the last
//! two steps at the overstep fraction α = overstep / dt of `Time<Fixed>`:
//! t = t₀ + α (t₁ − t₀), r = slerp(r₀, r₁, α). It lags one step behind and never overshoots.
//! [`TransformExtrapolation`] instead predicts ahead from the last step with the body's
//! velocities, t = t₁ + v α dt, r = exp(ω α dt) r₁: no lag, but it overshoots when a body
//! changes course (and assumes the body has no parent).
//!
//! A `Transform` the game writes is never smoothed over: until the next step reads it as a
//! teleport, the frames show it as written, and the smoothing restarts from it.

use bevy_app::{App, Plugin, RunFixedMainLoop, RunFixedMainLoopSystems};
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time};
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

use super::SyncedTransform;
use crate::particles::LinearVelocity;
use crate::rigid::AngularVelocity;

/// Interpolates this entity's rendered `Transform` between the last two physics steps.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(PoseHistory)]
pub struct TransformInterpolation;

/// Extrapolates this entity's rendered `Transform` ahead of the last physics step from its
/// velocities.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(PoseHistory)]
pub struct TransformExtrapolation;

/// The `Transform` poses of the last two physics steps, kept by hooke for entities with
/// [`TransformInterpolation`] or [`TransformExtrapolation`].
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct PoseHistory {
    previous: (Vec3, Quat),
    current: (Vec3, Quat),
    seeded: bool,
}

impl PoseHistory {
    /// The poses of the step before last and of the last step: (translation, rotation).
    #[must_use]
    pub fn poses(&self) -> [(Vec3, Quat); 2] {
        [self.previous, self.current]
    }

    /// A step ended at this pose.
    pub(super) fn push(&mut self, t: Vec3, r: Quat) {
        self.previous = if self.seeded { self.current } else { (t, r) };
        self.current = (t, r);
        self.seeded = true;
    }

    /// The body was teleported: no smear from where it was.
    pub(super) fn reset(&mut self, t: Vec3, r: Quat) {
        self.previous = (t, r);
        self.current = (t, r);
        self.seeded = true;
    }
}

/// Writes interpolated or extrapolated `Transform`s once per frame, after the frame's
/// fixed steps (`RunFixedMainLoopSystems::AfterFixedMainLoop`).
#[derive(Debug, Default, Clone, Copy)]
pub struct PhysicsInterpolationPlugin;

impl Plugin for PhysicsInterpolationPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            RunFixedMainLoop,
            smooth_transforms.in_set(RunFixedMainLoopSystems::AfterFixedMainLoop),
        );
    }
}

type Smoothed<'a> = (
    &'a PoseHistory,
    &'a mut Transform,
    &'a mut SyncedTransform,
    Has<TransformExtrapolation>,
    Option<&'a LinearVelocity>,
    Option<&'a AngularVelocity>,
);

fn smooth_transforms(fixed: Option<Res<Time<Fixed>>>, mut bodies: Query<Smoothed>) {
    let Some(fixed) = fixed else {
        return;
    };
    let alpha = fixed.overstep_fraction();
    let ahead = fixed.overstep().as_secs_f32();
    for (h, mut t, mut synced, extrapolate, v, w) in &mut bodies {
        // A `Transform` that is not the one hooke last wrote was written by the game: a
        // teleport the next step reads (`read_transforms`), shown as written until then.
        if !h.seeded || !synced.matches(&t) {
            continue;
        }
        let [(t0, r0), (t1, r1)] = h.poses();
        let (translation, rotation) = if extrapolate {
            let v = v.map_or(Vec3::ZERO, LinearVelocity::get);
            let w = w.map_or(Vec3::ZERO, AngularVelocity::get);
            (
                t1 + v * ahead,
                (Quat::from_scaled_axis(w * ahead) * r1).normalize(),
            )
        } else {
            (t0.lerp(t1, alpha), r0.slerp(r1, alpha))
        };
        if t.translation != translation || t.rotation != rotation {
            t.translation = translation;
            t.rotation = rotation;
        }
        *synced = SyncedTransform::of(&t);
    }
}
