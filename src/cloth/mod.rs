//! Cloth: a triangle surface over a [`Nodes`] + [`SpringNetwork`] mesh, with wind, strain
//! limiting, collisions and what a renderer needs.
//!
//! The springs are the spring module's (the same [`crate::springs::spring_force`], explicit or
//! in the backward-Euler solve with [`crate::integrator::ImplicitEuler`]); [`Cloth`] adds the surface:
//!
//! - **Generators.** [`crate::cloth::ClothBuilder`] makes a grid (structural, shear and bend
//!   springs); [`Cloth::from_triangles`] any triangle mesh: a structural spring per edge and a
//!   bending spring across each edge two triangles share (between their opposite corners).
//!   A triangle mesh's edges carry its shear. Nodes get the lumped mass ρ A / 3 of each
//!   triangle touching them (ρ in kg/m²).
//! - **Wind and drag.** Each triangle of area A and unit normal n̂ moving at v (its corners'
//!   mean) through air moving at u (the sum of the world's [`crate::particles::VelocityField`]s at its
//!   centroid) feels f = −c_d A ((v − u)·n̂) n̂, shared by its corners: air pushes on the
//!   cloth's face only, so a flag in a steady wind streams out and flutters.
//! - **Strain limiting** (Provot 1995). After each substep, a structural spring stretched past
//!   (1 + s_max) r is shortened back to it by moving its ends towards each other (by their
//!   inverse masses), and their relative velocity along it is removed, in a few Gauss–Seidel
//!   passes: a cloth does not stretch like rubber whatever its springs.
//! - **Collisions.** Nodes and triangles collide with colliders through the mesh contacts that
//!   soft bodies use ([`crate::collision`]'s contact layer with a thickness and friction, two-way
//!   with dynamic bodies): a ball smaller than the node spacing, a thin plank or a crate thrown
//!   down at 20 m/s lands on the cloth between its nodes. Self-collision is not handled.
//! - **Rendering.** [`Cloth::triangles`] (and [`Cloth::indices`]) with the node positions
//!   and the area-weighted vertex normals [`Cloth::normals`], refreshed at the end of each
//!   step.

mod builder;
mod plugin;

pub use builder::ClothBuilder;
pub use plugin::ClothPlugin;

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::core::error::{Error, Result, finite_vec, non_negative, positive};
use crate::integrator::implicit::ContactPlane;
use crate::particles::Nodes;
use crate::springs::SpringNetwork;

/// A cloth's surface over the [`Nodes`] and [`SpringNetwork`] on the same entity (see the
/// module docs).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Cloth {
    triangles: Vec<[u32; 3]>,
    /// The springs strain limiting holds (the structural ones).
    structural: Vec<u32>,
    /// The largest corner index and the largest structural spring index (both fixed at
    /// construction), so one comparison per step proves a mesh still fits.
    max_corner: u32,
    max_structural: Option<u32>,
    normals: Vec<Vec3A>,
    drag: f32,
    strain_limit: Option<f32>,
    thickness: f32,
    pub(crate) contacts: Vec<ContactPlane>,
}

/// The springs of a cloth made from triangles: stiffness k (N/m) and damping c (N·s/m) of
/// each family, and the cloth's areal density (kg/m²).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct ClothMaterial {
    /// Areal density ρ (kg/m²); default 0.2 (a cotton sheet).
    pub density: f32,
    /// Edge springs: stiffness (N/m) and damping (N·s/m); default (500, 0.5).
    pub structural: (f32, f32),
    /// Springs across shared edges: default (5, 0.05).
    pub bend: (f32, f32),
}

impl Default for ClothMaterial {
    fn default() -> Self {
        Self {
            density: 0.2,
            structural: (500.0, 0.5),
            bend: (5.0, 0.05),
        }
    }
}

fn check_node(index: usize, len: usize) -> Result<u32> {
    if index >= len {
        return Err(Error::IndexOutOfRange {
            what: "cloth triangle corner",
            index,
            len,
        });
    }
    u32::try_from(index).map_err(|_| Error::IndexOutOfRange {
        what: "cloth triangle corner",
        index,
        len: u32::MAX as usize,
    })
}

