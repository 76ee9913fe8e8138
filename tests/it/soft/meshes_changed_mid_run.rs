//! Soft-body meshes changed by game code mid-run: nodes emptied under the elements, or the
//! elements of a bigger mesh put on the nodes, panicked inside the step (index out of bounds
//! in `SoftBody::deformation_gradient` and in the implicit solve's factor). Such a body is
//! quarantined, named, and the rest of the world runs on; a consistent replacement (nodes and
//! elements together) is adopted.

use crate::common;

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::quarantine::{QuarantineReason, Quarantined};
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

/// A bigger jelly's nodes and elements (5×5×5 cells instead of 3×3×3).
fn bigger() -> (Nodes, SoftBody) {
    let mesh = TetMesh::cuboid(Vec3::splat(0.4), [5, 5, 5], CellSplit::Six).unwrap();
    let material = Material::new(2e5, 0.3, 1000.0).unwrap();
    SoftBody::build(
        &mesh,
        Vec3::new(0.0, 1.0, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap()
}

fn refused(w: &World, e: Entity) -> bool {
    matches!(
        w.get::<Quarantined>(e).map(|q| &q.reason),
        Some(QuarantineReason::InvalidInput(_))
    )
}

#[test]
fn a_soft_body_whose_nodes_are_emptied_or_outgrown_is_refused_not_indexed_out_of_bounds() {
    for implicit in [false, true] {
        let mut w = common::default_world();
        scenes::ground(&mut w).unwrap();
        let emptied = scenes::jelly(&mut w, Vec3::new(-1.0, 1.0, 0.0), implicit).unwrap();
        let outgrown = scenes::jelly(&mut w, Vec3::new(1.0, 1.0, 0.0), implicit).unwrap();
        let bystander = scenes::jelly(&mut w, Vec3::new(3.0, 1.0, 0.0), implicit).unwrap();
        for _ in 0..10 {
            w.step_physics();
        }
        w.entity_mut(emptied).insert(Nodes::new());
        w.entity_mut(outgrown).insert(bigger().1);
        for _ in 0..10 {
            w.step_physics();
        }
        assert!(refused(&w, emptied), "implicit {implicit}: emptied");
        assert!(refused(&w, outgrown), "implicit {implicit}: outgrown");
        assert!(w.get::<Quarantined>(bystander).is_none());
        let y = w.get::<Nodes>(bystander).unwrap().positions()[0].y;
        assert!(
            y.is_finite() && y < 1.0,
            "the rest of the world runs on: {y}"
        );
        println!(
            "implicit {implicit}: {:?}",
            w.get::<Quarantined>(outgrown).map(|q| &q.reason)
        );
    }
}

#[test]
fn a_soft_body_replaced_whole_mid_run_is_adopted() {
    for implicit in [false, true] {
        let mut w = common::default_world();
        scenes::ground(&mut w).unwrap();
        let e = scenes::jelly(&mut w, Vec3::new(0.0, 1.0, 0.0), implicit).unwrap();
        for _ in 0..10 {
            w.step_physics();
        }
        let (nodes, body) = bigger();
        let count = nodes.len();
        w.entity_mut(e).insert((nodes, body));
        for _ in 0..120 {
            w.step_physics();
        }
        assert!(w.get::<Quarantined>(e).is_none(), "implicit {implicit}");
        let n = w.get::<Nodes>(e).unwrap();
        assert_eq!(n.len(), count);
        let lowest = n.bounds().unwrap().0.y;
        println!(
            "implicit {implicit}: the bigger jelly rests with its lowest node at {lowest:.4} m"
        );
        assert!(lowest > -0.01 && lowest < 0.05, "{lowest}");
    }
}
