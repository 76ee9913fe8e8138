//! Pendulums on joints: periods against the closed forms, energy that never grows, anchors
//! that stay together. Every world is `PhysicsPlugins` and nothing else.

use bevy_ecs::prelude::*;
use hooke::prelude::*;

use crate::common::default_world;

/// Half extents of the rod (m): 0.1 × 1 × 0.1.
const HALF: Vec3 = Vec3::new(0.05, 0.5, 0.05);

/// K(k), the complete elliptic integral of the first kind, by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

/// The period of a rigid pendulum released from rest at `amplitude` (rad): 4 √(I_p/(m g d))
/// K(sin(θ₀/2)), with I_p the moment of inertia about the pivot and d the pivot's distance
/// from the centre of mass. For the rod hung at one end, I_p/m = (L² + a²)/12 + d².
fn rod_period(amplitude: f64) -> f64 {
    let (a, l, d) = (
        2.0 * f64::from(HALF.x),
        2.0 * f64::from(HALF.y),
        f64::from(HALF.y),
    );
    let ip_over_m = (l * l + a * a) / 12.0 + d * d;
    4.0 * (ip_over_m / (9.81 * d)).sqrt() * elliptic_k((0.5 * amplitude).sin())
}

/// A rod hinged at its top end to the world point (0, 2, 0), released from rest at
/// `amplitude` (rad) about z.
fn hinged_rod(world: &mut World, amplitude: f32) -> Entity {
    let pivot = Vec3::new(0.0, 2.0, 0.0);
    let turn = Quat::from_rotation_z(amplitude);
    let rod = world
        .spawn((
            RigidBody::Dynamic,
            Collider::cuboid(HALF.x, HALF.y, HALF.z).unwrap(),
            Position((pivot + turn * Vec3::new(0.0, -HALF.y, 0.0)).into()),
            Rotation(turn),
        ))
        .id();
    world.spawn(
        RevoluteJoint::to_world(rod, Vec3::Z).with_anchors(pivot, Vec3::new(0.0, HALF.y, 0.0)),
    );
    rod
}

/// The rod's swing angle from the vertical (rad) and its top anchor's distance from the
/// pivot (m).
fn swing(world: &World, rod: Entity) -> (f64, f32) {
    let x = world.get::<Position>(rod).unwrap().0;
    let q = world.get::<Rotation>(rod).unwrap().0;
    let pivot = Vec3A::new(0.0, 2.0, 0.0);
    let d = x - pivot;
    let top = x + q * Vec3A::new(0.0, HALF.y, 0.0);
    (
        f64::from(d.x).atan2(f64::from(-d.y)),
        (top - pivot).length(),
    )
}

/// Measured period (s): the mean time between successive downward zero crossings of the
/// angle over `swings` periods (linear interpolation inside a step); with the largest
/// anchor drift seen (m).
fn measured_period(amplitude: f32, swings: usize) -> (f64, f32) {
    let mut world = default_world();
    let rod = hinged_rod(&mut world, amplitude);
    let dt = f64::from(world.resource::<PhysicsTime>().dt());
    let (mut last, mut drift) = (swing(&world, rod).0, 0.0_f32);
    let mut crossings = Vec::new();
    let mut t = 0.0;
    while crossings.len() <= swings && t < 60.0 {
        world.step_physics();
        t += dt;
        let (theta, gap) = swing(&world, rod);
        drift = drift.max(gap);
        if last > 0.0 && theta <= 0.0 {
            crossings.push(t - dt * theta / (theta - last));
        }
        last = theta;
        assert!(world.get::<Quarantined>(rod).is_none());
    }
    let n = crossings.len() - 1;
    ((crossings[n] - crossings[0]) / n as f64, drift)
}