impl Cloth {
    /// A cloth from `positions` (m) and `triangles` (corner indices): the nodes with their
    /// lumped masses, a structural spring per edge and a bending spring across each edge two
    /// triangles share, and the surface. Nothing is pinned ([`Nodes::pin`] the nodes to hold).
    ///
    /// # Errors
    /// [`Error::TooFew`] without triangles, [`Error::IndexOutOfRange`] for a corner past the
    /// positions, [`Error::DegenerateTriangle`] for repeated corners or an area below
    /// 1e-12 m², [`Error::NonFinite`] for a bad position, and the material's errors
    /// ([`Error::NotPositive`] density, [`Error::Negative`] or [`Error::NonFinite`]
    /// coefficients).
    pub fn from_triangles(
        positions: &[Vec3],
        triangles: &[[usize; 3]],
        material: ClothMaterial,
    ) -> Result<(Nodes, SpringNetwork, Cloth)> {
        if triangles.is_empty() {
            return Err(Error::TooFew {
                what: "cloth triangles",
                min: 1,
                got: 0,
            });
        }
        let density = positive("cloth density", material.density)?;
        let (ks, cs) = (
            non_negative("structural stiffness", material.structural.0)?,
            non_negative("structural damping", material.structural.1)?,
        );
        let (kb, cb) = (
            non_negative("bend stiffness", material.bend.0)?,
            non_negative("bend damping", material.bend.1)?,
        );
        for &x in positions {
            finite_vec("cloth node position", x)?;
        }
        let len = positions.len();
        let mut tris = Vec::with_capacity(triangles.len());
        let mut mass = vec![0.0f32; len];
        for (t, corners) in triangles.iter().enumerate() {
            let [a, b, c] = [
                check_node(corners[0], len)?,
                check_node(corners[1], len)?,
                check_node(corners[2], len)?,
            ];
            let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize]);
            let area = 0.5 * (pb - pa).cross(pc - pa).length();
            let flat = area.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater);
            if a == b || b == c || a == c || flat {
                return Err(Error::DegenerateTriangle { index: t, area });
            }
            for i in [a, b, c] {
                mass[i as usize] += density * area / 3.0;
            }
            tris.push([a, b, c]);
        }
        let mut nodes = Nodes::with_capacity(len);
        for (i, &x) in positions.iter().enumerate() {
            if mass[i] > 0.0 {
                nodes.push(x, Vec3::ZERO, mass[i])?;
            } else {
                // A node no triangle touches is held where it is rather than massless.
                nodes.push_pinned(x)?;
            }
        }
        // Each edge once, with the corners opposite it (one for a border edge, two inside).
        let mut edges: std::collections::BTreeMap<(u32, u32), Vec<u32>> = Default::default();
        for &[a, b, c] in &tris {
            for (p, q, o) in [(a, b, c), (b, c, a), (c, a, b)] {
                edges.entry((p.min(q), p.max(q))).or_default().push(o);
            }
        }
        let mut net = SpringNetwork::new();
        let mut structural = Vec::with_capacity(edges.len());
        let rest = |p: u32, q: u32| (positions[q as usize] - positions[p as usize]).length();
        for (&(p, q), _) in edges.iter() {
            let i = net.push(p as usize, q as usize, rest(p, q), ks, cs)?;
            structural.push(i as u32);
        }
        if kb > 0.0 {
            for opposite in edges.values() {
                if let [o1, o2] = opposite[..]
                    && o1 != o2
                {
                    net.push(o1 as usize, o2 as usize, rest(o1, o2), kb, cb)?;
                }
            }
        }
        let cloth = Cloth::new(tris, structural, len);
        Ok((nodes, net, cloth))
    }

    pub(crate) fn new(triangles: Vec<[u32; 3]>, structural: Vec<u32>, nodes: usize) -> Self {
        Self {
            max_corner: triangles.iter().flatten().copied().max().unwrap_or(0),
            max_structural: structural.iter().copied().max(),
            triangles,
            structural,
            normals: vec![Vec3A::ZERO; nodes],
            drag: 0.0,
            strain_limit: None,
            thickness: 0.01,
            contacts: Vec::new(),
        }
    }

    /// Aerodynamic drag c_d (N·s/m³: newtons per square metre per m/s of face-on relative
    /// speed; see the module docs). 0 (the default) for none; about 1 for a light flag.
    ///
    /// # Errors
    /// [`Error::Negative`] or [`Error::NonFinite`].
    pub fn with_drag(mut self, c_d: f32) -> Result<Self> {
        self.drag = non_negative("cloth drag", c_d)?;
        Ok(self)
    }

    /// Limits the structural springs' strain to `s_max` (e.g. 0.1 for 10 %); None (the
    /// default) for no limit.
    ///
    /// # Errors
    /// [`Error::NotPositive`] or [`Error::NonFinite`].
    pub fn with_strain_limit(mut self, s_max: Option<f32>) -> Result<Self> {
        self.strain_limit = s_max.map(|s| positive("strain limit", s)).transpose()?;
        Ok(self)
    }

    /// The contact layer's thickness (m, default 0.01): nodes keep this far from colliders.
    ///
    /// # Errors
    /// [`Error::Negative`] or [`Error::NonFinite`].
    pub fn with_thickness(mut self, metres: f32) -> Result<Self> {
        self.thickness = non_negative("cloth thickness", metres)?;
        Ok(self)
    }

    /// The triangles (node indices, counter-clockwise as given).
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The triangles as a flat index list (three per triangle), as renderers take them.
    #[must_use]
    pub fn indices(&self) -> Vec<u32> {
        self.triangles.iter().flatten().copied().collect()
    }

    /// Unit vertex normals (area-weighted over the triangles at each node), as of the end of
    /// the last step; zero before the first step.
    #[must_use]
    pub fn normals(&self) -> &[Vec3A] {
        &self.normals
    }

    /// The drag coefficient c_d (N·s/m³).
    #[must_use]
    pub fn drag(&self) -> f32 {
        self.drag
    }

    /// The strain limit, if any.
    #[must_use]
    pub fn strain_limit(&self) -> Option<f32> {
        self.strain_limit
    }

    /// The largest strain (l − r)/r over the structural springs on `nodes`.
    #[must_use]
    pub fn max_strain(&self, nodes: &Nodes, springs: &SpringNetwork) -> f32 {
        self.structural
            .iter()
            .filter_map(|&i| springs.reading(i as usize, nodes))
            .map(|r| r.strain)
            .fold(0.0, f32::max)
    }

    /// Whether the recorded largest indices are the real ones (see [`Nodes::consistent`]).
    pub(crate) fn consistent(&self, nodes: usize) -> bool {
        self.max_corner == self.triangles.iter().flatten().copied().max().unwrap_or(0)
            && self.max_structural == self.structural.iter().copied().max()
            && self.contacts.iter().all(|c| (c.node as usize) < nodes)
    }

    /// Whether every triangle indexes into `nodes`.
    pub(crate) fn fits(&self, nodes: &Nodes) -> bool {
        (self.triangles.is_empty() || (self.max_corner as usize) < nodes.len())
            && self.normals.len() == nodes.len()
    }

    /// Whether every structural spring indexes into `springs` (game code may have replaced
    /// the network with another).
    pub(crate) fn fits_springs(&self, springs: &SpringNetwork) -> bool {
        self.max_structural
            .is_none_or(|m| (m as usize) < springs.len())
    }
}

impl crate::collision::nodes::NodeLayer for Cloth {
    fn thickness(&self) -> f32 {
        self.thickness
    }

    fn contacts_mut(&mut self) -> &mut Vec<ContactPlane> {
        &mut self.contacts
    }

    fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}
