//! Counts read from files near the integer limits are typed errors, in a debug build too
//! (where arithmetic overflow panics; `.ci/run` runs this module in one): a Gmsh or TetGen
//! count of `usize::MAX`, a snapshot whose length field is near `u64::MAX`, a scenario
//! pyramid of 2³² rows, an index of `i64::MIN`, and a trace over 1.6·10⁷ s (which reserved
//! every row up front and aborted).

use bevy_ecs::prelude::*;
use hooke::core::error::Error;
use hooke::prelude::*;
use hooke::snapshot::{Snapshot, SnapshotError};
use hooke::soft::TetMesh;
use hooke::tools::scenario::{MAX_TRACE_ROWS, Scenario, ScenarioErrorKind};

const MAX: usize = usize::MAX;

fn mesh_file_error(r: Result<TetMesh, Error>) -> String {
    match r {
        Err(e @ Error::MeshFile { .. }) => e.to_string(),
        other => panic!("expected a MeshFile error, got {other:?}"),
    }
}

#[test]
fn gmsh_counts_at_the_integer_limit_are_typed_errors() {
    let nodes2 = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
    let cases = [
        // A tag count whose "3 + tags" overflowed.
        format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n{nodes2}$Elements\n1\n1 4 {MAX} 1 2 3 4\n$EndElements\n"
        ),
        format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n{nodes2}$Elements\n{MAX}\n1 4 0 1 2 3 4\n$EndElements\n"
        ),
        format!("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{MAX}\n1 0 0 0\n$EndNodes\n"),
        format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 {MAX}\n1\n$EndNodes\n"
        ),
        format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n{MAX} 4 1 4\n$EndNodes\n"),
        format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 {MAX}\n1 1 2 3 4\n$EndElements\n"
        ),
    ];
    for text in &cases {
        println!("{}", mesh_file_error(TetMesh::from_gmsh(text)));
    }
}

#[test]
fn tetgen_counts_at_the_integer_limit_are_typed_errors() {
    let node = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
    println!(
        "{}",
        mesh_file_error(TetMesh::from_tetgen(
            &format!("{MAX} 3 0 0\n1 0 0 0\n"),
            "1 4 0\n1 1 2 3 4\n"
        ))
    );
    println!(
        "{}",
        mesh_file_error(TetMesh::from_tetgen(
            node,
            &format!("{MAX} 4 0\n1 1 2 3 4\n")
        ))
    );
    println!(
        "{}",
        mesh_file_error(TetMesh::from_tetgen(
            node,
            &format!("1 4 0\n1 1 2 3 {}\n", i64::MAX)
        ))
    );
}

#[test]
fn a_snapshot_length_near_the_limit_is_a_typed_error() {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    let mut bytes = Snapshot::capture(&world).unwrap().to_bytes();
    for len in [u64::MAX, u64::MAX - 5, 1 << 63] {
        bytes[12..20].copy_from_slice(&len.to_le_bytes());
        match Snapshot::from_bytes(&bytes) {
            Err(SnapshotError::Truncated { expected, .. }) => assert!(expected >= len),
            other => panic!("length {len}: expected Truncated, got {:?}", other.err()),
        }
    }
}

fn load(text: &str) -> Result<Scenario, String> {
    Scenario::from_str(text, "hostile.ron").map_err(|e| e.to_string())
}

#[test]
fn a_scenario_pyramid_of_2_to_the_32_rows_is_refused_without_overflow() {
    let text = r#"(
        duration: 0.1,
        entities: [(name: "p", spawn: Pyramid(layers: 4294967296))],
        expect: [(check: Speed(entity: "p[-1]", max: 1.0))],
    )"#;
    let error = match load(text) {
        Err(e) => e,
        Ok(s) => s
            .run()
            .map(|_| ())
            .expect_err("built 2^63 boxes")
            .to_string(),
    };
    assert!(error.contains("at most"), "{error}");
    let text = r#"(
        duration: 0.1,
        entities: [(name: "p", spawn: Pyramid(layers: 4))],
        expect: [(check: Speed(entity: "p[-9223372036854775808]", max: 1.0))],
    )"#;
    let error = load(text).expect_err("an index of i64::MIN");
    assert!(error.contains("has 10 entities"), "{error}");
}

#[test]
fn a_trace_longer_than_its_bound_is_refused_when_read() {
    let text = r#"(
        duration: 16000000.0,
        entities: [(name: "ball", spawn: Particle(at: (0.0, 1.0, 0.0)))],
        expect: [],
        trace: ["ball"],
    )"#;
    let error = Scenario::from_str(text, "long.ron").expect_err("9.6e8 trace rows");
    assert!(
        matches!(error.kind, ScenarioErrorKind::BadValue(_)),
        "{error}"
    );
    assert!(
        error.to_string().contains(&MAX_TRACE_ROWS.to_string()),
        "{error}"
    );
    // Without the trace the same file reads (running it is the user's choice).
    let untraced = text.replace("trace: [\"ball\"],", "");
    let steps = load(&untraced).map(|s| s.steps());
    assert!(
        steps.as_ref().is_ok_and(|&n| n > MAX_TRACE_ROWS),
        "{steps:?}"
    );
}