#[test]
fn a_rod_on_a_hinge_swings_with_the_period_of_its_inertia_about_the_pivot() {
    for (degrees, tolerance) in [(10.0_f32, 0.001), (90.0, 0.001)] {
        let amplitude = degrees.to_radians();
        let (period, drift) = measured_period(amplitude, 5);
        let exact = rod_period(f64::from(amplitude));
        let error = (period / exact - 1.0).abs();
        assert!(
            error < tolerance,
            "{degrees}°: period {period:.5} s against {exact:.5} s ({:.3} %)",
            100.0 * error
        );
        assert!(drift < 0.01, "{degrees}°: the anchor drifted {drift} m");
    }
}

/// What a chain run measured: energy after the first step, the highest and the last over
/// 60 s more (J), and the widest any anchor pair parted (m).
struct ChainRun {
    start: f64,
    highest: f64,
    end: f64,
    drift: f32,
}

/// A chain of `links` rods on ball joints hung from (0, 3, 0), released from rest at 1.2 rad
/// from the vertical, each rod below the first spinning at 0.4 k rad/s about the vertical
/// (so the motion is three-dimensional); no damping anywhere.
fn hooke_chain(links: usize) -> ChainRun {
    hooke_chain_in(default_world(), links, 60.0, false)
}

/// [`hooke_chain`] in `world` for `seconds`, the rods and joints spawned from the bottom up
/// when `reversed`.
fn hooke_chain_in(mut world: World, links: usize, seconds: f32, reversed: bool) -> ChainRun {
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let turn = Quat::from_rotation_z(1.2);
    let order: Vec<usize> = if reversed {
        (0..links).rev().collect()
    } else {
        (0..links).collect()
    };
    let mut rods = vec![Entity::PLACEHOLDER; links];
    for &k in &order {
        let top = pivot + turn * Vec3::new(0.0, -2.0 * HALF.y * k as f32, 0.0);
        rods[k] = world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(HALF.x, HALF.y, HALF.z).unwrap(),
                Position((top + turn * Vec3::new(0.0, -HALF.y, 0.0)).into()),
                Rotation(turn),
                AngularVelocity(Vec3A::new(0.0, 0.4 * k as f32, 0.0)),
            ))
            .id();
    }
    for &k in &order {
        let rod = rods[k];
        let joint = if k == 0 {
            SphericalJoint::to_world(rod).with_anchors(pivot, Vec3::Y * HALF.y)
        } else {
            SphericalJoint::new(rods[k - 1], rod).with_anchors(-Vec3::Y * HALF.y, Vec3::Y * HALF.y)
        };
        world.spawn(joint);
    }
    let energy = |world: &World| -> f64 {
        rods.iter()
            .map(|&e| {
                let m = f64::from(world.get::<Mass>(e).unwrap().value());
                let x = world.get::<Position>(e).unwrap().0;
                let v = world.get::<LinearVelocity>(e).unwrap().0;
                let w = world.get::<AngularVelocity>(e).unwrap().0;
                let l = world.get::<hooke::rigid::AngularMomentum>(e).unwrap().0;
                0.5 * m * f64::from(v.length_squared())
                    + 0.5 * f64::from(w.dot(l))
                    + m * 9.81 * f64::from(x.y)
            })
            .sum()
    };
    let drift = |world: &World| -> f32 {
        let end_of = |e: Entity, y: f32| {
            world.get::<Position>(e).unwrap().0
                + world.get::<Rotation>(e).unwrap().0 * Vec3A::new(0.0, y, 0.0)
        };
        let mut worst = (end_of(rods[0], HALF.y) - Vec3A::from(pivot)).length();
        for w in rods.windows(2) {
            worst = worst.max((end_of(w[0], -HALF.y) - end_of(w[1], HALF.y)).length());
        }
        worst
    };
    world.step_physics();
    let start = energy(&world);
    let mut run = ChainRun {
        start,
        highest: start,
        end: start,
        drift: 0.0,
    };
    let dt = world.resource::<PhysicsTime>().dt();
    for _ in 0..(seconds / dt).round() as usize {
        world.step_physics();
        run.highest = run.highest.max(energy(&world));
        run.drift = run.drift.max(drift(&world));
    }
    run.end = energy(&world);
    for &rod in &rods {
        assert!(world.get::<Quarantined>(rod).is_none());
    }
    run
}

