//! Colliders from Bevy meshes (feature `collider-from-mesh`): a triangle mesh, a convex hull
//! or a convex decomposition of a `bevy_mesh::Mesh`'s triangles.

use bevy_mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use glam::Vec3;
use parry3d::shape::SharedShape;

use super::Collider;
use crate::core::error::{Error, Result, finite_vec};

/// The mesh's vertex positions and triangles: a triangle list, indexed or not.
fn triangles(mesh: &Mesh) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(Error::UnsupportedMesh(format!(
            "a {:?} mesh: only triangle lists make colliders",
            mesh.primitive_topology()
        )));
    }
    let positions = match mesh.try_attribute_option(Mesh::ATTRIBUTE_POSITION) {
        Ok(Some(VertexAttributeValues::Float32x3(p))) => p,
        Ok(Some(_)) => {
            return Err(Error::UnsupportedMesh(
                "positions that are not Float32x3".into(),
            ));
        }
        Ok(None) => return Err(Error::UnsupportedMesh("no vertex positions".into())),
        Err(e) => return Err(Error::UnsupportedMesh(format!("{e}"))),
    };
    let vertices: Vec<Vec3> = positions.iter().map(|p| Vec3::from_array(*p)).collect();
    for v in &vertices {
        finite_vec("mesh vertex", *v)?;
    }
    let flat: Vec<u32> = match mesh.try_indices_option() {
        Ok(Some(Indices::U16(i))) => i.iter().map(|&i| u32::from(i)).collect(),
        Ok(Some(Indices::U32(i))) => i.clone(),
        Ok(None) => (0..vertices.len() as u32).collect(),
        Err(e) => return Err(Error::UnsupportedMesh(format!("{e}"))),
    };
    if !flat.len().is_multiple_of(3) {
        return Err(Error::UnsupportedMesh(format!(
            "{} indices, not a whole number of triangles",
            flat.len()
        )));
    }
    let tris = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    Ok((vertices, tris))
}

impl Collider {
    /// A triangle-mesh collider with the mesh's triangles (hollow: for static level
    /// geometry; a dynamic body is better served by [`Collider::convex_hull_from_mesh`] or
    /// [`Collider::convex_decomposition_from_mesh`]).
    ///
    /// # Errors
    /// [`Error::UnsupportedMesh`] for a mesh that is not a triangle list of `Float32x3`
    /// positions, and the errors of [`Collider::trimesh`] (no triangles, an index past the
    /// vertices, degenerate geometry).
    pub fn trimesh_from_mesh(mesh: &Mesh) -> Result<Self> {
        let (vertices, tris) = triangles(mesh)?;
        Self::trimesh(vertices, tris)
    }

    /// The convex hull of the mesh's vertices.
    ///
    /// # Errors
    /// [`Error::UnsupportedMesh`] as [`Collider::trimesh_from_mesh`]; [`Error::TooFew`] for a
    /// mesh whose vertices are fewer than four or all in one plane.
    pub fn convex_hull_from_mesh(mesh: &Mesh) -> Result<Self> {
        let (vertices, _) = triangles(mesh)?;
        Self::convex_hull(&vertices)
    }

    /// The mesh split into convex parts (parry's approximate convex decomposition, V-HACD),
    /// as one compound collider: a concave dynamic body.
    ///
    /// # Errors
    /// As [`Collider::trimesh_from_mesh`]; [`Error::UnsupportedMesh`] when the
    /// decomposition finds no part with volume.
    pub fn convex_decomposition_from_mesh(mesh: &Mesh) -> Result<Self> {
        let (vertices, tris) = triangles(mesh)?;
        // The same checks as a trimesh: triangles exist and their indices are in range.
        Self::trimesh(vertices.clone(), tris.clone())?;
        let shape =
            std::panic::catch_unwind(|| SharedShape::convex_decomposition(&vertices, &tris))
                .map_err(|_| Error::UnsupportedMesh("the convex decomposition failed".into()))?;
        let has_volume = shape.mass_properties(1.0).mass() > 0.0;
        if !has_volume {
            return Err(Error::UnsupportedMesh(
                "the convex decomposition has no volume (a flat mesh?)".into(),
            ));
        }
        Self::new(shape)
    }
}
