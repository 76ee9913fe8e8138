//! Spatial queries against exact geometry.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemState;
use glam::{Quat, Vec3};
use hooke::collision::Collider;
use hooke::collision::Sensor;
use hooke::collision::{QueryFilter, SpatialQuery};
use hooke::prelude::*;
use hooke::tools::scenes;

fn scene() -> (World, Entity, Entity) {
    let mut w = scenes::world_with(1.0 / 60.0, 4, Integrator::SymplecticEuler, Vec3::ZERO).unwrap();
    let ground = scenes::ground(&mut w).unwrap();
    // A box whose top face is at y = 1.5, centred at (2, 1, 0).
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(2.0, 1.0, 0.0)).unwrap();
    w.step_physics(); // bounding boxes are computed by the step
    (w, ground, b)
}

#[test]
fn ray_cast_hits_the_nearest_surface_with_its_normal() {
    let (mut w, ground, b) = scene();
    let mut state = SystemState::<SpatialQuery>::new(&mut w);
    let q = state.get(&w).unwrap();
    let hit = q
        .cast_ray(
            Vec3::new(2.0, 5.0, 0.0),
            Vec3::NEG_Y,
            100.0,
            &QueryFilter::default(),
        )
        .unwrap();
    assert_eq!(hit.entity, b);
    assert!((hit.distance - 3.5).abs() < 1e-4, "{}", hit.distance);
    assert!((hit.normal - Vec3::Y).length() < 1e-4);
    assert!((hit.point - Vec3::new(2.0, 1.5, 0.0)).length() < 1e-4);
    // Excluding the box, the ray reaches the ground at y = 0.
    let hit = q
        .cast_ray(
            Vec3::new(2.0, 5.0, 0.0),
            Vec3::NEG_Y,
            100.0,
            &QueryFilter::excluding(b),
        )
        .unwrap();
    assert_eq!(hit.entity, ground);
    assert!((hit.distance - 5.0).abs() < 1e-4);
    // Too short, or pointing away: nothing.
    assert!(
        q.cast_ray(
            Vec3::new(2.0, 5.0, 0.0),
            Vec3::NEG_Y,
            3.0,
            &QueryFilter::default()
        )
        .is_none()
    );
    assert!(
        q.cast_ray(
            Vec3::new(2.0, 5.0, 0.0),
            Vec3::Y,
            100.0,
            &QueryFilter::default()
        )
        .is_none()
    );
    assert!(
        q.cast_ray(Vec3::ZERO, Vec3::ZERO, 1.0, &QueryFilter::default())
            .is_none(),
        "zero direction"
    );
}

#[test]
fn shape_cast_stops_a_ball_at_contact_distance() {
    let (mut w, _, b) = scene();
    let mut state = SystemState::<SpatialQuery>::new(&mut w);
    let q = state.get(&w).unwrap();
    let ball = Collider::ball(0.25).unwrap();
    let hit = q
        .cast_shape(
            &ball,
            Vec3::new(2.0, 4.0, 0.0),
            Quat::IDENTITY,
            Vec3::NEG_Y,
            10.0,
            &QueryFilter::default(),
        )
        .unwrap();
    // The ball's bottom (y = 3.75) meets the box top (y = 1.5) after 2.25 m.
    assert_eq!(hit.entity, b);
    assert!((hit.distance - 2.25).abs() < 1e-3, "{}", hit.distance);
    assert!((hit.normal - Vec3::Y).length() < 1e-3, "{}", hit.normal);
}

#[test]
fn point_projection_and_overlaps() {
    let (mut w, ground, b) = scene();
    let sensor = w
        .spawn((
            hooke::rigid::RigidBodyBundle::fixed(Vec3::new(-3.0, 1.0, 0.0), Quat::IDENTITY)
                .unwrap(),
            Collider::ball(0.5).unwrap(),
            Sensor,
        ))
        .id();
    w.step_physics();
    let mut state = SystemState::<SpatialQuery>::new(&mut w);
    let q = state.get(&w).unwrap();
    let p = q
        .project_point(Vec3::new(2.0, 3.0, 0.0), 10.0, &QueryFilter::default())
        .unwrap();
    assert_eq!(p.entity, b);
    assert!((p.distance - 1.5).abs() < 1e-4 && !p.inside);
    let inside = q
        .project_point(Vec3::new(2.0, 1.0, 0.0), 10.0, &QueryFilter::default())
        .unwrap();
    assert!(inside.inside && inside.entity == b && inside.distance == 0.0);
    assert!(
        q.project_point(Vec3::new(2.0, 30.0, 0.0), 1.0, &QueryFilter::default())
            .is_none()
    );
    // A probe box straddling the box and the ground; the sensor only when asked for.
    let probe = Collider::cuboid(3.0, 0.3, 0.3).unwrap();
    let found = q.overlaps(
        &probe,
        Vec3::new(0.0, 0.6, 0.0),
        Quat::IDENTITY,
        &QueryFilter::default(),
    );
    let mut expected = vec![b];
    expected.sort_unstable();
    assert_eq!(found, expected);
    let all = QueryFilter {
        include_sensors: true,
        ..Default::default()
    };
    let found = q.overlaps(&probe, Vec3::new(0.0, 0.6, 0.0), Quat::IDENTITY, &all);
    let mut expected = vec![b, sensor];
    expected.sort_unstable();
    assert_eq!(found, expected);
    let low = q.overlaps(
        &probe,
        Vec3::new(0.0, 0.0, 0.0),
        Quat::IDENTITY,
        &QueryFilter::default(),
    );
    // Spanning y ∈ [−0.3, 0.3]: the ground (top at 0), not the box (bottom at 0.5).
    assert_eq!(low, vec![ground]);
}

