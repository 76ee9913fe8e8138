use super::*;

#[test]
fn softness_matches_box2d_coefficients() {
    // f = 30 Hz, ζ = 10, h = 1/240: ω = 188.5, a1 = 20.785, a2 = 16.32.
    let s = Softness::new(30.0, 10.0, 1.0 / 240.0);
    let omega = std::f32::consts::TAU * 30.0;
    let a1 = 20.0 + omega / 240.0;
    let a2 = omega / 240.0 * a1;
    assert!((s.bias_rate - omega / a1).abs() < 1e-4);
    assert!((s.mass_scale - a2 / (1.0 + a2)).abs() < 1e-6);
    assert!((s.impulse_scale - 1.0 / (1.0 + a2)).abs() < 1e-6);
    assert_eq!(Softness::new(0.0, 1.0, 0.01).mass_scale, 1.0);
}

fn lanes(v: Vec3A) -> V3 {
    V3::from_lanes([v; 4])
}

fn axis_mass(ma: f32, ia: Mat3A, ra: Vec3A, mb: f32, ib: Mat3A, rb: Vec3A, d: Vec3A) -> f32 {
    let live = F4::splat(f32::from_bits(!0));
    let (ia, ib) = (M3::from_lanes([&ia; 4]), M3::from_lanes([&ib; 4]));
    let axis = Axis::new(
        F4::splat(ma),
        &ia,
        lanes(ra),
        F4::splat(mb),
        &ib,
        lanes(rb),
        lanes(d),
        live,
    );
    axis.mass.to_array()[0]
}

#[test]
fn effective_mass_of_a_point_mass_and_a_lever() {
    let z = Mat3A::ZERO;
    let o = Vec3A::ZERO;
    assert_eq!(axis_mass(0.5, z, o, 0.0, z, o, Vec3A::Y), 2.0);
    // A unit-inertia body hit at r = x along y: k = 1/m + |r × n|² / I = 1 + 1.
    let i = Mat3A::IDENTITY;
    assert!((axis_mass(1.0, i, Vec3A::X, 0.0, z, o, Vec3A::Y) - 0.5).abs() < 1e-6);
    // Nothing can move: no impulse at all (not an infinite one).
    assert_eq!(axis_mass(0.0, z, Vec3A::X, 0.0, z, Vec3A::X, Vec3A::Y), 0.0);
}

/// Unit point masses (no inertia); `pairs` are body indices, `FIXED` for the ground. Every
/// manifold has one point at the bodies' centres, touching, closing at 1 m/s.
fn solver_with(bodies: usize, pairs: &[(u32, u32)]) -> ContactSolver {
    let mut s = ContactSolver::default();
    for i in 0..bodies {
        s.bodies.push(SolverBody::at_origin(
            Entity::from_raw_u32(i as u32 + 1).unwrap(),
            1.0 / (1.0 + i as f32),
            Mat3A::ZERO,
        ));
    }
    for (mi, &(a, b)) in pairs.iter().enumerate() {
        s.manifolds.push(ManifoldConstraint {
            a,
            b,
            n: Vec3A::Y,
            t: [Vec3A::X, Vec3A::Z],
            friction: 0.5,
            restitution: 0.0,
            threshold: 1.0,
            first: mi as u32,
            count: 1,
            pair: u32::MAX,
            manifold: 0,
            centre_a: Vec3A::ZERO,
            centre_b: Vec3A::ZERO,
            radius: 0.0,
            t_imp: [0.0; 2],
            twist: 0.0,
            surface: [0.0; 2],
            held: 0,
        });
        s.inputs.push(PointInput {
            base: -0.01,
            approach: -1.0,
            ..PointInput::default()
        });
    }
    s
}

fn run(s: &mut ContactSolver, velocities: &[Vec3A]) -> Vec<Vec3A> {
    for (state, &v) in s.states.iter_mut().zip(velocities) {
        state.v = v;
    }
    let soft = Softness::new(30.0, 10.0, 1.0 / 240.0);
    s.warm_start();
    s.solve(1.0 / 240.0, soft, soft, true, 3.0);
    s.solve(1.0 / 240.0, soft, soft, false, 3.0);
    s.states[..s.bodies.len()].iter().map(|s| s.v).collect()
}

