//! Structure-of-arrays particles for meshes (ropes as one component, cloth, soft bodies).

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};

use crate::core::error::{Error, Result, finite_vec};

/// Many particles in one component, stored as parallel arrays so that force and integration
/// loops stream through memory. Gravity, damping, every integrator and the NaN quarantine act
/// on them exactly as on particle entities; springs act through a
/// [`crate::springs::SpringNetwork`] on the same entity.
///
/// Units as for particles: positions in m, velocities in m/s, masses in kg, forces in N.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Nodes {
    pub(crate) x: Vec<Vec3A>,
    pub(crate) v: Vec<Vec3A>,
    pub(crate) f: Vec<Vec3A>,
    /// m, or 0 for pinned nodes (as in [`crate::particles::Mass`]).
    pub(crate) mass: Vec<f32>,
    pub(crate) inv_mass: Vec<f32>,
}

impl Nodes {
    /// Whether the arrays agree in length (they can disagree only in data read from a
    /// snapshot written by hand).
    pub(crate) fn consistent(&self) -> bool {
        let n = self.x.len();
        [
            self.v.len(),
            self.f.len(),
            self.mass.len(),
            self.inv_mass.len(),
        ]
        .iter()
        .all(|&l| l == n)
    }

    /// No nodes.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// No nodes, with room for `n`.
    #[must_use]
    pub fn with_capacity(n: usize) -> Self {
        Self {
            x: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            f: Vec::with_capacity(n),
            mass: Vec::with_capacity(n),
            inv_mass: Vec::with_capacity(n),
        }
    }

    /// Adds a node at `x` (m) with velocity `v` (m/s) and mass `kg`; returns its index.
    ///
    /// # Errors
    /// [`Error::NonFinite`] or [`Error::InvalidMass`].
    pub fn push(&mut self, x: Vec3, v: Vec3, kg: f32) -> Result<usize> {
        let m = crate::particles::Mass::new(kg)?;
        self.push_raw(
            finite_vec("node position", x)?,
            finite_vec("node velocity", v)?,
            m,
        )
    }

    /// Adds a pinned node at `x` (m); returns its index.
    ///
    /// # Errors
    /// [`Error::NonFinite`].
    pub fn push_pinned(&mut self, x: Vec3) -> Result<usize> {
        self.push_raw(
            finite_vec("node position", x)?,
            Vec3::ZERO,
            crate::particles::Mass::PINNED,
        )
    }

    fn push_raw(&mut self, x: Vec3, v: Vec3, m: crate::particles::Mass) -> Result<usize> {
        self.x.push(x.into());
        self.v.push(v.into());
        self.f.push(Vec3A::ZERO);
        self.mass.push(m.force_scale());
        self.inv_mass.push(m.inverse());
        Ok(self.x.len() - 1)
    }

    fn check(&self, i: usize) -> Result<()> {
        if i < self.x.len() {
            Ok(())
        } else {
            Err(Error::IndexOutOfRange {
                what: "node",
                index: i,
                len: self.x.len(),
            })
        }
    }

    /// Pins node `i` in place (infinite mass).
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`].
    pub fn pin(&mut self, i: usize) -> Result<()> {
        self.check(i)?;
        self.mass[i] = 0.0;
        self.inv_mass[i] = 0.0;
        self.v[i] = Vec3A::ZERO;
        Ok(())
    }

    /// The indices of the nodes whose position (m) satisfies `pick`, in index order: the
    /// nodes to pin, attach or drive, chosen by where they are rather than by searching the
    /// indices a mesh builder handed out.
    ///
    /// ```
    /// use hooke::prelude::*;
    /// use hooke::soft::{Material, SoftBody, StrainModel, TetMesh};
    /// let mesh = TetMesh::cuboid(Vec3::new(1.0, 0.2, 0.2), [5, 1, 1], Default::default()).unwrap();
    /// let material = Material::new(1e6, 0.3, 1000.0).unwrap();
    /// let (mut nodes, _body) =
    ///     SoftBody::build(&mesh, Vec3::ZERO, material, StrainModel::Corotated).unwrap();
    /// // A cantilever: the end face at the smallest x is clamped.
    /// let x_min = nodes.positions().iter().map(|p| p.x).fold(f32::INFINITY, f32::min);
    /// let clamped = nodes.pin_where(|p| p.x < x_min + 1e-4);
    /// assert_eq!(clamped, 4);
    /// assert_eq!(nodes.select(|p| p.x < x_min + 1e-4).len(), 4);
    /// ```
    #[must_use]
    pub fn select(&self, pick: impl Fn(Vec3) -> bool) -> Vec<usize> {
        (0..self.x.len())
            .filter(|&i| pick(self.x[i].into()))
            .collect()
    }

