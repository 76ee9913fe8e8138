//! Tetrahedral meshes: validation, generators and surface extraction.

use glam::{Mat3, Vec3};

use crate::core::error::{Error, Result, finite_vec, positive};

/// How a hexahedral cell is cut into tetrahedra.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CellSplit {
    /// Five tetrahedra per cell (one central, four corners), alternating in a checkerboard so
    /// that faces match between cells. Fewer elements; a little stiffer.
    Five,
    /// Six tetrahedra around the cell's main diagonal (Kuhn's split): every cell alike.
    #[default]
    Six,
}

/// Rest positions (m) and tetrahedra (indices of four corners, positively oriented:
/// (x₁ − x₀) · ((x₂ − x₀) × (x₃ − x₀)) > 0).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TetMesh {
    points: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
}

/// The smallest rest volume accepted, relative to the cube of the mesh's mean edge length.
const FLAT: f32 = 1e-6;

impl TetMesh {
    /// A validated mesh. Negatively oriented tetrahedra are re-ordered (two corners swapped),
    /// so any consistent orientation is accepted.
    ///
    /// # Errors
    /// [`Error::TooFew`] for no tetrahedron, [`Error::NonFinite`] for a bad point,
    /// [`Error::IndexOutOfRange`] for a bad index, [`Error::DegenerateElement`] for a
    /// tetrahedron with repeated corners or (almost) no volume.
    pub fn new(points: Vec<Vec3>, mut tets: Vec<[u32; 4]>) -> Result<Self> {
        if tets.is_empty() {
            return Err(Error::TooFew {
                what: "tetrahedra",
                min: 1,
                got: 0,
            });
        }
        for p in &points {
            finite_vec("mesh point", *p)?;
        }
        let n = points.len();
        for t in &tets {
            for &i in t {
                if i as usize >= n {
                    return Err(Error::IndexOutOfRange {
                        what: "tetrahedron corner",
                        index: i as usize,
                        len: n,
                    });
                }
            }
        }
        let mean_edge = {
            let sum: f32 = tets
                .iter()
                .map(|t| (points[t[1] as usize] - points[t[0] as usize]).length())
                .sum();
            sum / tets.len() as f32
        };
        let tiny = FLAT * mean_edge.powi(3);
        for (k, t) in tets.iter_mut().enumerate() {
            let v = signed_volume(&points, *t);
            let distinct = t[0] != t[1] && t[0] != t[2] && t[0] != t[3];
            let distinct = distinct && t[1] != t[2] && t[1] != t[3] && t[2] != t[3];
            if !distinct || v.abs() <= tiny || !v.is_finite() {
                return Err(Error::DegenerateElement {
                    index: k,
                    volume: v,
                });
            }
            if v < 0.0 {
                t.swap(2, 3);
            }
        }
        Ok(Self { points, tets })
    }

    /// The most cells [`TetMesh::cuboid`] cuts a box into: 2²⁰ (up to 6.3 million
    /// tetrahedra).
    pub const MAX_CELLS: usize = 1 << 20;

