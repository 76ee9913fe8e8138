//! Continuous collision for fast pairs: time-of-impact casts over the step.
//!
//! Speculative contacts (see the `solver` module) stop a fast body from closing more than
//! the gap its contact points see at the start of the step. They rest on the manifold that
//! parry finds for the pose at the start, which holds the *closest* features. A body moving
//! sideways as well as in, obliquely, can reach a face whose closest points do not overlap
//! it yet: a box 2.6 m from a 1 cm wall and 0.45 m below its edge gets an empty box–box
//! manifold (the faces' clipping has no overlap), then slides into the face region and
//! through the wall within one step (measured: 6 of 60 box shots at 30–75°, at 300 and
//! 1000 m/s).
//!
//! For a pair whose relative displacement in the step, |v_b − v_a| dt (plus the larger spin
//! sweep |ω| r dt), exceeds a quarter of the thinner collider's thickness (the smallest full
//! extent of its local bounding box, at least `ContactSettings::margin`: triangle meshes and
//! heightfields are zero thick), the two shapes are cast along their relative velocity for
//! one step (parry's `cast_shapes`). A hit at a time t > 0 whose normal no manifold of the
//! pair already has (within about 8°; for spinning pairs, any hit) becomes one more manifold
//! of one speculative point: the two witness points at the impact, which are material points
//! of their shapes, with the gap n·(p_b − p_a) they have at the start of the step (t times
//! the approach speed). The solver then lets the pair close no more than that gap, along the
//! impact's own normal.
//!
//! A pair in which a side's spin sweeps its reach farther than that is cast along both
//! bodies' arcs instead (parry's nonlinear cast, by conservative advancement): a plank
//! spinning at 50 rad/s went through the wall under the linear cast.

use glam::{Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::query::{NonlinearRigidMotion, ShapeCastOptions, ShapeCastStatus, TrackedContact};
use parry3d::shape::{PackedFeatureId, Shape};

use crate::collision::narrow_phase::points::choose_points;
use crate::collision::narrow_phase::{Manifold, ManifoldData};

/// Cosine of the angle within which a manifold's normal counts as the impact's.
const SAME_NORMAL: f32 = 0.99;

/// The smallest full extent of a shape's local bounding box (m): how thin it is.
#[must_use]
pub(crate) fn thickness(bounds: [Vec3; 2]) -> f32 {
    (bounds[1] - bounds[0]).min_element().max(0.0)
}

/// The thickness a pair is judged by (m): the thinner of the two, at least `margin` (a
/// triangle mesh or heightfield is zero thick, and every pair moving on one at all would
/// otherwise count as fast or deep).
#[must_use]
pub(crate) fn pair_thickness(a: f32, b: f32, margin: f32) -> f32 {
    a.min(b).max(margin)
}

/// True when a pair moves far enough against itself in one step to be cast: `sweep`, its
/// relative speed plus the larger of its sides' spin speeds |ω| r (m/s), carries it past a
/// quarter of `thin` in `dt`.
#[inline]
#[must_use]
pub(crate) fn is_fast(sweep: f32, dt: f32, thin: f32) -> bool {
    sweep * dt > 0.25 * thin
}

/// The most turns in one step that a side may make for its cast to follow the arc (1,000
/// rad/s over a 60 Hz step is 2.7 turns).
const MAX_ARC_TURNS: f32 = 16.0;

/// One side of a cast.
pub(crate) struct CastSide<'a> {
    pub shape: &'a dyn Shape,
    pub pose: Pose,
    /// Velocity of the centre of mass (m/s).
    pub velocity: Vec3,
    /// Angular velocity (rad/s).
    pub spin: Vec3,
    /// The centre of mass in the shape's frame (m).
    pub centre: Vec3,
    /// The fastest speed its spin gives any of its points, |ω| r (m/s).
    pub swing: f32,
    /// Farthest any point of the shape is from its centre of mass (m).
    pub reach: f32,
}

impl CastSide<'_> {
    fn motion(&self) -> NonlinearRigidMotion {
        NonlinearRigidMotion::new(self.pose, self.centre, self.velocity, self.spin)
    }
}

/// Of a pair, whether `a` is the smaller side (by reach), and the larger side's velocity at
/// the smaller side's centre of mass (m/s), its spin taken about its own centre.
#[must_use]
pub(crate) fn at_smaller(a: &CastSide, b: &CastSide) -> (bool, Vec3) {
    let a_small = a.reach <= b.reach;
    let (small, large) = if a_small { (a, b) } else { (b, a) };
    let centre = |s: &CastSide| s.pose * s.centre;
    let there = large.velocity + large.spin.cross(centre(small) - centre(large));
    (a_small, there)
}