/// rapier 0.36's chain, built as [`hooke_chain`]'s at its defaults (60 Hz, 4 substeps):
/// energy after one step and after 60 s more (J).
fn rapier_chain(links: usize) -> (f64, f64) {
    use rapier3d::prelude as rp;
    let mut world = rp::PhysicsWorld::new();
    world.gravity = rp::Vector::new(0.0, -9.81, 0.0);
    world.integration_parameters.dt = 1.0 / 60.0;
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let turn = Quat::from_rotation_z(1.2);
    let ground = world.insert_body(rp::RigidBodyBuilder::fixed());
    let mut above = None;
    let mut rods = Vec::new();
    for k in 0..links {
        let top = pivot + turn * Vec3::new(0.0, -2.0 * HALF.y * k as f32, 0.0);
        let centre = top + turn * Vec3::new(0.0, -HALF.y, 0.0);
        let (rod, _) = world.insert(
            rp::RigidBodyBuilder::dynamic()
                .translation(centre)
                .rotation(Vec3::new(0.0, 0.0, 1.2))
                .angvel(Vec3::new(0.0, 0.4 * k as f32, 0.0)),
            rp::ColliderBuilder::cuboid(HALF.x, HALF.y, HALF.z)
                .density(1000.0)
                .collision_groups(rp::InteractionGroups::none()),
        );
        let anchor = match above {
            None => pivot,
            Some(_) => -Vec3::Y * HALF.y,
        };
        let joint = rp::SphericalJointBuilder::new()
            .local_anchor1(anchor)
            .local_anchor2(Vec3::Y * HALF.y);
        world.insert_impulse_joint(above.unwrap_or(ground), rod, joint);
        above = Some(rod);
        rods.push(rod);
    }
    let energy = |world: &rp::PhysicsWorld| -> f64 {
        rods.iter()
            .map(|&h| {
                let b = &world.bodies[h];
                f64::from(b.kinetic_energy())
                    + f64::from(b.mass()) * 9.81 * f64::from(b.translation().y)
            })
            .sum()
    };
    world.step();
    let start = energy(&world);
    for _ in 0..3600 {
        world.step();
    }
    (start, energy(&world))
}

#[test]
fn a_pendulum_chain_on_ball_joints_never_gains_energy() {
    // (links, widest anchor drift allowed in m): measured 0.29 mm, 2.6 mm and 5.1 mm.
    for (links, drift) in [(1, 0.01), (2, 0.01), (5, 0.015)] {
        let run = hooke_chain(links);
        // Symplectic Euler's energy oscillates by O(h) about its value (measured highest
        // rise: 0.08 %, 0.13 % and 0.22 % of the start); it must not climb.
        assert!(
            run.highest - run.start < 5e-3 * run.start,
            "{links} links: energy rose by {} J (of {} J)",
            run.highest - run.start,
            run.start
        );
        assert!(
            run.drift < drift,
            "{links} links: anchors parted {} m",
            run.drift
        );
    }
}

#[test]
fn a_pendulum_chain_never_gains_energy_at_any_frame_rate_substeps_or_spawn_order() {
    // Two and five rods for 20 s, spawned top down and bottom up (the same to 0.1 %).
    // Measured highest rise, in the order of the settings: two rods 0.22, 0.19, 0.06 and
    // 0.05 % of the start, five 0.33, 0.11, 0.11 and 0.08 %; widest parting 3.3 cm (five
    // rods at one substep), 1.1 cm at 30 Hz, under 3 mm from 8 substeps or 144 Hz.
    let settings = [
        (1.0 / 30.0, 4),
        (1.0 / 60.0, 1),
        (1.0 / 60.0, 8),
        (1.0 / 144.0, 4),
    ];
    for links in [2, 5] {
        for (dt, substeps) in settings {
            for reversed in [false, true] {
                let mut world = default_world();
                world.insert_resource(PhysicsTime::new(dt, substeps).unwrap());
                let run = hooke_chain_in(world, links, 20.0, reversed);
                let rise = (run.highest - run.start) / run.start;
                assert!(
                    rise < 5e-3 && run.drift < 0.05,
                    "{links} rods at 1/{} s × {substeps}, reversed {reversed}: energy rose \
                     {:.3} %, anchors parted {} m",
                    (1.0 / dt).round(),
                    100.0 * rise,
                    run.drift
                );
            }
        }
    }
}

