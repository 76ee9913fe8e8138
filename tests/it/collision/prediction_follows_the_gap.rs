//! Guards the prediction distance of a pair, which counts each side's speed toward the
//! other along the normal it kept, once the shapes' support points show that normal still
//! separates them (issue 38). Box3D's convex pile drops hulls side by side, its washer
//! tumbles cubes; counting each one's whole speed gave neighbours falling together
//! speculative points between them that could never close, three times rapier's points.
//! The axis must still see a body that lands while another falls onto it. Hulls, boxes and
//! balls, in either spawn order.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::collision::Contacts;
use hooke::prelude::*;

/// 32 points spread over a sphere of radius 2 (a Fibonacci lattice), the size of Box3D's
/// pile hulls.
fn hull_points() -> Vec<Vec3> {
    let n = 32;
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let t = golden * i as f32;
            2.0 * Vec3::new(r * t.cos(), y, r * t.sin())
        })
        .collect()
}

/// The hull's extent along `axis`, below and above its origin (m).
fn extent(axis: Vec3) -> (f32, f32) {
    let d = hull_points()
        .iter()
        .map(|p| p.dot(axis))
        .collect::<Vec<_>>();
    (
        -d.iter().copied().fold(f32::INFINITY, f32::min),
        d.iter().copied().fold(f32::NEG_INFINITY, f32::max),
    )
}

/// The shapes the prediction is checked on: Box3D's pile hull, a 2 m cube and a ball of
/// radius 2.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Hull,
    Cube,
    Ball,
}

impl Kind {
    const ALL: [Kind; 3] = [Kind::Hull, Kind::Cube, Kind::Ball];

    fn collider(self) -> Collider {
        match self {
            Kind::Hull => Collider::convex_hull(&hull_points()).unwrap(),
            Kind::Cube => Collider::cuboid(1.0, 1.0, 1.0).unwrap(),
            Kind::Ball => Collider::ball(2.0).unwrap(),
        }
    }

    /// The shape's extent along `axis` (a coordinate axis), below and above its origin (m).
    fn extent(self, axis: Vec3) -> (f32, f32) {
        match self {
            Kind::Hull => extent(axis),
            Kind::Cube => (1.0, 1.0),
            Kind::Ball => (2.0, 2.0),
        }
    }
}

fn body(w: &mut World, kind: Kind, at: Vec3, v: Vec3) -> Entity {
    w.spawn((
        RigidBody::Dynamic,
        kind.collider(),
        Position::from(at),
        LinearVelocity::from(v),
    ))
    .id()
}

#[test]
fn bodies_falling_side_by_side_keep_no_points_between_them() {
    for kind in Kind::ALL {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        // 3 cm apart along x: inside the boxes' margins, so the two are a pair, but they
        // fall together at 50 m/s and can never meet.
        let (below, above) = kind.extent(Vec3::X);
        let a = body(&mut w, kind, Vec3::new(0.0, 500.0, 0.0), Vec3::NEG_Y * 50.0);
        let b = body(
            &mut w,
            kind,
            Vec3::new(above + below + 0.03, 500.0, 0.0),
            Vec3::NEG_Y * 50.0,
        );
        for _ in 0..10 {
            w.step_physics();
        }
        let contacts = w.resource::<Contacts>();
        assert_eq!(contacts.pairs_len(), 1, "{kind:?}: the two are a pair");
        let points = contacts.manifold_stats().1;
        assert_eq!(points, 0, "{kind:?}: {points} speculative points");
        assert!(!contacts.are_touching(a, b));
    }
}

#[test]
fn a_body_falling_onto_one_that_lands_stops_on_it() {
    // Either spawn order: the pair's first entity is then the lower or the upper body.
    for (kind, upper_first) in Kind::ALL.into_iter().flat_map(|k| [(k, false), (k, true)]) {
        let mut w = World::new();
        w.add_physics(PhysicsPlugins);
        w.spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 20.0).unwrap(),
            Position::from(Vec3::new(0.0, -0.5, 0.0)),
        ));
        // Both fall at 30 m/s (half a metre a step), 3 cm apart, the lower one 1.6 m above
        // the ground: it lands in the fourth step and the upper one must stop on it within
        // the step, though the two moved together until then.
        let (below, above) = kind.extent(Vec3::Y);
        let low_at = Vec3::new(0.0, below + 1.6, 0.0);
        let high_at = low_at + Vec3::Y * (above + below + 0.03);
        let (low, high) = if upper_first {
            let high = body(&mut w, kind, high_at, Vec3::NEG_Y * 30.0);
            (body(&mut w, kind, low_at, Vec3::NEG_Y * 30.0), high)
        } else {
            let low = body(&mut w, kind, low_at, Vec3::NEG_Y * 30.0);
            (low, body(&mut w, kind, high_at, Vec3::NEG_Y * 30.0))
        };
        let (mut deepest, mut touched) = (0.0f32, false);
        for _ in 0..30 {
            w.step_physics();
            if let Some(p) = w.resource::<Contacts>().pair(low, high) {
                deepest = deepest.max(p.depth);
                touched = true;
            }
        }
        println!(
            "{kind:?}, upper spawned first: {upper_first}; the upper one went {:.1} mm into the lower one",
            deepest * 1e3
        );
        assert!(touched, "{kind:?}: the upper one landed on the lower one");
        assert!(deepest < 0.05, "{kind:?}: went {deepest} m into it");
    }
}
