//! Reading TetGen and Gmsh meshes, and the line-numbered errors for bad files.

use glam::Vec3;
use hooke::Error;
use hooke::soft::{CellSplit, TetMesh};

/// A unit cube as TetGen would write it: 1-based, with comments and a boundary marker.
const NODE: &str = "# unit cube\n8 3 0 1\n1 0 0 0 1\n2 1 0 0 1\n3 0 1 0 1\n4 1 1 0 1\n5 0 0 1 1\n6 1 0 1 1\n7 0 1 1 1\n8 1 1 1 1\n";
const ELE: &str = "5 4 0\n1 2 1 4 6\n2 3 4 1 7\n3 5 6 7 1\n4 8 7 6 4\n5 1 4 6 7\n";

#[test]
fn tetgen_files_are_read() {
    let m = TetMesh::from_tetgen(NODE, ELE).unwrap();
    assert_eq!((m.points().len(), m.tets().len()), (8, 5));
    assert!((m.volume() - 1.0).abs() < 1e-6, "{}", m.volume());
    assert_eq!(m.surface().len(), 12);
    // And from disk, by stem or by either file.
    let dir = std::env::temp_dir().join(format!("hooke_tetgen_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("cube.node"), NODE).unwrap();
    std::fs::write(dir.join("cube.ele"), ELE).unwrap();
    for p in ["cube", "cube.node", "cube.ele"] {
        assert_eq!(TetMesh::load_tetgen(dir.join(p)).unwrap(), m);
    }
    let missing = TetMesh::load_tetgen(dir.join("nothing")).unwrap_err();
    assert!(
        matches!(missing, Error::MeshFile { line: 0, .. }),
        "{missing}"
    );
}

fn line_of(e: Error) -> (usize, String) {
    match e {
        Error::MeshFile { line, message, .. } => (line, message),
        other => panic!("not a mesh-file error: {other}"),
    }
}

#[test]
fn bad_tetgen_files_say_where() {
    let bad_number = NODE.replace("3 0 1 0 1", "3 0 one 0 1");
    let (line, msg) = line_of(TetMesh::from_tetgen(&bad_number, ELE).unwrap_err());
    assert_eq!(line, 5, "{msg}");
    let nan = NODE.replace("6 1 0 1 1", "6 1 NaN 1 1");
    assert_eq!(line_of(TetMesh::from_tetgen(&nan, ELE).unwrap_err()).0, 8);
    let unknown = ELE.replace("4 8 7 6 4", "4 8 7 6 9");
    let (line, msg) = line_of(TetMesh::from_tetgen(NODE, &unknown).unwrap_err());
    assert_eq!(line, 5, "{msg}");
    assert!(msg.contains("corner 9"), "{msg}");
    let flat = ELE.replace("5 1 4 6 7", "5 1 2 3 4");
    let (line, msg) = line_of(TetMesh::from_tetgen(NODE, &flat).unwrap_err());
    assert_eq!(line, 6, "{msg}");
    let short = "8 3 0 1\n1 0 0 0\n";
    assert!(
        line_of(TetMesh::from_tetgen(short, ELE).unwrap_err())
            .1
            .contains("ends")
    );
    let two_d = "8 2 0 0\n";
    assert!(
        line_of(TetMesh::from_tetgen(two_d, ELE).unwrap_err())
            .1
            .contains("dimension")
    );
}

/// A mesh written as Gmsh 2.2 ASCII, with a triangle (type 2) the reader must skip.
fn gmsh2(m: &TetMesh) -> String {
    let mut s = String::from(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"body\"\n$EndPhysicalNames\n$Nodes\n",
    );
    s += &format!("{}\n", m.points().len());
    for (i, p) in m.points().iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p.x, p.y, p.z);
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", m.tets().len() + 1);
    s += "1 2 2 0 1 1 2 3\n";
    for (k, t) in m.tets().iter().enumerate() {
        s += &format!(
            "{} 4 2 1 1 {} {} {} {}\n",
            k + 2,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        );
    }
    s + "$EndElements\n"
}

/// The same as Gmsh 4.1 ASCII: nodes and elements in entity blocks, tags offset by 100.
fn gmsh4(m: &TetMesh) -> String {
    let n = m.points().len();
    let mut s = String::from(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n$Nodes\n",
    );
    s += &format!("1 {n} 101 {}\n3 1 0 {n}\n", 100 + n);
    for i in 0..n {
        s += &format!("{}\n", 101 + i);
    }
    for p in m.points() {
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    s += &format!(
        "$EndNodes\n$Elements\n1 {0} 1 {0}\n3 1 4 {0}\n",
        m.tets().len()
    );
    for (k, t) in m.tets().iter().enumerate() {
        s += &format!(
            "{} {} {} {} {}\n",
            k + 1,
            t[0] + 101,
            t[1] + 101,
            t[2] + 101,
            t[3] + 101
        );
    }
    s + "$EndElements\n"
}

#[test]
fn gmsh_files_of_both_versions_give_the_mesh_back() {
    let m = TetMesh::cuboid(Vec3::new(1.0, 0.5, 0.25), [4, 2, 2], CellSplit::Five).unwrap();
    for (v, text) in [(2, gmsh2(&m)), (4, gmsh4(&m))] {
        let read = TetMesh::from_gmsh(&text).unwrap_or_else(|e| panic!("v{v}: {e}"));
        assert_eq!(read.tets().len(), m.tets().len(), "v{v}");
        assert!((read.volume() - m.volume()).abs() < 1e-5, "v{v}");
        assert_eq!(read.surface().len(), m.surface().len(), "v{v}");
    }
    let dir = std::env::temp_dir().join(format!("hooke_gmsh_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("box.msh");
    std::fs::write(&path, gmsh4(&m)).unwrap();
    assert_eq!(TetMesh::load_gmsh(&path).unwrap().tets().len(), 80);
}

#[test]
fn bad_gmsh_files_say_where() {
    let m = TetMesh::cuboid(Vec3::ONE, [1, 1, 1], CellSplit::Six).unwrap();
    let good = gmsh2(&m);
    let binary = good.replace("2.2 0 8", "2.2 1 8");
    assert_eq!(line_of(TetMesh::from_gmsh(&binary).unwrap_err()).0, 2);
    let v3 = good.replace("2.2 0 8", "3.0 0 8");
    assert!(
        line_of(TetMesh::from_gmsh(&v3).unwrap_err())
            .1
            .contains("format")
    );
    let unknown_node = good.replace("3 4 2 1 1 ", "3 4 2 1 1 99 ");
    let (line, msg) = line_of(TetMesh::from_gmsh(&unknown_node).unwrap_err());
    assert!(msg.contains("corner 99"), "{msg}");
    assert_eq!(
        good.lines().nth(line - 1).map(|l| l.starts_with("3 4")),
        Some(true)
    );
    let truncated: String = good.lines().take(14).map(|l| format!("{l}\n")).collect();
    assert!(
        line_of(TetMesh::from_gmsh(&truncated).unwrap_err())
            .1
            .contains("ends")
    );
    assert!(
        line_of(TetMesh::from_gmsh("hello\n").unwrap_err())
            .1
            .contains("not a Gmsh")
    );
    let missing = TetMesh::load_gmsh("/nonexistent/mesh.msh").unwrap_err();
    assert!(matches!(missing, Error::MeshFile { line: 0, .. }));
}
