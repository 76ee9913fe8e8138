//! Contacts against closed forms: bounce height, incline acceleration, stacking, tunnelling.

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::collision::Collider;
use hooke::collision::CollisionLayers;
use hooke::collision::ContactEnded;
use hooke::collision::ContactStarted;
use hooke::collision::Contacts;
use hooke::collision::Friction;
use hooke::collision::Restitution;
use hooke::collision::Sensor;
use hooke::prelude::*;
use hooke::rigid::RigidBodyBundle;
use hooke::rigid::Rotation;
use hooke::tools::scenes;

const G: f32 = 9.81;

/// Sleeping off: a sleeping body cannot drift, so with it on a stability test could pass
/// without measuring anything.
fn world(substeps: u32) -> World {
    crate::common::awake_world(1.0 / 60.0, substeps, Vec3::new(0.0, -G, 0.0))
}

fn pos(w: &World, e: Entity) -> Vec3 {
    w.get::<Position>(e).unwrap().get()
}

fn vel(w: &World, e: Entity) -> Vec3 {
    w.get::<LinearVelocity>(e).unwrap().get()
}

#[test]
fn ball_dropped_from_one_metre_with_e_08_bounces_to_064() {
    // 8 substeps. At the default 4 the apex is 0.627 m (−2.1 %, measured): symplectic Euler
    // itself loses g·h·t/2 ≈ 7 mm of height on the way up at h = 1/240, and before the
    // impact-speed extrapolation (see `impact_speed`) it was 0.617 m.
    let mut w = world(8);
    let ground = scenes::ground(&mut w).unwrap();
    let r = 0.1;
    let ball = scenes::dynamic_ball(&mut w, r, Vec3::new(0.0, 1.0 + r, 0.0)).unwrap();
    w.entity_mut(ball).insert(Restitution(0.8));
    w.entity_mut(ground).insert(Restitution(0.8));
    let (mut bounced, mut apex) = (false, 0.0f32);
    for _ in 0..150 {
        w.step_physics();
        let v = vel(&w, ball).y;
        if v > 0.0 {
            bounced = true;
        }
        if bounced {
            apex = apex.max(pos(&w, ball).y - r);
        }
        if bounced && v < 0.0 {
            break;
        }
    }
    println!("bounce apex {apex:.4} m (e² h = 0.64 m)");
    assert!((apex - 0.64).abs() < 0.02 * 0.64, "apex {apex}");
}

/// A box on a ramp tilted by `angle` with friction μ on both; returns its displacement along
/// the slope after `seconds` from rest.
fn slide(angle: f32, mu: f32, seconds: f32) -> f32 {
    let mut w = world(4);
    let q = Quat::from_rotation_z(angle);
    let ramp = w
        .spawn((
            RigidBodyBundle::fixed(Vec3::ZERO, q).unwrap(),
            Collider::cuboid(20.0, 0.5, 5.0).unwrap(),
            Friction(mu),
        ))
        .id();
    let _ = ramp;
    let up = q * Vec3::Y;
    // Flat (1 × 0.5 × 1 m), so it slides rather than tips (tipping needs tan θ > 2).
    let start = up * 0.75 + q * Vec3::new(5.0, 0.0, 0.0);
    let b = scenes::dynamic_box(&mut w, Vec3::new(0.5, 0.25, 0.5), start).unwrap();
    w.entity_mut(b).insert((Friction(mu), Rotation(q)));
    // Settle onto the slope first: the box starts resting on the surface.
    let x0 = pos(&w, b);
    for _ in 0..(seconds * 60.0) as usize {
        w.step_physics();
    }
    let down = q * Vec3::NEG_X;
    (pos(&w, b) - x0).dot(down)
}

