//! Move-and-slide: the geometry of one character move, over any [`Obstacles`].

use bevy_ecs::entity::Entity;
use glam::Vec3;

use super::{CharacterController, Ground};
use crate::collision::{Hit, ShapeContact};

/// Moves shorter than this (m) are done.
const DONE: f32 = 1e-5;
/// How far a hit moves the character back out along the normal (m), so the next sweep
/// along the surface does not start at exactly the kept gap and stop at once.
const NUDGE: f32 = 1e-4;

/// A cast's normal within about 25° of the face at its point is that face's (a cast at the
/// kept gap can lean by 20°; a round shape on an edge, by 45° or more).
const GRAZE_AGREEMENT: f32 = 0.9;
/// A move whose direction dips into a face by less than this (cosine) only grazes it.
const GRAZE: f32 = 1e-3;

/// The world as the character's shape sees it.
pub(crate) trait Obstacles {
    /// The first collider the shape, origin at `from`, meets moving `max` (m) along the unit
    /// `dir`, keeping the skin; the hit's distance is how far it can go. `skip` is ignored.
    fn cast(&self, from: Vec3, dir: Vec3, max: f32, skip: Option<Entity>) -> Option<Hit>;
    /// The face normal of `entity` under `point`, from a short ray down along −`up`
    /// starting just inside the point and above it; none if the ray starts inside.
    fn face_below(&self, entity: Entity, point: Vec3, inward: Vec3, up: Vec3) -> Option<Vec3>;
    /// The face normal of `entity` at `point`, from a short ray back along −`normal`; none
    /// if the ray misses.
    fn face_at(&self, entity: Entity, point: Vec3, normal: Vec3) -> Option<Vec3>;
    /// Colliders overlapping the shape at `at`.
    fn overlaps(&self, at: Vec3) -> Vec<ShapeContact>;
    /// Distance (m) from the shape origin to its lowest point along −`up`.
    fn feet_depth(&self, up: Vec3) -> f32;
}

/// A surface met by the move, with the velocity the character wanted into it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Contact {
    pub hit: Hit,
    /// The character's intended velocity when it met the surface (m/s).
    pub wanted: Vec3,
}

/// The outcome of [`move_and_slide`].
#[derive(Debug, Clone, Default)]
pub(crate) struct Move {
    /// Where the shape origin ends (m).
    pub position: Vec3,
    /// Surfaces met, in order.
    pub contacts: Vec<Contact>,
    /// The walkable ground under the end position.
    pub ground: Option<Ground>,
    /// Whether a ledge was stepped onto.
    pub stepped: bool,
}

/// The walkable ground at a hit, if it is on some: the face under the hit point decides
/// (a shape cast's normal at an edge, or at the kept gap, can lean by degrees), or else the
/// cast's normal.
fn ground_of(o: &impl Obstacles, c: &CharacterController, hit: &Hit) -> Option<Ground> {
    let inward = -(hit.normal - c.up * hit.normal.dot(c.up)).normalize_or_zero();
    let normal = match o.face_below(hit.entity, hit.point, inward, c.up) {
        Some(face) if c.is_walkable(face) => face,
        _ if c.is_walkable(hit.normal) => hit.normal,
        _ => return None,
    };
    Some(Ground {
        entity: hit.entity,
        point: hit.point,
        normal,
    })
}

/// The walkable ground within `reach` (m, beyond the skin) below the shape at `at`.
pub(crate) fn ground_below(
    o: &impl Obstacles,
    c: &CharacterController,
    at: Vec3,
    reach: f32,
) -> Option<(Ground, f32)> {
    let hit = o.cast(at, -c.up, reach, None)?;
    ground_of(o, c, &hit).map(|g| (g, hit.distance))
}

/// The move left after meeting a surface of outward normal `n`: its part into the surface
/// removed; on a surface too steep to walk, no climbing beyond what the move itself rose.
#[must_use]
pub(crate) fn slide(rest: Vec3, n: Vec3, up: Vec3, walkable: bool) -> Vec3 {
    let mut r = rest - n * rest.dot(n).min(0.0);
    if !walkable {
        let own_rise = rest.dot(up).max(0.0);
        let climb = r.dot(up);
        if climb > own_rise {
            r -= up * (climb - own_rise);
        }
        let wall = (n - up * n.dot(up)).normalize_or_zero();
        let into = r.dot(wall);
        if into < 0.0 {
            r -= wall * into;
        }
    }
    r
}

/// Steps onto a ledge in front: up by at most the step height, forward by `ahead`, then
/// down onto walkable ground higher than `from`. The new position and how far it went
/// forward.
fn step_up(
    o: &impl Obstacles,
    c: &CharacterController,
    from: Vec3,
    ahead: Vec3,
) -> Option<(Vec3, f32, Ground)> {
    let up = c.up;
    let rise = o
        .cast(from, up, c.step_height, None)
        .map_or(c.step_height, |h| h.distance);
    if rise <= c.skin {
        return None;
    }
    let lifted = from + up * rise;
    let length = ahead.length();
    let dir = ahead / length;
    let forward = o
        .cast(lifted, dir, length, None)
        .map_or(length, |h| h.distance);
    if forward <= DONE {
        return None;
    }
    let over = lifted + dir * forward;
    let land = o.cast(over, -up, rise, None)?;
    let ground = ground_of(o, c, &land)?;
    let at = over - up * land.distance;
    ((at - from).dot(up) > DONE).then_some((at, forward, ground))
}

