//! Cloth (`Nodes` + `SpringNetwork` + `Cloth`): generators and bad input, rendering output,
//! a drape over a sphere, a flag in wind, strain limiting, and a ball caught by a cloth
//! (two-way node contacts), at 60 Hz through the public API.

use crate::common;
use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};
use hooke::Error;
use hooke::cloth::Cloth;
use hooke::cloth::ClothBuilder;
use hooke::cloth::ClothMaterial;
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;

fn world(substeps: u32, g: Vec3) -> World {
    common::awake_world(1.0 / 60.0, substeps, g)
}

const G: Vec3 = Vec3::new(0.0, -9.81, 0.0);

#[test]
fn a_triangle_mesh_gets_edge_and_bend_springs_and_lumped_masses() {
    // A unit square as two triangles: 5 edges, one shared (the diagonal), so one bend spring.
    let x = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
    let material = ClothMaterial::default();
    let (nodes, net, cloth) = Cloth::from_triangles(&x, &[[0, 3, 1], [1, 3, 2]], material).unwrap();
    assert_eq!(net.len(), 6);
    assert_eq!(cloth.triangles().len(), 2);
    assert_eq!(cloth.indices(), vec![0, 3, 1, 1, 3, 2]);
    let total: f32 = (0..4).map(|i| nodes.mass(i).unwrap()).sum();
    assert!((total - material.density).abs() < 1e-6, "{total}");
    // The bend spring joins the corners opposite the diagonal (0 and 2), √2 long.
    let bend = net.ends().iter().position(|&e| e == [0, 2] || e == [2, 0]);
    assert!(bend.is_some(), "{:?}", net.ends());
}

#[test]
fn bad_cloth_meshes_are_typed_errors() {
    let x = [Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::new(2.0, 0.0, 0.0)];
    let m = ClothMaterial::default();
    let err = |t: &[[usize; 3]], x: &[Vec3], m: ClothMaterial| {
        Cloth::from_triangles(x, t, m).unwrap_err()
    };
    assert!(matches!(
        err(&[[0, 1, 7]], &x, m),
        Error::IndexOutOfRange { index: 7, .. }
    ));
    assert!(matches!(
        err(&[[0, 1, 1]], &x, m),
        Error::DegenerateTriangle { index: 0, .. }
    ));
    // Three collinear corners: zero area.
    assert!(matches!(
        err(&[[0, 2, 1], [0, 1, 3]], &x, m),
        Error::DegenerateTriangle { index: 1, .. }
    ));
    assert!(matches!(err(&[], &x, m), Error::TooFew { .. }));
    let nan = [Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 1.0)];
    assert!(matches!(
        err(&[[0, 1, 2]], &nan, m),
        Error::NonFinite { .. }
    ));
    let negative = ClothMaterial {
        structural: (-1.0, 0.0),
        ..m
    };
    assert!(matches!(
        err(&[[0, 2, 1]], &x, negative),
        Error::Negative { .. }
    ));
    let no_density = ClothMaterial { density: 0.0, ..m };
    assert!(matches!(
        err(&[[0, 2, 1]], &x, no_density),
        Error::NotPositive { .. }
    ));
    let nan_bend = ClothMaterial {
        bend: (f32::NAN, 0.0),
        ..m
    };
    assert!(matches!(
        err(&[[0, 2, 1]], &x, nan_bend),
        Error::NonFinite { .. }
    ));
    let (_, _, cloth) = Cloth::from_triangles(&x, &[[0, 2, 1]], m).unwrap();
    assert!(matches!(
        cloth.clone().with_drag(-1.0),
        Err(Error::Negative { .. })
    ));
    assert!(matches!(
        cloth.clone().with_strain_limit(Some(0.0)),
        Err(Error::NotPositive { .. })
    ));
    assert!(matches!(
        cloth.with_thickness(f32::NAN),
        Err(Error::NonFinite { .. })
    ));
}