/// The speculative manifold of the first impact within `dt`, if the pair will hit and none
/// of `manifolds` already has its normal; `thin` is the thinner side's thickness and
/// `scratch` the point choice's buffer.
pub(crate) fn impact_manifold(
    a: &CastSide,
    b: &CastSide,
    dt: f32,
    thin: f32,
    manifolds: &[Manifold],
    scratch: &mut Vec<(Vec3A, f32, bool)>,
) -> Option<Manifold> {
    let options = ShapeCastOptions {
        max_time_of_impact: dt,
        target_distance: 0.0,
        stop_at_penetration: false,
        compute_impact_geometry_on_penetration: false,
    };
    // A larger side that barely turns in the step (Box3D's washer drum, 20 m across at
    // 25°/s: its arc leaves the tangent by r (ω dt)² / 2 = 0.3 mm) moves near the smaller
    // side as a translation at its velocity there. It is cast so, and the pair is judged by
    // the spin the two differ by over the smaller side's reach; casting the drum along its
    // arc against every cube in it took half the washer's step.
    let (a_small, there) = at_smaller(a, b);
    let (small, large) = if a_small { (a, b) } else { (b, a) };
    let turn = large.spin.length() * dt;
    let steady = 0.5 * large.reach * turn * turn <= 0.1 * thin;
    let (va, vb, sweep) = if steady {
        let sweep = (a.spin - b.spin).length() * small.reach;
        match a_small {
            true => (a.velocity, there, sweep),
            false => (there, b.velocity, sweep),
        }
    } else {
        (a.velocity, b.velocity, a.swing.max(b.swing))
    };
    // A side whose spin sweeps more than the linear cast's tolerance is cast along its arc
    // (conservative advancement, dearer), else along a line. The arc cast can fail (its
    // bisection steps into an overlap and its normal is then meaningless: a box spinning at
    // 500 rad/s was given one that spun it up to 1,500 rad/s); the line cast stands in. An
    // unsupported pair (a trimesh against a trimesh) answers Err: no cast.
    let linear = || {
        parry3d::query::cast_shapes(&a.pose, va, a.shape, &b.pose, vb, b.shape, options)
            .ok()
            .flatten()
    };
    // Past a few turns in the step the arc cast's conservative advancement takes ever more
    // steps (a box spun to 2e11 rad/s by game code held one step for minutes); such a body
    // is past the divergence guard, quarantined at the end of the substep.
    let turns = a.spin.length().max(b.spin.length()) * dt / core::f32::consts::TAU;
    let spun = is_fast(sweep, dt, thin) && turns <= MAX_ARC_TURNS;
    let hit = if spun {
        match parry3d::query::cast_shapes_nonlinear(
            &a.motion(),
            a.shape,
            &b.motion(),
            b.shape,
            0.0,
            dt,
            false,
        ) {
            Ok(Some(hit)) if hit.status != ShapeCastStatus::Failed => Some(hit),
            Ok(None) => None,
            _ => linear(),
        }
    } else {
        linear()
    }?;
    if hit.status == ShapeCastStatus::PenetratingOrWithinTargetDist || hit.time_of_impact <= 0.0 {
        return None;
    }
    let n1 = hit.normal1;
    if !(n1.is_finite() && hit.witness1.is_finite() && hit.witness2.is_finite()) {
        return None;
    }
    // Under linear motion a manifold with the impact's normal already holds the points that
    // will touch. Under spin it holds the closest features at the start, not the corner the
    // spin brings round (a plank spinning at 50 rad/s went through a wall past a manifold
    // with the wall's normal), so the impact point is added beside it.
    let known = !spun
        && manifolds.iter().any(|m| {
            !m.points.is_empty()
                && match m.subshape_pos1() {
                    Some(part) => (part.rotation * m.local_n1).dot(n1) > SAME_NORMAL,
                    None => m.local_n1.dot(n1) > SAME_NORMAL,
                }
        });
    if known {
        return None;
    }
    let world_n = a.pose.rotation * n1;
    let gap = world_n.dot(b.pose * hit.witness2 - a.pose * hit.witness1);
    // The cast's witnesses are in the whole shapes' frames: the manifold names no part
    // (u32::MAX), so no part pose is applied to it.
    let mut m = Manifold::with_data(u32::MAX, u32::MAX, ManifoldData::default());
    m.local_n1 = n1;
    m.local_n2 = hit.normal2;
    m.points.push(TrackedContact::new(
        hit.witness1,
        hit.witness2,
        PackedFeatureId::UNKNOWN,
        PackedFeatureId::UNKNOWN,
        gap.max(0.0),
    ));
    choose_points(&mut m, scratch);
    Some(m)
}