    /// A box of `size` (full lengths, m) centred at the origin, cut into `cells` hexahedra
    /// along x, y, z and each of those into tetrahedra by `split`.
    ///
    /// # Errors
    /// [`Error::NotPositive`] for a bad size, [`Error::TooFew`] for a zero cell count or one
    /// over 1024 a side, [`Error::TooMany`] past [`TetMesh::MAX_CELLS`] in all.
    pub fn cuboid(size: Vec3, cells: [usize; 3], split: CellSplit) -> Result<Self> {
        for s in size.to_array() {
            positive("box size", s)?;
        }
        let [nx, ny, nz] = cells;
        let too_big = |c: usize| c == 0 || c > 1024;
        if cells.iter().any(|&c| too_big(c)) {
            return Err(Error::TooFew {
                what: "cells per side (1 to 1024)",
                min: 1,
                got: *cells.iter().find(|&&c| too_big(c)).unwrap_or(&0),
            });
        }
        // 1024 a side would be 10⁹ cells and 6·10⁹ tetrahedra: an allocation abort, not an
        // error. The whole box is bounded too.
        if nx * ny * nz > Self::MAX_CELLS {
            return Err(Error::TooMany {
                what: "cells in a cuboid mesh",
                max: Self::MAX_CELLS as u64,
                got: (nx * ny * nz) as u64,
            });
        }
        let id = |i: usize, j: usize, k: usize| ((k * (ny + 1) + j) * (nx + 1) + i) as u32;
        let mut points = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        let step = size / Vec3::new(nx as f32, ny as f32, nz as f32);
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    points.push(Vec3::new(i as f32, j as f32, k as f32) * step - 0.5 * size);
                }
            }
        }
        let mut tets = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    // Corners c[b] with bit 0 = +x, bit 1 = +y, bit 2 = +z.
                    let c: [u32; 8] = std::array::from_fn(|b| {
                        id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1))
                    });
                    match split {
                        CellSplit::Six => {
                            // Six paths from corner 0 to corner 7 along the edges.
                            for path in [[1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]] {
                                tets.push([c[0], c[path[0]], c[path[1]], c[7]]);
                            }
                        }
                        CellSplit::Five => {
                            // A checkerboard of the two mirror-image five-tet cuts, so that
                            // the diagonals of shared faces agree.
                            let (a, b, d, e) = if (i + j + k) % 2 == 0 {
                                (0, 3, 5, 6)
                            } else {
                                (1, 2, 4, 7)
                            };
                            let mut corners = |o: usize| {
                                let others: Vec<usize> = [a, b, d, e]
                                    .into_iter()
                                    .filter(|&x| neighbours(o, x))
                                    .collect();
                                tets.push([c[o], c[others[0]], c[others[1]], c[others[2]]]);
                            };
                            for o in (0..8).filter(|o| ![a, b, d, e].contains(o)) {
                                corners(o);
                            }
                            tets.push([c[a], c[b], c[d], c[e]]);
                        }
                    }
                }
            }
        }
        Self::new(points, tets)
    }

    /// A ball of `radius` (m): the cells of a `resolution`³ grid over its bounding cube whose
    /// centres lie inside, each split in six. A stair-stepped sphere of the right volume to
    /// within the grid's resolution.
    ///
    /// # Errors
    /// [`Error::NotPositive`] for a bad radius, [`Error::TooFew`] for a resolution below 2.
    pub fn ball(radius: f32, resolution: usize) -> Result<Self> {
        positive("ball radius", radius)?;
        if !(2..=256).contains(&resolution) {
            return Err(Error::TooFew {
                what: "ball resolution (2 to 256)",
                min: 2,
                got: resolution,
            });
        }
        let cube = Self::cuboid(Vec3::splat(2.0 * radius), [resolution; 3], CellSplit::Six)?;
        let mut kept = Vec::new();
        for cell in cube.tets.chunks(6) {
            // Corners 0 and 7 of the cell are the first and last of each of its tets.
            let centre =
                0.5 * (cube.points[cell[0][0] as usize] + cube.points[cell[0][3] as usize]);
            if centre.length() <= radius {
                kept.extend_from_slice(cell);
            }
        }
        // Drop the points no tetrahedron uses, renumbering.
        let mut map = vec![u32::MAX; cube.points.len()];
        let mut points = Vec::new();
        for t in &mut kept {
            for i in t.iter_mut() {
                if map[*i as usize] == u32::MAX {
                    map[*i as usize] = points.len() as u32;
                    points.push(cube.points[*i as usize]);
                }
                *i = map[*i as usize];
            }
        }
        Self::new(points, kept)
    }

    /// Rest positions (m).
    #[must_use]
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// Tetrahedra, positively oriented.
    #[must_use]
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Total rest volume (m³).
    #[must_use]
    pub fn volume(&self) -> f32 {
        self.tets
            .iter()
            .map(|t| signed_volume(&self.points, *t))
            .sum()
    }

    /// The boundary: every triangle that belongs to exactly one tetrahedron, wound so that
    /// its normal points out of the body. For rendering and contact.
    #[must_use]
    pub fn surface(&self) -> Vec<[u32; 3]> {
        surface_of(&self.tets)
    }
}

/// Whether two corners of a unit cell (bit-coded) share an edge.
fn neighbours(a: usize, b: usize) -> bool {
    (a ^ b).count_ones() == 1
}

/// The volume of tetrahedron `t` (m³), positive for positive orientation.
#[must_use]
pub fn signed_volume(points: &[Vec3], t: [u32; 4]) -> f32 {
    let p = |i: usize| points[t[i] as usize];
    let m = Mat3::from_cols(p(1) - p(0), p(2) - p(0), p(3) - p(0));
    m.determinant() / 6.0
}

/// The boundary of `tets`: every triangle that belongs to exactly one tetrahedron, wound so
/// that its normal points out of a positively oriented mesh.
#[must_use]
pub(crate) fn surface_of(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(4 * tets.len());
    for t in tets {
        // Outward-wound faces of a positively oriented tet.
        for f in [
            [t[1], t[2], t[3]],
            [t[0], t[3], t[2]],
            [t[0], t[1], t[3]],
            [t[0], t[2], t[1]],
        ] {
            let mut key = f;
            key.sort_unstable();
            faces.push((key, f));
        }
    }
    faces.sort_unstable_by_key(|f| f.0);
    let mut out = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            out.push(faces[i].1);
        }
        i = j;
    }
    out
}
