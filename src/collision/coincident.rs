//! Bodies spawned at exactly one point are set apart by a millimetre before they first
//! touch.
//!
//! Two shapes whose centres coincide have no contact normal: parry then answers +y for
//! every such pair. Four hundred balls spawned at one point were pushed apart along y only,
//! a column of them was driven into the ground, and 111 sank through it (one 40 m down
//! within 11 s). Boxes fared better only because a face normal is always defined. Each
//! dynamic body spawned since the last step at the very position of an earlier one of that
//! step (both with a collider) is moved [`APART`] metres along its own direction of a spiral over the sphere, so
//! that the contacts push the heap apart in every direction, as jittered spawns do (within
//! the free axes of a body with [`crate::rigid::LockedAxes`]).

use bevy_ecs::prelude::*;
use glam::Vec3A;

use crate::particles::Position;
use crate::rigid::RigidBody;

/// How far a coincident spawn is moved (m): far above parry's tolerance for a normal,
/// far below any shape a game simulates.
pub const APART: f32 = 1e-3;

/// Positions of the dynamic bodies spawned since the last step, with how many share each.
#[derive(Resource, Default)]
pub(crate) struct RecentSpawns(std::collections::HashMap<[u32; 3], u32>);

/// The `k`-th direction of a spiral over the unit sphere (golden-ratio steps in height and
/// golden-angle steps around): spread evenly for any count, without knowing the count.
#[must_use]
fn spiral(k: u32) -> Vec3A {
    let k = k as f32;
    let y = 1.0 - 2.0 * (k * 0.618_034).fract();
    let r = (1.0 - y * y).max(0.0).sqrt();
    let (s, c) = (k * 2.399_963).sin_cos();
    Vec3A::new(r * c, y, r * s)
}

/// Observer: a body was spawned; a dynamic one with a collider at the very position of an
/// earlier such spawn of this step moves [`APART`] m along its spiral direction (bodies
/// that cannot touch are left where they were put). Not while a snapshot restores.
pub(crate) fn separate_coincident_spawns(
    event: On<Add<RigidBody>>,
    mut bodies: Query<
        (&RigidBody, &mut Position, Option<&crate::rigid::LockedAxes>),
        With<super::Collider>,
    >,
    recent: Option<ResMut<RecentSpawns>>,
    restoring: Option<Res<crate::core::restore::Restoring>>,
) {
    let Some(mut recent) = recent.filter(|_| restoring.is_none()) else {
        return;
    };
    let Ok((kind, mut x, locks)) = bodies.get_mut(event.event().entity) else {
        return;
    };
    if *kind != RigidBody::Dynamic || !x.0.is_finite() {
        return;
    }
    let count = recent
        .0
        .entry(x.0.to_array().map(f32::to_bits))
        .or_insert(0);
    if *count > 0 {
        // Never off a locked axis: a 2.5D game's bodies stay in their plane.
        let away = match locks {
            Some(l) => (spiral(*count) * l.translation_mask()).normalize_or_zero(),
            None => spiral(*count),
        };
        x.0 += away * APART;
    }
    *count += 1;
}

/// Forgets the last step's spawns.
pub(crate) fn forget_recent_spawns(mut recent: ResMut<RecentSpawns>) {
    if !recent.0.is_empty() {
        recent.0.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spiral_directions_are_unit_and_spread() {
        let d: Vec<Vec3A> = (1..400).map(spiral).collect();
        assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
        let up = d.iter().filter(|v| v.y > 0.0).count();
        assert!((180..220).contains(&up), "{up} of 399 point up");
        let closest = (0..d.len())
            .flat_map(|i| (i + 1..d.len()).map(move |j| (i, j)))
            .map(|(i, j)| (d[i] - d[j]).length())
            .fold(f32::INFINITY, f32::min);
        // 0.0059 for the first 399: offsets 6 µm apart, far above parry's tolerance.
        assert!(closest > 1e-3, "two directions nearly equal: {closest}");
    }
}
