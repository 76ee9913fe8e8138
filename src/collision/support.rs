//! A convex hull's support function, four vertices at a time.
//!
//! parry finds a hull's support point by a scalar scan of its vertices, and its GJK and EPA
//! ask for one several times per pair and step: in Box3D's convex pile that scan was a fifth
//! of hooke's step. [`HullLanes`] keeps the vertices in structure-of-arrays form, and
//! four-wide products find the largest product and then the first vertex that has it: the
//! products are the scalar dot product's, in the same order, and ties go to the lowest index
//! as in parry, so contacts do not change by a bit. The face whose normal leads along a direction (parry's support
//! feature, asked once per manifold) is found the same way over the face normals.
//! [`LanedHull`] hands both to parry's hull-against-hull manifold, which takes any
//! [`PolygonalFeatureMap`].

use glam::Vec3;
use parry3d::shape::{
    ConvexPolyhedron, PackedFeatureId, PolygonalFeature, PolygonalFeatureMap, SupportMap,
};
use wide::f32x4;

/// A hull's vertices and face normals in columns.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HullLanes {
    /// The vertices.
    pub points: Columns,
    /// The face normals.
    pub normals: Columns,
}

impl HullLanes {
    /// The columns of `hull`'s vertices and face normals.
    #[must_use]
    pub fn new(hull: &ConvexPolyhedron) -> Option<Self> {
        let normals: Vec<Vec3> = hull.faces().iter().map(|f| f.normal).collect();
        Some(Self {
            points: Columns::new(hull.points())?,
            normals: Columns::new(&normals)?,
        })
    }
}

/// Vectors as columns of four, x, y and z of one column side by side (the last column
/// padded with copies of the first vector, which can never win a tie against it).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Columns(Box<[[f32x4; 3]]>);

impl Columns {
    /// The columns of `points`; `None` for no points.
    #[must_use]
    pub fn new(points: &[Vec3]) -> Option<Self> {
        let first = *points.first()?;
        let columns = points
            .chunks(4)
            .map(|c| {
                let mut lanes = [first; 4];
                lanes[..c.len()].copy_from_slice(c);
                [0, 1, 2].map(|axis| f32x4::new(lanes.map(|p| p[axis])))
            })
            .collect();
        Some(Self(columns))
    }

    /// The index of the first vector with the largest product with `dir` (0 if `dir` is not
    /// finite), the one parry's scalar scans pick.
    #[must_use]
    pub fn support_id(&self, dir: Vec3) -> usize {
        let (dx, dy, dz) = (
            f32x4::splat(dir.x),
            f32x4::splat(dir.y),
            f32x4::splat(dir.z),
        );
        let dot = |[x, y, z]: &[f32x4; 3]| *x * dx + *y * dy + *z * dz;
        // First the largest product; then the first column that holds it, computed again
        // the same way. Cheaper than carrying indices along, and the first index of the
        // maximum, as in parry's scan. A product that is not a number never equals the
        // largest: no column holds it, and the answer is 0, as in parry.
        let mut largest = dot(&self.0[0]);
        for column in &self.0[1..] {
            largest = largest.fast_max(dot(column));
        }
        let [a, b, c, d] = largest.to_array();
        let largest = f32x4::splat(a.max(b).max(c.max(d)));
        for (k, column) in self.0.iter().enumerate() {
            let hits = dot(column).simd_eq(largest).to_bitmask();
            if hits != 0 {
                return 4 * k + hits.trailing_zeros() as usize;
            }
        }
        0
    }
}

/// A parry hull with its [`HullLanes`]: parry's own hull in every query but the support
/// point and the support face, which come from the columns.
#[derive(Clone, Copy)]
pub(crate) struct LanedHull<'a> {
    /// The hull.
    pub hull: &'a ConvexPolyhedron,
    /// Its vertices in columns.
    pub lanes: &'a HullLanes,
}

impl SupportMap for LanedHull<'_> {
    #[inline]
    fn local_support_point(&self, dir: Vec3) -> Vec3 {
        self.hull.points()[self.lanes.points.support_id(dir)]
    }
}

impl PolygonalFeatureMap for LanedHull<'_> {
    /// parry's hull feature: the leading face's first four vertices and edges.
    #[inline]
    fn local_support_feature(&self, dir: Vec3, out_feature: &mut PolygonalFeature) {
        let fid = self.lanes.normals.support_id(dir);
        let face = &self.hull.faces()[fid];
        let first = face.first_vertex_or_edge as usize;
        let count = (face.num_vertices_or_edges as usize).min(4);
        let vertices = &self.hull.vertices_adj_to_face()[first..first + count];
        let edges = &self.hull.edges_adj_to_face()[first..first + count];
        for (i, (&v, &e)) in vertices.iter().zip(edges).enumerate() {
            out_feature.vertices[i] = self.hull.points()[v as usize];
            out_feature.vids[i] = PackedFeatureId::vertex(v);
            out_feature.eids[i] = PackedFeatureId::edge(e);
        }
        out_feature.fid = PackedFeatureId::face(fid as u32);
        out_feature.num_vertices = count;
    }

    fn is_convex_polyhedron(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vertex and the face parry's scalar scans pick, for every direction tried, on hulls whose
    /// vertex count leaves every padding (1 to 4 in the last column), and on ties.
    #[test]
    fn support_point_and_feature_are_parrys() {
        let mut state = 7u32;
        let mut unit = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        for n in [4usize, 5, 6, 7, 8, 13, 32, 61] {
            let points: Vec<Vec3> = (0..n).map(|_| Vec3::new(unit(), unit(), unit())).collect();
            let Some(hull) = ConvexPolyhedron::from_convex_hull(&points) else {
                continue;
            };
            let lanes = HullLanes::new(&hull).unwrap();
            let laned = LanedHull {
                hull: &hull,
                lanes: &lanes,
            };
            for _ in 0..500 {
                let dir = Vec3::new(unit(), unit(), unit());
                assert_eq!(
                    laned.local_support_point(dir),
                    hull.local_support_point(dir),
                    "{n} points, {dir}"
                );
                let (mut ours, mut parrys) = (PolygonalFeature::new(), PolygonalFeature::new());
                laned.local_support_feature(dir, &mut ours);
                hull.local_support_feature(dir, &mut parrys);
                assert_eq!(
                    format!("{ours:?}"),
                    format!("{parrys:?}"),
                    "{n} points, {dir}"
                );
            }
        }
        // Ties: a cube's corners along an axis (four share the largest product).
        let cube: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2) as f32))
            .collect();
        let lanes = Columns::new(&cube).unwrap();
        for dir in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, Vec3::ZERO, Vec3::NAN] {
            let scalar = parry3d::utils::point_cloud_support_point_id(dir, &cube);
            assert_eq!(lanes.support_id(dir), scalar, "{dir}");
        }
    }
}