#[test]
fn a_pendulum_chain_keeps_its_energy_at_least_as_well_as_rapiers() {
    // Measured |ΔE| in 60 s, hooke against rapier 0.36: one rod 0.16 J against 17.5 J, two
    // rods 13.9 J (lost) against 195 J (gained), five rods 143 J against 201 J of 1,027 J
    // (both lost; hooke lost 230 J while its groups were solved as soft springs).
    for links in [1, 2, 5] {
        let run = hooke_chain(links);
        let (start, end) = rapier_chain(links);
        // The same scene: the same energy to start with.
        assert!(
            (run.start - start).abs() < 1e-3 * start,
            "{} against {start}",
            run.start
        );
        let (ours, theirs) = ((run.end - run.start).abs(), (end - start).abs());
        assert!(
            ours <= theirs,
            "{links} links: hooke's energy moved {ours} J in 60 s, rapier's {theirs} J"
        );
    }
}

#[test]
fn joined_bodies_do_not_collide_unless_asked_to() {
    for collide in [false, true] {
        let mut world = default_world();
        world.insert_resource(Gravity::ZERO);
        let boxes: Vec<Entity> = (0..2)
            .map(|k| {
                world
                    .spawn((
                        RigidBody::Dynamic,
                        Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
                        Position(Vec3A::new(0.9 * k as f32, 0.0, 0.0)),
                    ))
                    .id()
            })
            .collect();
        world.spawn(
            SphericalJoint::new(boxes[0], boxes[1])
                .with_anchors(Vec3::new(0.45, 0.0, 0.0), Vec3::new(-0.45, 0.0, 0.0))
                .with_collision(collide),
        );
        for _ in 0..5 {
            world.step_physics();
        }
        let touching = world
            .resource::<Contacts>()
            .are_touching(boxes[0], boxes[1]);
        assert_eq!(touching, collide, "with_collision({collide})");
        // Without the contact the overlap stays where it was built; with it, the contact
        // pushes against the joint and the anchors part.
        let gap = world.get::<Position>(boxes[1]).unwrap().0.x
            - world.get::<Position>(boxes[0]).unwrap().0.x;
        if !collide {
            assert!((gap - 0.9).abs() < 1e-4, "{gap}");
        }
    }
}

#[test]
fn a_quarantined_body_frees_its_partner_and_nothing_else_stops() {
    // Two rods on ball joints; the upper one's velocity is written NaN mid-swing.
    let mut world = default_world();
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let spawn_rod = |world: &mut World, k: usize| {
        world
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(HALF.x, HALF.y, HALF.z).unwrap(),
                Position(Vec3A::new(
                    0.0,
                    pivot.y - HALF.y - 2.0 * HALF.y * k as f32,
                    0.0,
                )),
                LinearVelocity(Vec3A::new(1.0, 0.0, 0.0)),
            ))
            .id()
    };
    let (upper, lower) = (spawn_rod(&mut world, 0), spawn_rod(&mut world, 1));
    world.spawn(SphericalJoint::to_world(upper).with_anchors(pivot, Vec3::Y * HALF.y));
    let link = world
        .spawn(SphericalJoint::new(upper, lower).with_anchors(-Vec3::Y * HALF.y, Vec3::Y * HALF.y))
        .id();
    for _ in 0..10 {
        world.step_physics();
    }
    world.get_mut::<LinearVelocity>(upper).unwrap().0 = Vec3A::NAN;
    world.step_physics();
    assert!(world.get::<Quarantined>(upper).is_some());
    let v0 = world.get::<LinearVelocity>(lower).unwrap().0;
    for _ in 0..30 {
        world.step_physics();
    }
    // The lower rod falls freely: its vertical speed grew by g t, and it is finite and live.
    let v1 = world.get::<LinearVelocity>(lower).unwrap().0;
    assert!(world.get::<Quarantined>(lower).is_none());
    assert!(v1.is_finite());
    assert!((v0.y - v1.y - 9.81 * 0.5).abs() < 1e-3, "{v0} then {v1}");
    assert_eq!(world.get::<JointImpulse>(link).unwrap().force(), Vec3::ZERO);
}

