//! Colliders from Bevy meshes (feature `collider-from-mesh`): a cube's trimesh, hull and
//! decomposition hold its volume; a torus's decomposition holds the torus's 2π²Rr² where its
//! hull does not, and a dynamic torus rests flat on the ground; meshes that cannot make a
//! collider are typed errors.
#![cfg(feature = "collider-from-mesh")]

use crate::common;
use hooke::bevy_mesh::{CuboidMeshBuilder, Indices, Mesh, MeshBuilder, TorusMeshBuilder};
use hooke::prelude::*;

fn volume(c: &Collider) -> f32 {
    c.shape().mass_properties(1.0).mass()
}

#[test]
fn a_cube_mesh_makes_a_trimesh_a_hull_and_a_decomposition() {
    let cube = CuboidMeshBuilder::default().build(); // 1 m cube
    let trimesh = Collider::trimesh_from_mesh(&cube).unwrap();
    let [min, max] = [
        trimesh.shape().compute_local_aabb().mins,
        trimesh.shape().compute_local_aabb().maxs,
    ];
    assert!((max - min - Vec3::ONE).length() < 1e-5);
    assert!((volume(&Collider::convex_hull_from_mesh(&cube).unwrap()) - 1.0).abs() < 1e-4);
    assert!((volume(&Collider::convex_decomposition_from_mesh(&cube).unwrap()) - 1.0).abs() < 0.05);
}

#[test]
fn a_torus_decomposes_into_its_own_volume_and_rests_flat() {
    // Minor radius r = 0.25 m, major radius R = 0.75 m: V = 2π² R r² = 0.925 m³.
    let torus = TorusMeshBuilder::new(0.5, 1.0).build();
    let exact = 2.0 * std::f32::consts::PI.powi(2) * 0.75 * 0.25f32.powi(2);
    let parts = Collider::convex_decomposition_from_mesh(&torus).unwrap();
    let hull = Collider::convex_hull_from_mesh(&torus).unwrap();
    let v = volume(&parts);
    assert!(
        (v - exact).abs() < 0.15 * exact,
        "decomposition {v} vs {exact}"
    );
    // The hull fills the hole (about π R_out² × 2r less its rounded rim: 1.2 m³).
    assert!(
        volume(&hull) > 1.2 * exact && volume(&hull) > v + 0.15,
        "hull {}",
        volume(&hull)
    );

    let mut world = common::default_world();
    world.spawn((
        RigidBody::Static,
        Collider::cuboid(5.0, 0.5, 5.0).unwrap(),
        Position::from(Vec3::new(0.0, -0.5, 0.0)),
    ));
    let ring = world
        .spawn((
            RigidBody::Dynamic,
            parts,
            Position::from(Vec3::new(0.0, 1.0, 0.0)),
        ))
        .id();
    for _ in 0..240 {
        world.step_physics();
    }
    let y = world.get::<Position>(ring).unwrap().get().y;
    // The mesh's tessellation and the decomposition's hulls stand a little proud of the
    // smooth torus.
    assert!(
        (y - 0.25).abs() < 0.03,
        "the ring lies flat at its minor radius: {y}"
    );
}

#[test]
fn meshes_that_make_no_collider_are_typed_errors() {
    let mut no_positions = CuboidMeshBuilder::default().build();
    no_positions.remove_attribute(Mesh::ATTRIBUTE_POSITION);
    for result in [
        Collider::trimesh_from_mesh(&no_positions),
        Collider::convex_hull_from_mesh(&no_positions),
        Collider::convex_decomposition_from_mesh(&no_positions),
    ] {
        assert!(
            matches!(result, Err(Error::UnsupportedMesh(_))),
            "{:?}",
            result.err()
        );
    }
    let flat = CuboidMeshBuilder::default()
        .build()
        .scaled_by(Vec3::new(1.0, 0.0, 1.0));
    assert!(matches!(
        Collider::convex_hull_from_mesh(&flat),
        Err(Error::TooFew { .. })
    ));
    assert!(Collider::convex_decomposition_from_mesh(&flat).is_err());
    let mut ragged = CuboidMeshBuilder::default().build();
    ragged.insert_indices(Indices::U32(vec![0, 1, 2, 3]));
    assert!(matches!(
        Collider::trimesh_from_mesh(&ragged),
        Err(Error::UnsupportedMesh(_))
    ));
    let mut empty = CuboidMeshBuilder::default().build();
    empty.insert_indices(Indices::U32(Vec::new()));
    assert!(matches!(
        Collider::trimesh_from_mesh(&empty),
        Err(Error::TooFew { .. })
    ));
}