#[test]
fn box_on_a_30_degree_incline_slides_at_the_coulomb_acceleration() {
    let angle = 30f32.to_radians();
    let t = 1.0;
    let d = slide(angle, 0.3, t);
    let a = 2.0 * d / (t * t);
    let expected = G * (angle.sin() - 0.3 * angle.cos());
    println!("incline μ = 0.3: a = {a:.4} m/s² (g(sin θ − μ cos θ) = {expected:.4})");
    assert!((a - expected).abs() < 0.02 * expected, "a = {a}");
}

#[test]
fn box_on_a_30_degree_incline_with_mu_06_stays_put() {
    let d = slide(30f32.to_radians(), 0.6, 2.0);
    println!("incline μ = 0.6: moved {d:.5} m in 2 s");
    assert!(d.abs() < 1e-3, "moved {d}");
}

#[test]
fn stack_of_ten_boxes_stands_for_ten_seconds() {
    // 8 substeps allow the 60 Hz contact; at the default 4 the contacts run at 30 Hz and the
    // column compresses 23.8 mm under its own weight (measured), over the 1 cm allowed.
    let mut w = world(8);
    let boxes = scenes::box_column(&mut w, 10).unwrap();
    w.step_physics();
    let top0 = pos(&w, boxes[9]);
    for _ in 0..600 {
        w.step_physics();
    }
    let drift = (pos(&w, boxes[9]) - top0).length();
    println!("10-box stack: top drift {:.2} mm over 10 s", drift * 1000.0);
    assert!(drift < 0.01, "drift {drift}");
}

#[test]
fn fast_small_ball_does_not_tunnel_through_a_thin_wall() {
    let mut w = world(1);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::new(2.0, 1.0, 0.0), Quat::IDENTITY).unwrap(),
        Collider::cuboid(0.025, 2.0, 2.0).unwrap(),
    ));
    let ball = scenes::dynamic_ball(&mut w, 0.05, Vec3::new(0.0, 1.0, 0.0)).unwrap();
    w.entity_mut(ball).insert(GravityScale(0.0));
    w.get_mut::<LinearVelocity>(ball).unwrap().0 = glam::Vec3A::new(100.0, 0.0, 0.0);
    for _ in 0..30 {
        w.step_physics();
        assert!(pos(&w, ball).x < 2.0, "tunnelled to {}", pos(&w, ball));
    }
    println!(
        "fast ball stopped at x = {:.4} (wall face at 1.975)",
        pos(&w, ball).x
    );
}

fn count<M: bevy_ecs::message::Message>(
    w: &World,
    cursor: &mut bevy_ecs::message::MessageCursor<M>,
) -> usize {
    cursor.read(w.resource::<Messages<M>>()).count()
}

#[test]
fn contact_events_start_and_end_once_each() {
    let mut w = world(4);
    let ground = scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 1.0, 0.0)).unwrap();
    let mut started = w.resource::<Messages<ContactStarted>>().get_cursor();
    let mut ended = w.resource::<Messages<ContactEnded>>().get_cursor();
    let (mut s, mut e) = (0, 0);
    for _ in 0..120 {
        w.step_physics();
        s += count(&w, &mut started);
        e += count(&w, &mut ended);
    }
    assert_eq!((s, e), (1, 0), "landing and resting");
    assert!(w.resource::<Contacts>().are_touching(ground, b));
    w.entity_mut(b)
        .insert(ExternalImpulse(Vec3::new(0.0, 8000.0, 0.0)));
    for _ in 0..30 {
        w.step_physics();
        s += count(&w, &mut started);
        e += count(&w, &mut ended);
    }
    assert_eq!((s, e), (1, 1), "lifted off once");
    assert!(!w.resource::<Contacts>().are_touching(ground, b));
}

