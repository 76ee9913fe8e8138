//! Contacts never create energy, whatever the spawn order. A striker into a row of four
//! touching balls (e = 1, no friction, no gravity) ended with 1.40× the kinetic energy when
//! the striker was spawned first, and 0.57× when it was spawned last.

use crate::common;
use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;

/// The cradle: balls 0..count touching along x, the striker (index `count`) at 3 m/s from
/// the left; spawned in `order` (a permutation of 0..=count). Returns (energy after /
/// before, the most energy ever above the start over the start, momentum after / before).
/// At the defaults (`PhysicsPlugins` alone, gravity off), or at `time` (step, substeps).
fn cradle(
    count: usize,
    order: &[usize],
    e: f32,
    mu: f32,
    time: Option<(f32, u32)>,
) -> (f64, f64, f64) {
    let mut w = common::default_world();
    w.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    if let Some((dt, substeps)) = time {
        w.insert_resource(hooke::core::time::PhysicsTime::new(dt, substeps).unwrap());
    }
    let steps = time.map_or(120, |(dt, _)| (2.0 / dt) as usize);
    for &i in order {
        let (x, v) = if i == count {
            (-0.6, 3.0)
        } else {
            (0.2 * i as f32, 0.0)
        };
        w.spawn((
            RigidBody::Dynamic,
            Collider::ball(0.1).unwrap(),
            Restitution(e),
            Friction(mu),
            Position::from(Vec3::new(x, 0.0, 0.0)),
            LinearVelocity::from(Vec3::new(v, 0.0, 0.0)),
        ));
    }
    w.step_physics();
    let d = w.resource::<PhysicsDiagnostics>();
    let (k0, p0) = (d.kinetic_energy, d.linear_momentum.x);
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..steps {
        w.step_physics();
        worst = worst.max(w.resource::<PhysicsDiagnostics>().kinetic_energy / k0 - 1.0);
    }
    let d = w.resource::<PhysicsDiagnostics>();
    (
        d.kinetic_energy / k0,
        worst,
        f64::from(d.linear_momentum.x / p0),
    )
}

/// Every permutation of 0..n, in lexicographic order.
fn permutations(n: usize) -> Vec<Vec<usize>> {
    let mut all = vec![(0..n).collect::<Vec<_>>()];
    loop {
        let mut p = all.last().unwrap().clone();
        let Some(i) = (0..n - 1).rev().find(|&i| p[i] < p[i + 1]) else {
            return all;
        };
        let j = (i + 1..n).rev().find(|&j| p[j] > p[i]).unwrap();
        p.swap(i, j);
        p[i + 1..].reverse();
        all.push(p);
    }
}

#[test]
fn a_cradle_never_gains_energy_in_any_spawn_order() {
    let count = 4;
    let (mut low, mut high, mut worst_gain) = (f64::INFINITY, 0.0f64, f64::NEG_INFINITY);
    let orders = permutations(count + 1);
    for order in &orders {
        let (ratio, gain, momentum) = cradle(count, order, 1.0, 0.0, None);
        low = low.min(ratio);
        high = high.max(ratio);
        worst_gain = worst_gain.max(gain);
        assert!(
            (momentum - 1.0).abs() < 1e-4,
            "{order:?}: momentum x{momentum}"
        );
        assert!(
            gain < 1e-4,
            "{order:?}: energy x{ratio}, at most {gain:.3e} above"
        );
    }
    println!(
        "{} spawn orders of a 5-ball cradle: energy after x{low:.3} to x{high:.3}, never more than {worst_gain:.1e} above the start",
        orders.len()
    );
    // Every fifth order again at other frame rates and substeps, with friction.
    for time in [(1.0 / 30.0, 1), (1.0 / 60.0, 8), (1.0 / 144.0, 2)] {
        for order in orders.iter().step_by(5) {
            let (ratio, gain, momentum) = cradle(count, order, 1.0, 0.5, Some(time));
            assert!(
                (momentum - 1.0).abs() < 1e-4,
                "{time:?} {order:?}: momentum x{momentum}"
            );
            assert!(
                gain < 1e-4,
                "{time:?} {order:?}: energy x{ratio}, {gain:.3e} above"
            );
        }
    }
}

/// A marker that puts a body in another archetype.
#[derive(Component)]
struct Elsewhere;

/// Three boxes dropped as a stack onto the ground (e = 0.5, μ = 0.5) and a ball thrown into
/// it, spawned in `order` (bodies 0..4, the ground last or first), the bodies in `odd` given
/// an extra component (another archetype). Returns the most kinetic + gravitational energy
/// ever above the start, over the start's kinetic energy.
fn stack(order: &[usize], odd: &[usize], ground_first: bool) -> f64 {
    let mut w = common::awake_world(1.0 / 60.0, 4, Vec3::new(0.0, -9.81, 0.0));
    if ground_first {
        hooke::tools::scenes::ground(&mut w).unwrap();
    }
    for &i in order {
        let mut e = if i < 3 {
            w.spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
                Position::from(Vec3::new(0.0, 0.3 + 0.55 * i as f32, 0.0)),
            ))
        } else {
            w.spawn((
                RigidBody::Dynamic,
                Collider::ball(0.2).unwrap(),
                Position::from(Vec3::new(-2.0, 0.8, 0.0)),
                LinearVelocity::from(Vec3::new(6.0, 0.0, 0.0)),
            ))
        };
        e.insert((Restitution(0.5), Friction(0.5)));
        if odd.contains(&i) {
            e.insert(Elsewhere);
        }
    }
    if !ground_first {
        hooke::tools::scenes::ground(&mut w).unwrap();
    }
    w.step_physics();
    let total = |w: &World| {
        let d = w.resource::<PhysicsDiagnostics>();
        d.kinetic_energy + d.gravitational_energy
    };
    let (start, scale) = (total(&w), w.resource::<PhysicsDiagnostics>().kinetic_energy);
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..150 {
        w.step_physics();
        worst = worst.max((total(&w) - start) / scale);
    }
    worst
}

#[test]
fn a_stack_hit_by_a_ball_never_gains_energy_in_any_order_or_archetype_layout() {
    let mut worst = f64::NEG_INFINITY;
    let mut runs = 0;
    for (k, order) in permutations(4).iter().enumerate() {
        // Every order, with the ground first or last and one of four archetype layouts.
        let layouts: [&[usize]; 4] = [&[], &[3], &[0, 2], &[1, 2, 3]];
        let gain = stack(order, layouts[k % 4], k % 2 == 0);
        assert!(
            gain < 1e-3,
            "{order:?}: {gain:.3e} of the start's kinetic energy gained"
        );
        worst = worst.max(gain);
        runs += 1;
    }
    println!(
        "{runs} spawn orders and layouts of a struck stack: at most {worst:.1e} of the start's kinetic energy above it"
    );
}