/// Pushes the shape out of what it overlaps (a platform moved into it, a spawn inside a
/// wall), two passes along the contact normals.
fn depenetrate(o: &impl Obstacles, c: &CharacterController, mut at: Vec3) -> Vec3 {
    for _ in 0..2 {
        let mut push = Vec3::ZERO;
        for contact in o.overlaps(at) {
            let depth = c.skin - contact.distance;
            if contact.distance < 0.0 && depth > 0.0 {
                push += contact.normal * depth;
            }
        }
        if push == Vec3::ZERO {
            break;
        }
        at += push;
    }
    at
}

/// Moves the shape origin from `start` by `motion` (m) over a step of `dt` (s): slides
/// along what it meets, steps up ledges while grounded, then finds the ground and, if
/// `was_grounded` and it lost it, snaps down to it.
#[must_use]
pub(crate) fn move_and_slide(
    o: &impl Obstacles,
    c: &CharacterController,
    start: Vec3,
    motion: Vec3,
    was_grounded: bool,
    dt: f32,
) -> Move {
    let up = c.up;
    let speed = motion.length() / dt;
    let mut out = Move {
        position: depenetrate(o, c, start),
        ..Move::default()
    };
    let mut rest = motion;
    let mut grounded = was_grounded;
    let mut skip = None;
    for _ in 0..c.max_slides.max(1) + 1 {
        let length = rest.length();
        if length <= DONE {
            break;
        }
        let dir = rest / length;
        let Some(hit) = o.cast(out.position, dir, length, skip) else {
            out.position += rest;
            break;
        };
        // A cast's normal at the kept gap can lean by a degree or two from the face it
        // found; the face's own normal (within 25°) is the one slid along, and a move that
        // only grazes that face leaves its collider out of the next cast.
        let face = o
            .face_at(hit.entity, hit.point, hit.normal)
            .filter(|f| f.dot(hit.normal) > GRAZE_AGREEMENT);
        if skip.is_none()
            && let Some(face) = face
            && dir.dot(face) > -GRAZE
        {
            skip = Some(hit.entity);
            continue;
        }
        let hit = Hit {
            normal: face.unwrap_or(hit.normal),
            ..hit
        };
        skip = None;
        let travel = hit.distance.min(length);
        out.position += dir * travel + hit.normal * NUDGE;
        rest = dir * (length - travel);
        out.contacts.push(Contact {
            hit,
            wanted: dir * speed,
        });
        let walkable = c.is_walkable(hit.normal);
        if walkable {
            grounded = true;
        } else if grounded && c.step_height > 0.0 {
            let ahead = rest - up * rest.dot(up);
            let feet = out.position.dot(up) - o.feet_depth(up);
            let height = hit.point.dot(up) - feet;
            if ahead.length() > DONE
                && height <= c.step_height + c.skin
                && let Some((at, forward, _)) = step_up(o, c, out.position, ahead)
            {
                out.position = at;
                out.stepped = true;
                let left = ahead.length() - forward;
                rest = ahead.normalize_or_zero() * left;
                continue;
            }
        }
        rest = slide(rest, hit.normal, up, walkable);
    }
    let rising = motion.dot(up) > DONE;
    out.ground = ground_below(o, c, out.position, c.skin).map(|(g, _)| g);
    if out.ground.is_none()
        && was_grounded
        && !rising
        && c.snap_distance > 0.0
        && let Some((ground, distance)) = ground_below(o, c, out.position, c.snap_distance)
    {
        out.position -= up * distance;
        out.ground = Some(ground);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slide_keeps_the_tangential_part() {
        let r = slide(Vec3::new(1.0, 0.0, -1.0), Vec3::Z, Vec3::Y, false);
        assert_eq!(r, Vec3::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn a_steep_slope_is_not_climbed() {
        // 60° slope facing −x; walking +x into it.
        let n = Vec3::new(-(60f32.to_radians().sin()), 60f32.to_radians().cos(), 0.0);
        let r = slide(Vec3::X, n, Vec3::Y, false);
        assert!(r.y <= 1e-6 && r.x <= 1e-6, "{r}");
        // The same slope when walkable: the move turns up along it.
        let r = slide(Vec3::X, n, Vec3::Y, true);
        assert!(r.y > 0.4, "{r}");
    }

    #[test]
    fn a_fall_onto_a_steep_slope_slides_down_it() {
        let n = Vec3::new(-(60f32.to_radians().sin()), 60f32.to_radians().cos(), 0.0);
        let r = slide(-Vec3::Y, n, Vec3::Y, false);
        assert!(r.y < 0.0 && r.x < 0.0, "downhill is −x: {r}");
        assert!(r.dot(n).abs() < 1e-6);
    }
}