#[test]
fn heavy_box_on_light_box_at_1_to_100_stays_stable() {
    // 8 substeps: at the default 4 the pair stays bounded (15 s measured) but compresses
    // 57 mm under the 30 Hz contacts and keeps a 1–12 cm/s jitter; at 8 it comes to rest.
    let mut w = world(8);
    scenes::ground(&mut w).unwrap();
    let light = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    let heavy = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 1.5, 0.0)).unwrap();
    let m = w.get::<Mass>(light).unwrap().value();
    w.entity_mut(heavy).insert(Mass::new(100.0 * m).unwrap());
    // Settle for two seconds (the soft contacts compress under the load), then hold still.
    for _ in 0..120 {
        w.step_physics();
    }
    let y_settled = pos(&w, heavy).y;
    let (mut creep, mut speed) = (0.0f32, 0.0f32);
    for _ in 0..180 {
        w.step_physics();
        creep = creep.max((pos(&w, heavy).y - y_settled).abs());
        speed = speed
            .max(vel(&w, light).length())
            .max(vel(&w, heavy).length());
    }
    println!(
        "1:100 stack: compressed {:.1} mm while settling, then creep {:.3} mm and max speed {speed:.4} m/s over 3 s",
        (1.5 - y_settled) * 1000.0,
        creep * 1000.0
    );
    assert!(creep < 1e-3, "creep {creep}");
    assert!(speed < 0.01, "jitter {speed}");
    assert!(
        (pos(&w, light).y - 0.5).abs() < 0.01,
        "light box crushed: {}",
        pos(&w, light)
    );
}

#[test]
fn sensors_report_overlaps_without_pushing_and_layers_filter() {
    let mut w = world(4);
    let ground = scenes::ground(&mut w).unwrap();
    w.entity_mut(ground).insert(CollisionLayers {
        memberships: 0b01,
        filters: u32::MAX,
    });
    let zone = w
        .spawn((
            RigidBodyBundle::fixed(Vec3::new(0.0, 2.0, 0.0), Quat::IDENTITY).unwrap(),
            Collider::cuboid(1.0, 0.5, 1.0).unwrap(),
            Sensor,
        ))
        .id();
    let ghost_layers = CollisionLayers {
        memberships: 0b10,
        filters: 0b10,
    };
    let ball = scenes::dynamic_ball(&mut w, 0.2, Vec3::new(0.0, 4.0, 0.0)).unwrap();
    let ghost = scenes::dynamic_ball(&mut w, 0.2, Vec3::new(3.0, 1.0, 0.0)).unwrap();
    w.entity_mut(ghost).insert(ghost_layers);
    let mut seen_in_zone = false;
    for _ in 0..90 {
        w.step_physics();
        seen_in_zone |= w.resource::<Contacts>().are_touching(zone, ball);
    }
    assert!(seen_in_zone, "the sensor never reported the ball");
    // The ball fell through the sensor to the ground; the ghost (other layer) fell through it.
    assert!((pos(&w, ball).y - 0.2).abs() < 0.02, "{}", pos(&w, ball));
    assert!(
        pos(&w, ghost).y < -1.0,
        "layers did not filter: {}",
        pos(&w, ghost)
    );
}

#[test]
fn particles_with_a_radius_collide_one_way_with_static_and_two_way_with_dynamic() {
    let mut w = world(4);
    scenes::ground(&mut w).unwrap();
    let grain = w
        .spawn((
            ParticleBundle::new(Vec3::new(5.0, 1.0, 0.0), Vec3::ZERO, 0.1).unwrap(),
            Collider::ball(0.05).unwrap(),
        ))
        .id();
    // A particle flying into a resting box pushes it.
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.1), Vec3::new(0.0, 0.1, 0.0)).unwrap();
    let shot = w
        .spawn((
            ParticleBundle::new(Vec3::new(-1.0, 0.1, 0.0), Vec3::new(20.0, 0.0, 0.0), 2.0).unwrap(),
            Collider::ball(0.05).unwrap(),
            GravityScale(0.0),
        ))
        .id();
    for _ in 0..60 {
        w.step_physics();
    }
    assert!(
        (pos(&w, grain).y - 0.05).abs() < 0.01,
        "grain at {}",
        pos(&w, grain)
    );
    assert!(pos(&w, b).x > 0.1, "the box was not pushed: {}", pos(&w, b));
    assert!(vel(&w, shot).x < 20.0, "the particle was not slowed");
}

