//! Reading tetrahedral meshes: TetGen `.node`/`.ele` and Gmsh `.msh` (ASCII, versions 2 and 4).
//!
//! Every error names the file and the line. Only linear tetrahedra are read: TetGen's
//! 10-node elements and Gmsh's second-order tets (type 11) keep their four corners; other
//! Gmsh element types (points, lines, triangles: the boundary) are skipped.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;

use super::TetMesh;
use crate::core::error::{Error, Result};

/// The non-empty, non-comment lines of a file, with their 1-based numbers.
struct Lines<'a> {
    file: &'a str,
    lines: Vec<(usize, &'a str)>,
    at: usize,
}

impl<'a> Lines<'a> {
    fn new(file: &'a str, text: &'a str) -> Self {
        let lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
            .filter(|(_, l)| !l.is_empty())
            .collect();
        Self { file, lines, at: 0 }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::MeshFile {
            file: self.file.to_string(),
            line,
            message: message.into(),
        }
    }

    /// The next line's number and its whitespace-separated fields.
    fn next(&mut self, what: &str) -> Result<(usize, Vec<&'a str>)> {
        let last = self.lines.last().map_or(0, |l| l.0);
        let (n, l) = *self
            .lines
            .get(self.at)
            .ok_or_else(|| self.error(last + 1, format!("file ends before {what}")))?;
        self.at += 1;
        Ok((n, l.split_whitespace().collect()))
    }

    fn number<T: std::str::FromStr>(
        &self,
        line: usize,
        field: Option<&&str>,
        what: &str,
    ) -> Result<T> {
        let f = field.ok_or_else(|| self.error(line, format!("missing {what}")))?;
        f.parse()
            .map_err(|_| self.error(line, format!("{what} is not a number: {f:?}")))
    }

    fn point(&self, line: usize, fields: &[&str]) -> Result<Vec3> {
        let c: [f32; 3] = [
            self.number(line, fields.first(), "x")?,
            self.number(line, fields.get(1), "y")?,
            self.number(line, fields.get(2), "z")?,
        ];
        let p = Vec3::from_array(c);
        if !p.is_finite() {
            return Err(self.error(line, format!("coordinates must be finite, got {p}")));
        }
        Ok(p)
    }
}

/// Node ids as written in a file, mapped to indices; the element's corners resolved.
fn corners(
    lines: &Lines,
    line: usize,
    ids: &HashMap<i64, u32>,
    fields: &[&str],
) -> Result<[u32; 4]> {
    let mut t = [0u32; 4];
    for (k, slot) in t.iter_mut().enumerate() {
        let id: i64 = lines.number(line, fields.get(k), "corner")?;
        *slot = *ids
            .get(&id)
            .ok_or_else(|| lines.error(line, format!("corner {id} is not a node of the file")))?;
    }
    Ok(t)
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| Error::MeshFile {
        file: path.display().to_string(),
        line: 0,
        message: format!("cannot read: {e}"),
    })
}

/// Whether validation errors can be pinned to a line: the element's line in the file.
fn validated(
    points: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
    lines: &Lines,
    tet_lines: &[usize],
) -> Result<TetMesh> {
    TetMesh::new(points, tets).map_err(|e| match e {
        Error::DegenerateElement { index, volume } => lines.error(
            tet_lines.get(index).copied().unwrap_or(0),
            format!("tetrahedron is degenerate (rest volume {volume} m³)"),
        ),
        other => other,
    })
}

