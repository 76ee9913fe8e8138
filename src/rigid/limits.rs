//! Speed limits: a body never moves or turns faster than its cap.

use super::{AngularMomentum, AngularVelocity};
use crate::core::error::{Result, positive};
use crate::core::quarantine::{Validate, validate_on_insert};
use crate::particles::LinearVelocity;
use bevy_ecs::prelude::*;

/// The fastest a body may move (m/s): its velocity is scaled down to this after every
/// substep's solve. Takes effect from the next substep.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct MaxLinearSpeed(pub f32);

/// The fastest a body may turn (rad/s): ω and L are scaled down together to this after
/// every substep's solve.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct MaxAngularSpeed(pub f32);

impl Validate for MaxLinearSpeed {
    fn validate(&self) -> Result<()> {
        positive("maximum linear speed", self.0).map(|_| ())
    }
}

impl Validate for MaxAngularSpeed {
    fn validate(&self) -> Result<()> {
        positive("maximum angular speed", self.0).map(|_| ())
    }
}

/// The factor that brings a speed of `speed` down to `cap` (1 when under it).
#[must_use]
#[inline]
pub fn speed_scale(speed: f32, cap: f32) -> f32 {
    if speed > cap { cap / speed } else { 1.0 }
}

type Capped<'a> = (
    Option<&'a MaxLinearSpeed>,
    Option<&'a MaxAngularSpeed>,
    &'a mut LinearVelocity,
    Option<&'a mut AngularVelocity>,
    Option<&'a mut AngularMomentum>,
);

/// Bodies with a cap, simulated.
type CappedFilter = (
    Or<(With<MaxLinearSpeed>, With<MaxAngularSpeed>)>,
    crate::core::rest::Simulated,
);

/// Scales each capped body's velocities down to its caps.
pub(crate) fn limit_speeds(mut bodies: Query<Capped, CappedFilter>) {
    for (linear, angular, mut v, w, l) in &mut bodies {
        if let Some(cap) = linear {
            let s = speed_scale(v.0.length(), cap.0);
            if s < 1.0 {
                v.0 *= s;
            }
        }
        if let (Some(cap), Some(mut w)) = (angular, w) {
            let s = speed_scale(w.0.length(), cap.0);
            if s < 1.0 {
                w.0 *= s;
                if let Some(mut l) = l {
                    l.0 *= s;
                }
            }
        }
    }
}