#[test]
fn pile_of_a_thousand_boxes_settles_without_exploding() {
    let mut w = world(4);
    let boxes = scenes::box_pile(&mut w, 1000).unwrap();
    for _ in 0..600 {
        w.step_physics();
    }
    let mut max_v = 0.0f32;
    for _ in 0..60 {
        w.step_physics();
        for &b in &boxes {
            max_v = max_v.max(vel(&w, b).length());
        }
    }
    let lowest = boxes
        .iter()
        .map(|&b| pos(&w, b).y)
        .fold(f32::INFINITY, f32::min);
    let highest = boxes
        .iter()
        .map(|&b| pos(&w, b).y)
        .fold(f32::NEG_INFINITY, f32::max);
    println!(
        "1000-box pile: max speed {max_v:.4} m/s over the second after 10 s, centres from {lowest:.3} to {highest:.2} m"
    );
    assert!(max_v < 0.05, "max speed {max_v}");
    assert!(lowest > 0.3, "a box sank into the ground: {lowest}");
    assert_eq!(w.resource::<PhysicsDiagnostics>().counts.quarantined, 0);
}

#[test]
fn pyramid_of_twenty_rows_holds_at_the_default_substeps() {
    let mut w = world(4);
    let boxes = scenes::pyramid(&mut w, 20).unwrap();
    let top = *boxes.last().unwrap();
    for _ in 0..60 {
        w.step_physics();
    }
    let settled = pos(&w, top);
    // The pyramid is one box deep: its top leans out of plane (z) as it settles, so creep is
    // the in-plane drift and the lean is bounded apart, and must not grow. Measured: creep
    // 0.52 mm; the lean peaks at 5.0 mm in the first 3 s and holds at 3.0 mm from 20 s on
    // (0.84 mm before the solver took each face's corners in one order, which made columns
    // of 100 boxes stand; rapier's top sways about 1.2 mm, sampled every 3.3 s).
    let mut sway = 0.0f32;
    let mut first_window = 0.0f32;
    let mut last_window = 0.0f32;
    for step in 0..540 {
        w.step_physics();
        let lean = (pos(&w, top).z - settled.z).abs();
        sway = sway.max(lean);
        if step < 180 {
            first_window = first_window.max(lean);
        } else if step >= 360 {
            last_window = last_window.max(lean);
        }
    }
    let d = pos(&w, top) - settled;
    let creep = Vec3::new(d.x, d.y, 0.0).length();
    println!(
        "20-row pyramid: top creeps {:.2} mm in plane over 9 s after settling, leans {:.2} mm out of plane at most ({:.2} mm in the first 3 s, {:.2} in the last)",
        creep * 1000.0,
        sway * 1000.0,
        first_window * 1000.0,
        last_window * 1000.0
    );
    assert!(creep < 2e-3, "creep {creep}");
    assert!(sway < 1e-2, "sway {sway}");
    assert!(
        last_window <= first_window,
        "the lean grows: {first_window} then {last_window}"
    );
}

#[test]
fn the_pile_example_scene_runs_clean_and_comes_to_rest_on_the_ramp_and_ground() {
    let mut w = scenes::world_with(
        1.0 / 60.0,
        4,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -G, 0.0),
    )
    .unwrap();
    let (boxes, balls) = scenes::pile_scene(&mut w, 60, 30).unwrap();
    for _ in 0..300 {
        w.step_physics();
    }
    assert_eq!(w.resource::<PhysicsDiagnostics>().counts.quarantined, 0);
    for &e in boxes.iter().chain(&balls) {
        let p = pos(&w, e);
        assert!(p.is_finite() && p.y > 0.0, "{e} fell through to {p}");
    }
}