#[test]
fn a_joint_with_a_bad_input_is_quarantined_with_its_reason() {
    let mut world = default_world();
    let body = world
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.5).unwrap(),
            Position(Vec3A::ZERO),
        ))
        .id();
    let mut bent = RevoluteJoint::to_world(body, Vec3::Z);
    bent.axis_b = Vec3::new(0.0, 0.0, 2.0);
    let cases = [
        world.spawn(SphericalJoint::new(body, body)).id(),
        world.spawn(bent).id(),
        world
            .spawn(FixedJoint::to_world(body, Quat::IDENTITY).with_anchors(Vec3::NAN, Vec3::ZERO))
            .id(),
        world
            .spawn(RevoluteJoint::to_world(body, Vec3::Z).with_motor(1.0, -5.0))
            .id(),
    ];
    world.step_physics();
    let names = [
        "itself",
        "hinge axis b",
        "joint anchor a",
        "motor max torque",
    ];
    let cases: Vec<_> = cases.into_iter().zip(names).collect();
    super::assert_quarantined_for(&world, &cases);
    // The body itself runs on.
    assert!(world.get::<Quarantined>(body).is_none());
}

#[test]
fn a_ball_on_a_spherical_joint_circles_as_a_conical_pendulum() {
    // A ball (r = 0.1 m) hung by a ball joint from a point d = 1 m above its centre, set
    // turning about the vertical at Ω with its string α from it. A ball's inertia is the
    // same about every axis, so the steady cone is the point pendulum's: Ω² = g / (d cos α).
    for alpha in [20_f32.to_radians(), 60_f32.to_radians()] {
        let mut world = default_world();
        let pivot = Vec3A::new(0.0, 3.0, 0.0);
        let d = 1.0_f32;
        let omega = (9.81 / (d * alpha.cos())).sqrt();
        let x = pivot + Vec3A::new(d * alpha.sin(), -d * alpha.cos(), 0.0);
        let spin = Vec3A::new(0.0, omega, 0.0);
        let ball = world
            .spawn((
                RigidBody::Dynamic,
                Collider::ball(0.1).unwrap(),
                Position(x),
                LinearVelocity(spin.cross(x - pivot)),
                AngularVelocity(spin),
            ))
            .id();
        // Anchored at the pivot, d from the ball's centre: the rod is the ball's own lever.
        world.spawn(SphericalJoint::to_world(ball).with_anchors(pivot.into(), (pivot - x).into()));
        let (mut azimuth, mut last, mut widest) = (0.0_f32, 0.0_f32, 0.0_f32);
        let steps = 600;
        for _ in 0..steps {
            world.step_physics();
            let r = world.get::<Position>(ball).unwrap().0 - pivot;
            let now = (-r.z).atan2(r.x);
            azimuth += (now - last + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
                - std::f32::consts::PI;
            last = now;
            let cone = (r.x.hypot(r.z)).atan2(-r.y);
            widest = widest.max((cone - alpha).abs());
        }
        let rate = azimuth / (steps as f32 / 60.0);
        assert!(
            widest < 0.01,
            "the cone opened or closed by {widest} rad from {alpha}"
        );
        assert!(
            (rate / omega - 1.0).abs() < 0.002,
            "α {alpha}: {rate} rad/s about the vertical, closed form {omega}"
        );
        assert!(world.get::<Quarantined>(ball).is_none());
    }
}
