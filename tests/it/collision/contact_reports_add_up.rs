//! `ContactReport`s carry points, normals and the step's total impulse, and those impulses
//! are the ones that moved the bodies: a resting box's reports carry its weight, a box held
//! on a slope by friction carries the slope's share in the friction part, and the reports of
//! a landing add up to the ball's change of momentum less gravity's impulse. Each in both
//! spawn orders (which decides which body is `a`).

use crate::common;
use bevy_ecs::message::MessageCursor;
use bevy_ecs::prelude::*;
use hooke::prelude::*;

/// The reports of this step for the pairs containing `body`, with the sign that turns a
/// report's impulses (on `b`) into those on `body`.
fn reports_on(
    world: &World,
    cursor: &mut MessageCursor<ContactReport>,
    body: Entity,
) -> Vec<(ContactReport, f32)> {
    cursor
        .read(world.resource::<Messages<ContactReport>>())
        .filter(|r| r.a == body || r.b == body)
        .map(|r| (r.clone(), if r.b == body { 1.0 } else { -1.0 }))
        .collect()
}

fn ground(world: &mut World, tilt: f32) -> Entity {
    world
        .spawn((
            RigidBody::Static,
            Collider::cuboid(10.0, 0.5, 10.0).unwrap(),
            // Its top face passes through the origin.
            Position::from(Quat::from_rotation_z(tilt) * Vec3::new(0.0, -0.5, 0.0)),
            Rotation(Quat::from_rotation_z(tilt)),
            Friction(0.8),
        ))
        .id()
}

fn crate_on(world: &mut World, tilt: f32) -> Entity {
    let up = Quat::from_rotation_z(tilt) * Vec3::Y;
    world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Mass::new(2.0).unwrap(),
            Position::from(up * 0.5),
            Rotation(Quat::from_rotation_z(tilt)),
            Friction(0.8),
            ContactReporting::default(),
        ))
        .id()
}

/// A 2 kg box at rest on a slope of `tilt`, after 1 s: the step's reports, dt, and the
/// pair's impulse as `Contacts::pair` keeps it (its last substep's) with the substep count.
fn resting(tilt: f32, box_first: bool) -> (Vec<(ContactReport, f32)>, f32, (f32, u32)) {
    let mut w = common::default_world();
    // Asleep, a body's contacts are not solved and not reported: keep it awake to watch the
    // load it keeps carrying.
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let b = if box_first {
        let b = crate_on(&mut w, tilt);
        ground(&mut w, tilt);
        b
    } else {
        ground(&mut w, tilt);
        crate_on(&mut w, tilt)
    };
    let mut cursor = w.resource::<Messages<ContactReport>>().get_cursor();
    for _ in 0..60 {
        w.step_physics();
        reports_on(&w, &mut cursor, b);
    }
    w.step_physics();
    let reports = reports_on(&w, &mut cursor, b);
    let kept = reports.first().map_or(0.0, |(r, _)| {
        w.resource::<Contacts>()
            .pair(r.a, r.b)
            .map_or(0.0, |p| p.normal_impulse)
    });
    let time = w.resource::<PhysicsTime>();
    (reports, time.dt(), (kept, time.substeps()))
}

#[test]
fn a_resting_box_reports_its_weight_at_its_four_corners() {
    for box_first in [true, false] {
        let (reports, dt, (last_substep, substeps)) = resting(0.0, box_first);
        assert_eq!(reports.len(), 1, "one pair, one report");
        let (r, sign) = &reports[0];
        let on_box = *sign * r.impulse;
        let weight = 2.0 * 9.81 * dt;
        assert!(
            (on_box.y - weight).abs() < 0.01 * weight,
            "impulse {on_box} vs m g dt {weight}"
        );
        assert!(
            on_box.x.abs() + on_box.z.abs() < 1e-3 * weight,
            "no sideways load: {on_box}"
        );
        assert!((r.normal_impulse - weight).abs() < 0.01 * weight);
        assert!(
            (r.force().y.abs() - 2.0 * 9.81).abs() < 0.2,
            "force {}",
            r.force()
        );
        assert_eq!(r.points.len(), 4, "the four corners");
        // `Contacts::pair` keeps the last substep's impulse: at rest, a substep's share.
        let share = weight / substeps as f32;
        assert!(
            (last_substep - share).abs() < 0.01 * share,
            "last substep {last_substep} vs m g h {share}"
        );
        for p in &r.points {
            assert!(p.position.y.abs() < 0.01, "on the ground: {}", p.position);
            assert!(
                p.position.x.abs() > 0.45 && p.position.z.abs() > 0.45,
                "a corner: {}",
                p.position
            );
            assert!(p.normal.y.abs() > 0.999);
            assert!(
                p.normal_impulse > 0.15 * weight,
                "each corner carries a share"
            );
        }
    }
}