#[test]
fn nan_in_one_box_of_a_stack_does_not_cross_the_contacts() {
    let mut w = world(4);
    let boxes = scenes::box_column(&mut w, 3).unwrap();
    for _ in 0..30 {
        w.step_physics();
    }
    // Game code writes NaN into the middle box's velocity through a mutable borrow.
    w.get_mut::<LinearVelocity>(boxes[1]).unwrap().0 = glam::Vec3A::NAN;
    for _ in 0..60 {
        w.step_physics();
    }
    assert_only_the_middle_box_is_quarantined(&w, &boxes);
}

/// The middle box of a 3-column is quarantined; its neighbours stay finite and live.
fn assert_only_the_middle_box_is_quarantined(w: &World, boxes: &[Entity]) {
    assert!(
        w.get::<hooke::core::quarantine::Quarantined>(boxes[1])
            .is_some()
    );
    for &b in [boxes[0], boxes[2]].iter() {
        assert!(
            pos(w, b).is_finite() && vel(w, b).is_finite(),
            "NaN crossed into {b}"
        );
        assert!(
            w.get::<hooke::core::quarantine::Quarantined>(b).is_none(),
            "{b} was quarantined too"
        );
    }
}

#[derive(Component)]
struct Poisoned;

fn poison(mut bodies: Query<&mut Force, With<Poisoned>>) {
    for mut f in &mut bodies {
        f.0 = glam::Vec3A::NAN;
    }
}

#[test]
fn nan_born_mid_step_from_a_force_does_not_cross_the_contacts() {
    let mut w = world(4);
    let boxes = scenes::box_column(&mut w, 3).unwrap();
    hooke::core::schedule::add_force_systems(&mut w, || {
        poison.in_set(hooke::core::schedule::ForceSystems::User)
    });
    for _ in 0..30 {
        w.step_physics();
    }
    // From now on a game force system writes NaN into the middle box, inside the substeps.
    w.entity_mut(boxes[1]).insert(Poisoned);
    for _ in 0..30 {
        w.step_physics();
    }
    assert_only_the_middle_box_is_quarantined(&w, &boxes);
}

#[test]
fn a_box_spun_on_the_ground_stops_at_the_twist_friction_rate() {
    // Twist friction about the normal is limited to μ ρ N, with ρ the contact points' mean
    // distance from their centre: the four corners of a unit face, ρ = √2/2. The spin then
    // falls at α = μ N ρ / I, I = m a²/6, and stops after t = ω₀ a² / (6 μ g ρ) = 0.240 s
    // for ω₀ = 5 rad/s, μ = 0.5. (Uniform pressure over the face would give ρ = 0.383 a.)
    let mut w = world(4);
    scenes::ground(&mut w).unwrap();
    let b = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(0.0, 0.5, 0.0)).unwrap();
    for _ in 0..30 {
        w.step_physics();
    }
    let inertia = *w.get::<hooke::rigid::Inertia>(b).unwrap();
    let q = w.get::<Rotation>(b).unwrap().0;
    let omega0 = 5.0;
    w.get_mut::<hooke::rigid::AngularMomentum>(b).unwrap().0 =
        inertia.angular_momentum(q, glam::Vec3A::new(0.0, omega0, 0.0));
    let expected = omega0 / (6.0 * 0.5 * G * std::f32::consts::FRAC_1_SQRT_2);
    let mut stopped = None;
    for step in 1..=60 {
        w.step_physics();
        let spin = w.get::<AngularVelocity>(b).unwrap().0.y;
        if stopped.is_none() && spin.abs() < 0.01 {
            stopped = Some(step as f32 / 60.0);
        }
    }
    let t = stopped.expect("the box kept spinning");
    println!("spin stopped after {t:.3} s (model {expected:.3} s)");
    assert!(
        (t - expected).abs() < 0.1 * expected + 1.0 / 60.0,
        "{t} vs {expected}"
    );
    assert!(pos(&w, b).is_finite() && (pos(&w, b).y - 0.5).abs() < 0.01);
}