#[test]
fn all_hits_along_a_ray_come_nearest_first_capped_and_filtered_by_a_predicate() {
    let (mut w, ground, b) = scene();
    let c = scenes::dynamic_box(&mut w, Vec3::splat(0.25), Vec3::new(2.0, 3.0, 0.0)).unwrap();
    w.step_physics();
    let mut state = SystemState::<SpatialQuery>::new(&mut w);
    let q = state.get(&w).unwrap();
    let (from, down) = (Vec3::new(2.0, 6.0, 0.0), Vec3::NEG_Y);
    let top_of = |e: Entity| {
        let y = w.get::<Position>(e).unwrap().get().y;
        if e == ground {
            0.0
        } else if e == b {
            y + 0.5
        } else {
            y + 0.25
        }
    };
    let all = q.ray_hits(from, down, 100.0, 10, &QueryFilter::default(), &|_| true);
    let order: Vec<Entity> = all.iter().map(|h| h.entity).collect();
    assert_eq!(order, vec![c, b, ground]);
    for h in &all {
        assert!(
            (h.distance - (6.0 - top_of(h.entity))).abs() < 1e-3,
            "{h:?}"
        );
        assert!((h.normal - Vec3::Y).length() < 1e-3);
    }
    // Capped at two: the two nearest.
    let two = q.ray_hits(from, down, 100.0, 2, &QueryFilter::default(), &|_| true);
    assert_eq!(two, all[..2].to_vec());
    // A predicate skips the small box: the first hit is then the big one.
    let first = q
        .cast_ray_predicate(from, down, 100.0, &QueryFilter::default(), &|e| e != c)
        .unwrap();
    assert_eq!(first.entity, b);
    // Swept, a 0.1 m ball meets the same three, nearest first, 0.1 m earlier each.
    let ball = Collider::ball(0.1).unwrap();
    let swept = q.shape_hits(
        &ball,
        (from, Quat::IDENTITY),
        down,
        100.0,
        10,
        &QueryFilter::default(),
        &|_| true,
    );
    assert_eq!(swept.iter().map(|h| h.entity).collect::<Vec<_>>(), order);
    for (s, r) in swept.iter().zip(&all) {
        assert!(
            (s.distance - (r.distance - 0.1)).abs() < 1e-3,
            "{s:?} {r:?}"
        );
    }
    // Points: inside the big box, inside nothing above it.
    assert_eq!(
        q.colliders_at_point(Vec3::new(2.0, 1.0, 0.0), &QueryFilter::default()),
        vec![b]
    );
    assert!(
        q.colliders_at_point(Vec3::new(2.0, 2.0, 0.0), &QueryFilter::default())
            .is_empty()
    );
}

#[test]
fn ray_casters_update_their_hits_every_step_from_the_body_they_ride() {
    let (mut w, ground, b) = scene();
    // A fixed caster above the box, seeing two hits; one on a ball moving down at 3 m/s
    // (no gravity here), looking down from its centre (it never sees itself).
    let eye = w
        .spawn(
            hooke::collision::RayCaster::new(Vec3::new(2.0, 5.0, 0.0), Vec3::NEG_Y, 100.0)
                .with_max_hits(2),
        )
        .id();
    let ball = scenes::dynamic_ball(&mut w, 0.3, Vec3::new(-3.0, 4.0, 0.0)).unwrap();
    w.entity_mut(ball).insert(hooke::collision::RayCaster::new(
        Vec3::ZERO,
        Vec3::NEG_Y,
        100.0,
    ));
    for _ in 0..30 {
        w.step_physics();
        let hits = &w.get::<hooke::collision::RayHits>(ball).unwrap().0;
        let y = w.get::<Position>(ball).unwrap().get().y;
        assert_eq!(hits.len(), 1);
        assert_eq!(hits[0].entity, ground);
        assert!(
            (hits[0].distance - y).abs() < 1e-4,
            "{} vs {y}",
            hits[0].distance
        );
    }
    let seen: Vec<Entity> = w
        .get::<hooke::collision::RayHits>(eye)
        .unwrap()
        .0
        .iter()
        .map(|h| h.entity)
        .collect();
    assert_eq!(seen, vec![b, ground]);
}