#[test]
fn a_strain_limited_cloth_whose_network_is_replaced_does_not_panic() {
    let mut w = world(4, G);
    let (nodes, net, cloth) = ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 6, 6, 0.1)
        .build_cloth()
        .unwrap();
    let cloth = cloth.with_strain_limit(Some(0.1)).unwrap();
    let e = w.spawn((nodes, net, cloth)).id();
    w.step_physics();
    // Game code swaps in a network of one spring: the cloth's structural list no longer fits.
    let mut small = SpringNetwork::new();
    small.push(0, 1, 0.1, 8.0, 0.01).unwrap();
    w.entity_mut(e).insert(small);
    for _ in 0..10 {
        w.step_physics();
    }
    assert!(
        w.get::<Nodes>(e)
            .unwrap()
            .positions()
            .iter()
            .all(|x| x.is_finite())
    );
}

#[test]
fn absurd_builder_sizes_are_errors_not_allocation_panics() {
    let huge = ClothBuilder::new(Vec3::ZERO, usize::MAX, 3, 0.1).build();
    assert!(matches!(huge, Err(Error::OutOfRange { .. })), "{huge:?}");
    let huge = ClothBuilder::new(Vec3::ZERO, 1 << 13, 1 << 12, 0.1).build();
    assert!(matches!(huge, Err(Error::OutOfRange { .. })));
    let mut w = world(1, G);
    let rope = hooke::springs::ChainBuilder::rope(Vec3::ZERO, Vec3::X, usize::MAX).spawn(&mut w);
    assert!(matches!(rope, Err(Error::OutOfRange { .. })), "{rope:?}");
}

#[test]
fn zero_length_and_coincident_springs_give_no_nan() {
    for implicit in [false, true] {
        let mut w = world(4, G);
        let mut nodes = Nodes::new();
        nodes.push_pinned(Vec3::new(0.0, 1.0, 0.0)).unwrap();
        nodes
            .push(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, 0.1)
            .unwrap();
        nodes
            .push(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, 0.1)
            .unwrap();
        let mut net = SpringNetwork::new();
        net.push(0, 1, 0.0, 1e4, 1.0).unwrap(); // zero length, ends coincide
        net.push(1, 2, 0.1, 1e4, 1.0).unwrap(); // rest 0.1 m, ends coincide
        let mut e = w.spawn((nodes, net));
        if implicit {
            e.insert(ImplicitEuler::default());
        }
        let e = e.id();
        for _ in 0..120 {
            w.step_physics();
        }
        assert!(w.get::<Quarantined>(e).is_none(), "implicit {implicit}");
        let n = w.get::<Nodes>(e).unwrap();
        assert!(n.positions().iter().all(|x| x.is_finite()));
        assert!(
            n.velocities().iter().all(|v| v.length() < 1.0),
            "bounded, implicit {implicit}"
        );
    }
}

#[test]
fn a_grid_cloth_renders_triangles_and_unit_normals() {
    let mut w = world(4, G);
    let e = ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 6, 4, 0.1)
        .spawn(&mut w)
        .unwrap();
    let cloth = w.get::<Cloth>(e).unwrap();
    assert_eq!(cloth.triangles().len(), 2 * 5 * 3);
    assert_eq!(cloth.indices().len(), 90);
    w.step_physics();
    let cloth = w.get::<Cloth>(e).unwrap();
    assert_eq!(cloth.normals().len(), 24);
    for n in cloth.normals() {
        assert!(
            (n.length() - 1.0).abs() < 1e-5 && n.y > 0.99,
            "flat cloth, face up: {n}"
        );
    }
}