impl TetMesh {
    /// A mesh from the text of a TetGen `.node` file and its `.ele` file.
    ///
    /// # Errors
    /// [`Error::MeshFile`] with the file and line for anything malformed, an unknown corner,
    /// a non-finite coordinate or a degenerate tetrahedron.
    pub fn from_tetgen(node: &str, ele: &str) -> Result<Self> {
        let mut nl = Lines::new(".node", node);
        let (line, head) = nl.next("the header")?;
        let count: usize = nl.number(line, head.first(), "point count")?;
        let dim: usize = nl.number(line, head.get(1), "dimension")?;
        if dim != 3 {
            return Err(nl.error(line, format!("dimension must be 3, got {dim}")));
        }
        let mut points = Vec::with_capacity(count.min(1 << 24));
        let mut ids = HashMap::new();
        for _ in 0..count {
            let (line, f) = nl.next("all the points")?;
            let id: i64 = nl.number(line, f.first(), "point number")?;
            if ids.insert(id, points.len() as u32).is_some() {
                return Err(nl.error(line, format!("point {id} appears twice")));
            }
            points.push(nl.point(line, &f[1..])?);
        }
        let mut el = Lines::new(".ele", ele);
        let (line, head) = el.next("the header")?;
        let count: usize = el.number(line, head.first(), "tetrahedron count")?;
        let per: usize = el.number(line, head.get(1), "nodes per tetrahedron")?;
        if per != 4 && per != 10 {
            return Err(el.error(
                line,
                format!("nodes per tetrahedron must be 4 or 10, got {per}"),
            ));
        }
        let (mut tets, mut tet_lines) = (Vec::new(), Vec::new());
        for _ in 0..count {
            let (line, f) = el.next("all the tetrahedra")?;
            tets.push(corners(&el, line, &ids, &f[1..])?);
            tet_lines.push(line);
        }
        validated(points, tets, &el, &tet_lines)
    }

    /// Reads `path.node` and `path.ele` (give the path without extension, or either file).
    ///
    /// # Errors
    /// As [`TetMesh::from_tetgen`], and [`Error::MeshFile`] (line 0) for a file that cannot be
    /// read.
    pub fn load_tetgen(path: impl AsRef<Path>) -> Result<Self> {
        let p = path.as_ref();
        let stem = match p.extension().and_then(|e| e.to_str()) {
            Some("node" | "ele") => p.with_extension(""),
            _ => p.to_path_buf(),
        };
        let (node_path, ele_path) = (stem.with_extension("node"), stem.with_extension("ele"));
        let (node, ele) = (read(&node_path)?, read(&ele_path)?);
        Self::from_tetgen(&node, &ele).map_err(|e| match e {
            Error::MeshFile {
                file,
                line,
                message,
            } => Error::MeshFile {
                file: if file == ".node" {
                    node_path.display().to_string()
                } else {
                    ele_path.display().to_string()
                },
                line,
                message,
            },
            other => other,
        })
    }

    /// A mesh from the text of a Gmsh `.msh` file, ASCII format 2 or 4.
    ///
    /// # Errors
    /// [`Error::MeshFile`] with the line for a binary or unknown format, a missing section,
    /// malformed numbers, unknown nodes or degenerate tetrahedra.
    pub fn from_gmsh(text: &str) -> Result<Self> {
        Self::from_gmsh_named(text, ".msh")
    }