#[test]
fn colouring_never_puts_a_dynamic_body_twice_in_a_batch() {
    // A chain 0-1-2-…-9 with every body also on the ground: each body has up to three
    // manifolds.
    let mut pairs: Vec<(u32, u32)> = (0..9).map(|i| (i, i + 1)).collect();
    pairs.extend((0..10).map(|i| (FIXED, i)));
    let mut s = solver_with(10, &pairs);
    s.build();
    let mut seen = vec![0; pairs.len()];
    for batch in &s.batches {
        let mut bodies: Vec<u32> = batch
            .a
            .iter()
            .chain(&batch.b)
            .copied()
            .filter(|&i| i != s.rest())
            .collect();
        let n = bodies.len();
        bodies.sort_unstable();
        bodies.dedup();
        assert_eq!(bodies.len(), n, "a body twice in one batch");
        for &mi in batch.lanes.iter().filter(|&&mi| mi != u32::MAX) {
            seen[mi as usize] += 1;
        }
    }
    assert!(seen.iter().all(|&n| n == 1), "each manifold once: {seen:?}");
    // Ten ground contacts share no dynamic body: they fill batches of four.
    assert!(s.batches.len() < pairs.len());
}

#[test]
fn lanes_solve_exactly_like_manifolds_one_at_a_time() {
    // Independent pairs (no body in common): batching must not change a single bit.
    let pairs: Vec<(u32, u32)> = (0..6).map(|i| (2 * i, 2 * i + 1)).collect();
    let v: Vec<Vec3A> = (0..12)
        .map(|i| Vec3A::new(0.1 * i as f32, if i % 2 == 0 { 1.0 } else { -0.5 }, 0.3))
        .collect();
    let mut wide = solver_with(12, &pairs);
    wide.build();
    let mut single = solver_with(12, &pairs);
    single.build_with(0);
    assert!(wide.batches.len() < single.batches.len());
    assert_eq!(run(&mut wide, &v), run(&mut single, &v));
}

#[test]
fn a_contact_stops_the_approach_and_conserves_momentum() {
    // Bodies 0 (1 kg, below, rising at 1 m/s) and 1 (2 kg, falling at 1 m/s) meet.
    let mut s = solver_with(2, &[(0, 1)]);
    s.build();
    let v = run(&mut s, &[Vec3A::Y, -Vec3A::Y]);
    // After the relax pass the normal velocities agree (no bias): v = (1·1 − 2·1)/3.
    assert!((v[0].y - v[1].y).abs() < 1e-6, "{v:?}");
    assert!((v[0].y - (-1.0 / 3.0)).abs() < 1e-5, "{v:?}");
    // Friction (μ = 0.5 of the normal impulse) takes out the sideways slip, which is zero.
    assert_eq!(v[0].x, 0.0);
}

#[test]
fn a_frozen_body_becomes_an_immovable_obstacle() {
    let mut s = solver_with(2, &[(0, 1)]);
    s.build();
    s.freeze(0);
    let v = run(&mut s, &[Vec3A::ZERO, -Vec3A::Y]);
    // Body 1 stops against the frozen body as against the ground; body 0 is never written.
    assert!(v[1].y.abs() < 1e-6, "{v:?}");
    assert!(!s.bodies[0].dynamic);
    assert_eq!(s.states[s.rest() as usize].v, Vec3A::ZERO);
}

#[test]
fn a_spent_restitution_budget_never_scales_an_impulse_up() {
    use super::restitution::budget_share;
    // The case that blew up a struck row: the budget was −2.65 J and an impulse that took
    // 7.7 mJ out was scaled by 344; the next point's by 64.
    assert_eq!(budget_share(-0.0077, -2.65), 1.0);
    assert_eq!(budget_share(-603.0, -38_480.0), 1.0);
    // An impulse that adds energy gets what is left of the budget, none once it is spent.
    assert_eq!(budget_share(4.0, 1.0), 0.25);
    assert_eq!(budget_share(2.0, -1.0), 0.0);
    assert_eq!(budget_share(1.0, 3.0), 1.0);
    for (cost, budget) in [
        (-5.0, -1.0),
        (-1.0, -5.0),
        (3.0, -2.0),
        (0.5, 0.2),
        (0.0, -1.0),
    ] {
        let share = budget_share(cost, budget);
        assert!((0.0..=1.0).contains(&share), "{cost} {budget}: {share}");
    }
}