/// A 25 × 25 cloth 1.2 m across, 0.6 m above a sphere of radius 0.5 on the ground.
fn drape(substeps: u32, implicit: bool) -> (World, Entity) {
    let mut w = world(substeps, G);
    w.spawn((
        RigidBodyBundle::fixed(Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY).unwrap(),
        Collider::ball(0.5).unwrap(),
    ));
    let (nodes, net, cloth) = ClothBuilder::new(Vec3::new(-0.6, 1.1, -0.6), 25, 25, 0.05)
        .pin_corners(false)
        .stiffness(400.0, 100.0, 2.0)
        .build_cloth()
        .unwrap();
    let e = w.spawn((nodes, net, cloth)).id();
    if implicit {
        w.entity_mut(e).insert(ImplicitEuler::default());
    }
    (w, e)
}

#[test]
fn a_cloth_dropped_on_a_sphere_drapes_over_it_and_comes_to_rest() {
    let (mut w, e) = drape(1, true);
    for _ in 0..300 {
        w.step_physics();
    }
    assert!(w.get::<Quarantined>(e).is_none());
    let n = w.get::<Nodes>(e).unwrap();
    let centre = Vec3A::new(0.0, 0.5, 0.0);
    let inside = n
        .positions()
        .iter()
        .map(|x| (*x - centre).length())
        .fold(f32::INFINITY, f32::min);
    let speed = n.max_speed();
    let top = n.positions()[12 * 25 + 12];
    let corner = n.positions()[0];
    println!(
        "drape after 5 s: top node at y {:.4}, corner at y {:.3}, nearest node {inside:.4} m from the centre, fastest {speed:.2e} m/s",
        top.y, corner.y
    );
    assert!(inside > 0.5 - 0.002, "no node inside the sphere: {inside}");
    assert!(
        (top.y - 1.01).abs() < 0.01,
        "the top rests on the sphere: {}",
        top.y
    );
    assert!(corner.y < 0.8, "the corners hang down: {}", corner.y);
    assert!(speed < 0.05, "at rest: {speed} m/s");
}

#[test]
fn a_flag_in_steady_wind_streams_out_and_stays_bounded() {
    let mut w = world(1, G);
    // The wind blows face-on at the flag at rest (along +z): it turns the flag to stream out
    // along +z.
    w.spawn(hooke::particles::VelocityField::uniform(Vec3::new(0.0, 0.0, 8.0)).unwrap());
    // 20 × 12 nodes, 1 m × 0.55 m, in the x–y plane, its x = 0 edge on the pole.
    let (nx, ny, s) = (20usize, 12usize, 0.05f32);
    let mut x = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            x.push(Vec3::new(i as f32 * s, 2.0 - j as f32 * s, 0.0));
        }
    }
    let mut tris = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let id = |i: usize, j: usize| j * nx + i;
            tris.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            tris.push([id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)]);
        }
    }
    let (mut nodes, net, cloth) =
        Cloth::from_triangles(&x, &tris, ClothMaterial::default()).unwrap();
    for j in 0..ny {
        nodes.pin(j * nx).unwrap();
    }
    let cloth = cloth.with_drag(1.0).unwrap();
    let e = w.spawn((nodes, net, cloth, ImplicitEuler::default())).id();
    let (mut farthest, mut tip_x) = (0.0f32, Vec::new());
    for step in 0..600 {
        w.step_physics();
        let n = w.get::<Nodes>(e).unwrap();
        for p in n.positions() {
            farthest = farthest.max(p.x.abs().max(p.z.abs()));
        }
        if step >= 300 {
            let tip = (0..ny)
                .map(|j| n.positions()[j * nx + nx - 1].z)
                .sum::<f32>()
                / ny as f32;
            tip_x.push(tip);
        }
    }
    assert!(w.get::<Quarantined>(e).is_none());
    let mean = tip_x.iter().sum::<f32>() / tip_x.len() as f32;
    println!(
        "flag, last 5 of 10 s in an 8 m/s wind along z: free edge at mean z {mean:.3} m (length 0.95 m), farthest {farthest:.3} m"
    );
    assert!(farthest < 1.1, "bounded: {farthest}");
    assert!(mean > 0.6, "the wind turns it downwind: {mean}");

    // Without wind the same flag stays in its plane.
    let mut calm = world(1, G);
    let (mut nodes, net, cloth) =
        Cloth::from_triangles(&x, &tris, ClothMaterial::default()).unwrap();
    for j in 0..ny {
        nodes.pin(j * nx).unwrap();
    }
    let e = calm
        .spawn((
            nodes,
            net,
            cloth.with_drag(1.0).unwrap(),
            ImplicitEuler::default(),
        ))
        .id();
    for _ in 0..300 {
        calm.step_physics();
    }
    let n = calm.get::<Nodes>(e).unwrap();
    let tip = (0..ny)
        .map(|j| n.positions()[j * nx + nx - 1].z)
        .sum::<f32>()
        / ny as f32;
    println!("without wind: free edge at mean z {tip:.3} m");
    assert!(tip.abs() < 0.01, "{tip}");
}

