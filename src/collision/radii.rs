//! How far a shape reaches from its origin and how near its surface comes to it. The narrow
//! phase bounds how fast a turning shape's points move, and how fast its surface can close on
//! a neighbour, with these two radii.

use glam::Vec3;
use parry3d::shape::{Shape, TypedShape};

/// The farthest point of `shape` from its origin (m), and the radius of the largest ball
/// about the origin inside it (m; 0 where the shape does not say or the origin is outside).
/// `bounds` is the shape's local bounding box, the answer for shapes without a closer one.
#[must_use]
pub(crate) fn radii(shape: &dyn Shape, bounds: [Vec3; 2]) -> (f32, f32) {
    let boxed = bounds[0].abs().max(bounds[1].abs()).length();
    let (far, near) = match shape.as_typed_shape() {
        TypedShape::Ball(b) => (b.radius, b.radius),
        TypedShape::Cuboid(c) => (c.half_extents.length(), c.half_extents.min_element()),
        TypedShape::ConvexPolyhedron(p) => {
            let far = p.points().iter().map(|v| v.length()).fold(0.0, f32::max);
            // Each face's plane lies at n · v from the origin, for any vertex v of the face.
            let near = p
                .faces()
                .iter()
                .map(|f| {
                    let v = p.vertices_adj_to_face()[f.first_vertex_or_edge as usize];
                    f.normal.dot(p.points()[v as usize])
                })
                .fold(f32::INFINITY, f32::min);
            (far, near.max(0.0))
        }
        _ => (boxed, 0.0),
    };
    (far.min(boxed), near.min(far))
}

/// The fastest the surface of a shape turning at `spin` (rad/s) about `centre` can move
/// along any one direction (m/s): the support point p in direction n moves along n at
/// (ω × p) · n, at most |ω| √(|p|² − (p·n)²), and p·n is at least the inner radius about
/// the centre while |p| is at most the reach.
#[must_use]
pub(crate) fn surface_swing(spin: f32, reach: f32, near: f32, centre: Vec3) -> f32 {
    let inner = (near - centre.length()).max(0.0);
    spin * (reach * reach - inner * inner).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::shape::{Ball, ConvexPolyhedron, Cuboid};

    #[test]
    fn radii_of_a_ball_a_box_and_a_hull_are_their_corners_and_faces() {
        let b = Ball::new(0.5);
        assert_eq!(radii(&b, [Vec3::splat(-0.5), Vec3::splat(0.5)]), (0.5, 0.5));
        let c = Cuboid::new(Vec3::new(1.0, 2.0, 2.0));
        let (far, near) = radii(&c, [-c.half_extents, c.half_extents]);
        assert!((far - 3.0).abs() < 1e-6 && near == 1.0);
        // The unit cube as a hull: corners at √3/2, faces at 1/2.
        let pts: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2) as f32) - 0.5)
            .collect();
        let h = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        let (far, near) = radii(&h, [Vec3::splat(-0.5), Vec3::splat(0.5)]);
        assert!((far - 0.75f32.sqrt()).abs() < 1e-6, "{far}");
        assert!((near - 0.5).abs() < 1e-6, "{near}");
    }

    #[test]
    fn a_turning_ball_about_its_centre_does_not_move_its_surface() {
        assert_eq!(surface_swing(10.0, 0.5, 0.5, Vec3::ZERO), 0.0);
        // Off its centre it does: the whole reach.
        assert_eq!(surface_swing(10.0, 1.0, 0.5, Vec3::X * 0.5), 10.0);
    }
}
