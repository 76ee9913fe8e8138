//! Sizes that allocated until the process aborted are typed errors, checked before anything
//! is allocated: a cuboid mesh of 1024³ cells, a scenario column of 10⁹ boxes, a pyramid of
//! 2³² rows (whose box count overflows).

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::core::error::Error;
use hooke::soft::{CellSplit, TetMesh};
use hooke::tools::scenario::Scenario;
use hooke::tools::scenes;

#[test]
fn a_cuboid_mesh_past_its_cell_bound_is_a_typed_error() {
    let huge = TetMesh::cuboid(Vec3::ONE, [1024, 1024, 1024], CellSplit::Six);
    assert!(matches!(huge, Err(Error::TooMany { .. })), "{huge:?}");
    assert!(TetMesh::cuboid(Vec3::ONE, [8, 8, 8], CellSplit::Six).is_ok());
}

#[test]
fn scene_box_counts_past_their_bound_are_typed_errors() {
    let mut w = World::new();
    let before = w.entities().len();
    assert!(matches!(
        scenes::box_column(&mut w, 1_000_000_000),
        Err(Error::TooMany { .. })
    ));
    assert!(matches!(
        scenes::pyramid(&mut w, 1 << 32),
        Err(Error::TooMany { .. })
    ));
    assert!(matches!(
        scenes::pyramid(&mut w, usize::MAX),
        Err(Error::TooMany { .. })
    ));
    assert_eq!(w.entities().len(), before, "nothing was spawned");
}

#[test]
fn a_scenario_asking_for_a_billion_boxes_fails_to_build_not_to_allocate() {
    let text = r#"(
        name: "huge",
        duration: 0.1,
        entities: [(name: "column", spawn: Column(n: 1000000000))],
        expect: [],
    )"#;
    let scenario = Scenario::from_str(text, "huge.ron").expect("it reads");
    let run = scenario.run();
    match run {
        Ok(_) => panic!("built a billion boxes"),
        Err(e) => {
            println!("{e}");
            assert!(e.to_string().contains("at most"), "{e}");
        }
    }
}