#[test]
fn strain_limiting_holds_a_soft_cloth_to_ten_percent() {
    let strain = |limit: Option<f32>| {
        let mut w = world(4, G);
        let (nodes, net, cloth) = ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 12, 12, 0.05)
            .stiffness(2.0, 1.0, 0.1)
            .build_cloth()
            .unwrap();
        let cloth = cloth.with_strain_limit(limit).unwrap();
        let e = w.spawn((nodes, net, cloth)).id();
        let mut most = 0.0f32;
        for _ in 0..180 {
            w.step_physics();
            let (n, s, c) = (
                w.get::<Nodes>(e).unwrap(),
                w.get::<SpringNetwork>(e).unwrap(),
                w.get::<Cloth>(e).unwrap(),
            );
            most = most.max(c.max_strain(n, s));
        }
        most
    };
    let (free, held) = (strain(None), strain(Some(0.1)));
    println!(
        "soft cloth hanging 3 s: largest structural strain {free:.3} free, {held:.4} limited to 0.1"
    );
    assert!(free > 0.3, "{free}");
    assert!(held < 0.1 + 0.01, "{held}");
}

#[test]
fn a_ball_dropped_on_a_cloth_trampoline_is_caught_and_held() {
    let mut w = world(4, G);
    let (mut nodes, net, cloth) = ClothBuilder::new(Vec3::new(-0.5, 1.0, -0.5), 21, 21, 0.05)
        .pin_corners(false)
        .stiffness(2000.0, 500.0, 5.0)
        .build_cloth()
        .unwrap();
    for k in 0..21 {
        for i in [k, 20 * 21 + k, k * 21, k * 21 + 20] {
            nodes.pin(i).unwrap();
        }
    }
    let cloth_e = w.spawn((nodes, net, cloth, ImplicitEuler::default())).id();
    let ball = w
        .spawn((
            RigidBody::Dynamic,
            Collider::ball(0.1).unwrap(),
            Mass::new(0.5).unwrap(),
            hooke::rigid::Inertia::diagonal(0.002, 0.002, 0.002).unwrap(),
            Position::from(Vec3::new(0.0, 1.5, 0.0)),
        ))
        .id();
    let mut lowest = f32::INFINITY;
    for _ in 0..300 {
        w.step_physics();
        lowest = lowest.min(w.get::<Position>(ball).unwrap().0.y);
    }
    assert!(w.get::<Quarantined>(cloth_e).is_none());
    let y = w.get::<Position>(ball).unwrap().0.y;
    let v = w.get::<LinearVelocity>(ball).unwrap().0.length();
    let sag = 1.0 - w.get::<Nodes>(cloth_e).unwrap().positions()[10 * 21 + 10].y;
    println!(
        "ball on the trampoline after 5 s: at y {y:.3} (lowest {lowest:.3}), speed {v:.3} m/s; cloth centre sags {sag:.3} m"
    );
    assert!(lowest > 0.6, "caught, not through: {lowest}");
    assert!(y > 0.8 && y < 1.1, "held on the cloth: {y}");
    assert!(sag > 0.005, "the cloth carries the ball's weight: {sag}");
    assert!(v < 0.2, "comes to rest: {v}");
}