    /// The indices of the nodes inside the box from `min` to `max` (m, corners included), in
    /// index order.
    #[must_use]
    pub fn within(&self, min: Vec3, max: Vec3) -> Vec<usize> {
        self.select(|p| p.cmpge(min).all() && p.cmple(max).all())
    }

    /// Pins every node whose position satisfies `pick` (see [`Self::select`]); returns how
    /// many it pinned.
    pub fn pin_where(&mut self, pick: impl Fn(Vec3) -> bool) -> usize {
        let chosen = self.select(pick);
        for &i in &chosen {
            // In range: `select` returned it.
            let _ = self.pin(i);
        }
        chosen.len()
    }

    /// Gives node `i` the mass `kg` (unpinning a pinned node).
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] or [`Error::InvalidMass`].
    pub fn set_mass(&mut self, i: usize, kg: f32) -> Result<()> {
        self.check(i)?;
        let m = crate::particles::Mass::new(kg)?;
        self.mass[i] = m.force_scale();
        self.inv_mass[i] = m.inverse();
        Ok(())
    }

    /// Moves node `i` to `x` (m).
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] or [`Error::NonFinite`].
    pub fn set_position(&mut self, i: usize, x: Vec3) -> Result<()> {
        self.check(i)?;
        self.x[i] = finite_vec("node position", x)?.into();
        Ok(())
    }

    /// Sets node `i`'s velocity (m/s).
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] or [`Error::NonFinite`].
    pub fn set_velocity(&mut self, i: usize, v: Vec3) -> Result<()> {
        self.check(i)?;
        self.v[i] = finite_vec("node velocity", v)?.into();
        Ok(())
    }

    /// Adds `f` (N) to node `i`'s force accumulator, for a force system placed in
    /// [`crate::core::schedule::ForceSystems::User`] (a point load, a grab). The accumulator is reset every
    /// evaluation, so the force acts only while the system keeps adding it.
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] or [`Error::NonFinite`].
    pub fn add_force(&mut self, i: usize, f: Vec3A) -> Result<()> {
        self.check(i)?;
        self.f[i] += Vec3A::from(finite_vec("node force", f.into())?);
        Ok(())
    }

    /// Number of nodes.
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no nodes.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Positions (m).
    #[must_use]
    pub fn positions(&self) -> &[Vec3A] {
        &self.x
    }

    /// Velocities (m/s).
    #[must_use]
    pub fn velocities(&self) -> &[Vec3A] {
        &self.v
    }

    /// Forces of the last evaluation (N).
    #[must_use]
    pub fn forces(&self) -> &[Vec3A] {
        &self.f
    }

    /// Inverse masses (1/kg), 0 for pinned nodes.
    #[must_use]
    pub fn inverse_masses(&self) -> &[f32] {
        &self.inv_mass
    }

    /// Mass of node `i` (kg), infinite when pinned; `None` out of range.
    #[must_use]
    pub fn mass(&self, i: usize) -> Option<f32> {
        let inv = *self.inv_mass.get(i)?;
        Some(if inv == 0.0 {
            f32::INFINITY
        } else {
            self.mass[i]
        })
    }

    /// The nodes' bounding box (min, max corners, m); None for no nodes.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = Vec3::from(*self.x.first()?);
        Some(self.x.iter().fold((first, first), |(lo, hi), p| {
            (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p)))
        }))
    }

    /// The fastest node's speed (m/s); 0 for no nodes.
    #[must_use]
    pub fn max_speed(&self) -> f32 {
        self.v.iter().map(|v| v.length()).fold(0.0, f32::max)
    }

    /// True when every position and velocity is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.x.iter().all(|x| x.is_finite()) && self.v.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_are_selected_by_region_and_predicate_in_index_order() {
        let mut nodes = Nodes::default();
        for x in [2.0, 0.0, 1.0, -1.0] {
            nodes.push(Vec3::new(x, 0.0, 0.0), Vec3::ZERO, 1.0).unwrap();
        }
        assert_eq!(nodes.select(|p| p.x >= 0.0), vec![0, 1, 2]);
        // Corners included, a hair outside excluded.
        assert_eq!(
            nodes.within(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0)),
            vec![1, 2]
        );
        assert!(nodes.within(Vec3::splat(0.1), Vec3::splat(0.9)).is_empty());
        assert_eq!(nodes.pin_where(|p| p.x < 0.5), 2);
        assert_eq!(nodes.inverse_masses(), &[1.0, 0.0, 1.0, 0.0]);
    }
}