    fn from_gmsh_named(text: &str, file: &str) -> Result<Self> {
        let mut l = Lines::new(file, text);
        let mut version = None;
        let (mut points, mut ids) = (Vec::new(), HashMap::new());
        let (mut tets, mut tet_lines) = (Vec::new(), Vec::new());
        while l.at < l.lines.len() {
            let (line, f) = l.next("a section")?;
            match f.first().copied() {
                Some("$MeshFormat") => {
                    let (line, f) = l.next("the format line")?;
                    let v: f32 = l.number(line, f.first(), "format version")?;
                    let binary: u32 = l.number(line, f.get(1), "file type")?;
                    if binary != 0 {
                        return Err(l.error(line, "binary .msh files are not read; save as ASCII"));
                    }
                    if !(2.0..5.0).contains(&v) || (3.0..4.0).contains(&v) {
                        return Err(l.error(line, format!("format {v} is not read (2.x or 4.x)")));
                    }
                    version = Some(v);
                }
                Some("$Nodes") => {
                    let v = version.ok_or_else(|| l.error(line, "$Nodes before $MeshFormat"))?;
                    if v < 3.0 {
                        let (line, f) = l.next("the node count")?;
                        let n: usize = l.number(line, f.first(), "node count")?;
                        for _ in 0..n {
                            let (line, f) = l.next("all the nodes")?;
                            let id: i64 = l.number(line, f.first(), "node tag")?;
                            ids.insert(id, points.len() as u32);
                            points.push(l.point(line, &f[1..])?);
                        }
                    } else {
                        let (line, f) = l.next("the node header")?;
                        let blocks: usize = l.number(line, f.first(), "entity block count")?;
                        for _ in 0..blocks {
                            let (line, f) = l.next("a node block")?;
                            let n: usize = l.number(line, f.get(3), "nodes in block")?;
                            let mut tags = Vec::with_capacity(n.min(1 << 24));
                            for _ in 0..n {
                                let (line, f) = l.next("the node tags")?;
                                tags.push(l.number::<i64>(line, f.first(), "node tag")?);
                            }
                            for tag in tags {
                                let (line, f) = l.next("the node coordinates")?;
                                ids.insert(tag, points.len() as u32);
                                points.push(l.point(line, &f)?);
                            }
                        }
                    }
                    l.next("$EndNodes")?;
                }
                Some("$Elements") => {
                    let v = version.ok_or_else(|| l.error(line, "$Elements before $MeshFormat"))?;
                    if v < 3.0 {
                        let (line, f) = l.next("the element count")?;
                        let n: usize = l.number(line, f.first(), "element count")?;
                        for _ in 0..n {
                            let (line, f) = l.next("all the elements")?;
                            let kind: u32 = l.number(line, f.get(1), "element type")?;
                            let tags: usize = l.number(line, f.get(2), "tag count")?;
                            if kind == 4 || kind == 11 {
                                let start = tags.saturating_add(3);
                                tets.push(corners(&l, line, &ids, f.get(start..).unwrap_or(&[]))?);
                                tet_lines.push(line);
                            }
                        }
                    } else {
                        let (line, f) = l.next("the element header")?;
                        let blocks: usize = l.number(line, f.first(), "entity block count")?;
                        for _ in 0..blocks {
                            let (line, f) = l.next("an element block")?;
                            let kind: u32 = l.number(line, f.get(2), "element type")?;
                            let n: usize = l.number(line, f.get(3), "elements in block")?;
                            for _ in 0..n {
                                let (line, f) = l.next("the block's elements")?;
                                if kind == 4 || kind == 11 {
                                    tets.push(corners(&l, line, &ids, &f[1..])?);
                                    tet_lines.push(line);
                                }
                            }
                        }
                    }
                    l.next("$EndElements")?;
                }
                Some(section) if section.starts_with('$') && !section.starts_with("$End") => {
                    // A section we don't need ($PhysicalNames, $Entities, ...): skip to its end.
                    let end = format!("$End{}", &section[1..]);
                    loop {
                        let (_, f) = l.next(&end)?;
                        if f.first() == Some(&end.as_str()) {
                            break;
                        }
                    }
                }
                _ => {}
            }
        }
        if version.is_none() {
            return Err(l.error(1, "no $MeshFormat section: not a Gmsh file"));
        }
        if tets.is_empty() {
            return Err(l.error(
                l.lines.last().map_or(0, |x| x.0),
                "no tetrahedra (element types 4 or 11)",
            ));
        }
        validated(points, tets, &l, &tet_lines)
    }

    /// Reads a Gmsh `.msh` file (ASCII, format 2 or 4).
    ///
    /// # Errors
    /// As [`TetMesh::from_gmsh`], and [`Error::MeshFile`] (line 0) for a file that cannot be
    /// read.
    pub fn load_gmsh(path: impl AsRef<Path>) -> Result<Self> {
        let p = path.as_ref();
        Self::from_gmsh_named(&read(p)?, &p.display().to_string())
    }
}
