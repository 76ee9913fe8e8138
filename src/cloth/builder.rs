//! The grid cloth builder.

use bevy_ecs::prelude::*;
use glam::Vec3;

use super::Cloth;
use crate::core::error::{Error, Result, positive};
use crate::particles::Nodes;
use crate::springs::SpringNetwork;

/// A rectangular cloth as one [`Nodes`] + [`SpringNetwork`] + [`Cloth`]: structural springs to
/// the four neighbours, shear springs on both diagonals and bending springs that skip one
/// node, and two triangles per grid cell.
#[derive(Debug, Clone, PartialEq)]
pub struct ClothBuilder {
    origin: Vec3,
    nx: usize,
    nz: usize,
    spacing: f32,
    node_mass: f32,
    k_structural: f32,
    k_shear: f32,
    k_bend: f32,
    damping: [f32; 3],
    pin_corners: bool,
    thickness: Option<f32>,
}

impl ClothBuilder {
    /// A horizontal `nx` × `nz` cloth in the x–z plane starting at `origin`, nodes `spacing`
    /// m apart, 0.01 kg per node, k = 8 / 4 / 1 N/m (structural / shear / bend),
    /// c = 0.01 N·s/m, pinned at the two corners of its first row. A node feels about
    /// 4(k_structural + k_shear + k_bend), so ω_max ≈ 2√(52/0.01) ≈ 144 rad/s: stable for
    /// symplectic Euler at 60 Hz with 2 substeps or more.
    #[must_use]
    pub fn new(origin: Vec3, nx: usize, nz: usize, spacing: f32) -> Self {
        Self {
            origin,
            nx,
            nz,
            spacing,
            node_mass: 0.01,
            k_structural: 8.0,
            k_shear: 4.0,
            k_bend: 1.0,
            damping: [0.01; 3],
            pin_corners: true,
            thickness: None,
        }
    }

    /// Stiffnesses (N/m) of the structural, shear and bending springs.
    #[must_use]
    pub fn stiffness(mut self, structural: f32, shear: f32, bend: f32) -> Self {
        (self.k_structural, self.k_shear, self.k_bend) = (structural, shear, bend);
        self
    }

    /// How far the nodes keep from colliders (m; the cloth collides with every collider at
    /// [`Cloth`]'s default 0.01 m without it).
    #[must_use]
    pub fn thickness(mut self, metres: f32) -> Self {
        self.thickness = Some(metres);
        self
    }

    /// Mass of each node (kg).
    #[must_use]
    pub fn node_mass(mut self, kg: f32) -> Self {
        self.node_mass = kg;
        self
    }

    /// Damping c (N·s/m) of every spring.
    #[must_use]
    pub fn damping(mut self, c: f32) -> Self {
        self.damping = [c; 3];
        self
    }

    /// Damping (N·s/m) of the structural, shear and bending springs.
    #[must_use]
    pub fn family_damping(mut self, structural: f32, shear: f32, bend: f32) -> Self {
        self.damping = [structural, shear, bend];
        self
    }

    /// Whether the first row's two corners are pinned.
    #[must_use]
    pub fn pin_corners(mut self, pin: bool) -> Self {
        self.pin_corners = pin;
        self
    }

    /// Builds the arrays.
    ///
    /// # Errors
    /// [`Error::TooFew`] for a side under 3 nodes; errors of the node and spring constructors.
    pub fn build(&self) -> Result<(Nodes, SpringNetwork)> {
        for n in [self.nx, self.nz] {
            if n < 3 {
                return Err(Error::TooFew {
                    what: "cloth nodes per side",
                    min: 3,
                    got: n,
                });
            }
        }
        let s = positive("cloth spacing", self.spacing)?;
        let (nx, nz) = (self.nx, self.nz);
        // Refused before anything is allocated (the product may not even fit a usize).
        if nx
            .checked_mul(nz)
            .is_none_or(|n| n > crate::springs::MAX_BUILDER_NODES)
        {
            return Err(Error::OutOfRange {
                what: "cloth node count",
                value: nx as f32 * nz as f32,
                range: "at most 2^24",
            });
        }
        let mut nodes = Nodes::with_capacity(nx * nz);
        for j in 0..nz {
            for i in 0..nx {
                let x = self.origin + Vec3::new(i as f32 * s, 0.0, j as f32 * s);
                nodes.push(x, Vec3::ZERO, self.node_mass)?;
            }
        }
        if self.pin_corners {
            nodes.pin(0)?;
            nodes.pin(nx - 1)?;
        }
        let id = |i: usize, j: usize| j * nx + i;
        let mut net = SpringNetwork::new();
        let [c, c_shear, c_bend] = self.damping;
        let diag = s * std::f32::consts::SQRT_2;
        for j in 0..nz {
            for i in 0..nx {
                if i + 1 < nx {
                    net.push(id(i, j), id(i + 1, j), s, self.k_structural, c)?;
                }
                if j + 1 < nz {
                    net.push(id(i, j), id(i, j + 1), s, self.k_structural, c)?;
                }
                if i + 1 < nx && j + 1 < nz {
                    net.push(id(i, j), id(i + 1, j + 1), diag, self.k_shear, c_shear)?;
                    net.push(id(i + 1, j), id(i, j + 1), diag, self.k_shear, c_shear)?;
                }
                if i + 2 < nx {
                    net.push(id(i, j), id(i + 2, j), 2.0 * s, self.k_bend, c_bend)?;
                }
                if j + 2 < nz {
                    net.push(id(i, j), id(i, j + 2), 2.0 * s, self.k_bend, c_bend)?;
                }
            }
        }
        Ok((nodes, net))
    }

    /// Builds the arrays and the surface: two triangles per cell (counter-clockwise seen
    /// from +y for a cloth in the x–z plane), the structural springs for strain limiting.
    ///
    /// # Errors
    /// As [`ClothBuilder::build`].
    pub fn build_cloth(&self) -> Result<(Nodes, SpringNetwork, Cloth)> {
        let (nodes, net) = self.build()?;
        let (nx, nz) = (self.nx as u32, self.nz as u32);
        let id = |i: u32, j: u32| j * nx + i;
        let mut triangles = Vec::with_capacity(2 * (self.nx - 1) * (self.nz - 1));
        for j in 0..nz - 1 {
            for i in 0..nx - 1 {
                triangles.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
                triangles.push([id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)]);
            }
        }
        let structural = (0..net.len() as u32)
            .filter(|&s| {
                let [a, b] = net.ends()[s as usize];
                let (d, e) = (a.abs_diff(b), nx);
                d == 1 && a / nx == b / nx || d == e
            })
            .collect();
        let mut cloth = Cloth::new(triangles, structural, nodes.len());
        if let Some(t) = self.thickness {
            cloth = cloth.with_thickness(t)?;
        }
        Ok((nodes, net, cloth))
    }

    /// Builds and spawns the cloth as one entity ([`Nodes`], [`SpringNetwork`], [`Cloth`]).
    ///
    /// # Errors
    /// As [`ClothBuilder::build`].
    pub fn spawn(&self, world: &mut World) -> Result<Entity> {
        let parts = self.build_cloth()?;
        Ok(world.spawn(parts).id())
    }

    /// As [`ClothBuilder::spawn`], from a system's `Commands`.
    ///
    /// # Errors
    /// As [`ClothBuilder::build`].
    pub fn spawn_with(&self, commands: &mut Commands) -> Result<Entity> {
        let parts = self.build_cloth()?;
        Ok(commands.spawn(parts).id())
    }
}