#[test]
fn a_box_held_by_friction_on_a_slope_reports_the_slope_share_as_friction() {
    let tilt = 20f32.to_radians();
    for box_first in [true, false] {
        let (reports, dt, _) = resting(tilt, box_first);
        assert_eq!(reports.len(), 1);
        let (r, sign) = &reports[0];
        let on_box = *sign * r.impulse;
        let weight = 2.0 * 9.81 * dt;
        // The ground holds the box still: its impulse is the weight's, straight up.
        assert!(
            (on_box - Vec3::Y * weight).length() < 0.01 * weight,
            "impulse {on_box}"
        );
        // Split along the slope: the normal part m g cos θ, friction m g sin θ.
        let slope_normal = Quat::from_rotation_z(tilt) * Vec3::Y;
        let friction = *sign * r.friction_impulse();
        assert!(
            (r.normal_impulse - weight * tilt.cos()).abs() < 0.01 * weight,
            "normal {} vs {}",
            r.normal_impulse,
            weight * tilt.cos()
        );
        assert!(
            (friction.length() - weight * tilt.sin()).abs() < 0.01 * weight,
            "friction {friction} vs {}",
            weight * tilt.sin()
        );
        assert!(
            friction.dot(slope_normal).abs() < 1e-3 * weight,
            "friction lies in the slope"
        );
    }
}

#[test]
fn a_landing_reports_the_momentum_it_took() {
    for ball_first in [true, false] {
        let mut w = common::default_world();
        let spawn_ball = |w: &mut World| {
            w.spawn((
                RigidBody::Dynamic,
                Collider::ball(0.25).unwrap(),
                Mass::new(3.0).unwrap(),
                Position::from(Vec3::new(0.0, 2.0, 0.0)),
                LinearVelocity::from(Vec3::new(1.0, 0.0, 0.0)),
                ContactReporting::default(),
            ))
            .id()
        };
        let ball = if ball_first {
            let b = spawn_ball(&mut w);
            ground(&mut w, 0.0);
            b
        } else {
            ground(&mut w, 0.0);
            spawn_ball(&mut w)
        };
        let mut cursor = w.resource::<Messages<ContactReport>>().get_cursor();
        let dt = w.resource::<PhysicsTime>().dt();
        let mut total = Vec3::ZERO;
        // (step, velocity before it) of the first report, and (step, velocity after) of the
        // last.
        let (mut first, mut last) = (None, (0, Vec3::ZERO));
        for step in 0..90 {
            let v0 = common::v(&w, ball);
            w.step_physics();
            let reports = reports_on(&w, &mut cursor, ball);
            if !reports.is_empty() {
                first.get_or_insert((step, v0));
                total += reports.iter().map(|(r, s)| *s * r.impulse).sum::<Vec3>();
                if std::env::var("DEBUG_REPORTS").is_ok() {
                    let j: Vec3 = reports.iter().map(|(r, s)| *s * r.impulse).sum();
                    let dv =
                        3.0 * (common::v(&w, ball) - v0) - Vec3::new(0.0, -9.81 * 3.0 * dt, 0.0);
                    eprintln!("{step} J {j} mdv {dv} n {}", reports[0].0.normal);
                }
                last = (step, common::v(&w, ball));
            }
        }
        let (start, v_before) = first.expect("it landed");
        let (end, v_after) = last;
        // From the first report to the last: m Δv = Σ J + m g T.
        let steps = (end - start + 1) as f32;
        let gravity = Vec3::new(0.0, -9.81, 0.0) * 3.0 * dt * steps;
        let expected = 3.0 * (v_after - v_before) - gravity;
        assert!(
            (total - expected).length() < 0.01 * expected.length(),
            "reported {total} vs m Δv − m g T = {expected} (ball first: {ball_first})"
        );
        // The landing took the fall's momentum, m √(2 g h), at least.
        assert!(total.y > 3.0 * (2.0 * 9.81 * 1.75f32).sqrt());
    }
}

#[test]
fn a_threshold_reports_the_impact_and_not_the_rest() {
    let mut w = common::default_world();
    // Awake, so that only the threshold can silence the resting contact.
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    ground(&mut w, 0.0);
    let b = w
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            Mass::new(2.0).unwrap(),
            Position::from(Vec3::new(0.0, 3.0, 0.0)),
            ContactReporting::above(0.5),
        ))
        .id();
    let mut cursor = w.resource::<Messages<ContactReport>>().get_cursor();
    let mut per_step = Vec::new();
    for _ in 0..120 {
        w.step_physics();
        per_step.push(reports_on(&w, &mut cursor, b).len());
    }
    let first = per_step
        .iter()
        .position(|&n| n > 0)
        .expect("the impact is reported");
    // A 2 kg box falling 2.5 m lands with 14 N·s; resting, it carries 0.33 N·s a step.
    assert!(
        per_step[first + 10..].iter().all(|&n| n == 0),
        "{per_step:?}"
    );
}

#[test]
fn a_negative_threshold_is_a_typed_quarantine() {
    let mut w = common::default_world();
    let b = common::dynamic(&mut w, Collider::ball(0.5).unwrap(), Vec3::Y);
    w.entity_mut(b)
        .insert(ContactReporting { min_impulse: -1.0 });
    w.step_physics();
    assert!(w.get::<Quarantined>(b).is_some());
}
