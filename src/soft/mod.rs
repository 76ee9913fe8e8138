//! Soft bodies: the material models of tetrahedral FEM.
//!
//! A [`SoftBody`] is one entity per tetrahedral mesh ([`TetMesh`]): its nodes are a
//! [`Nodes`] component, its elements live in the [`SoftBody`] component, and
//! [`SoftBodyPlugin`] adds their elastic forces in [`crate::core::schedule::ForceSystems::Elasticity`], so
//! every integrator of the dial advances it. The material math is pure functions of the
//! deformation gradient ([`strain`]), tested against closed forms.
//!
//! **Deformation gradient.** A tetrahedron with rest corners X₀..X₃ and current corners
//! x₀..x₃ maps rest edges to current edges linearly: F = Ds Dm⁻¹, with Ds = [x₁−x₀, x₂−x₀,
//! x₃−x₀] and Dm the same of the rest corners. F = I at rest; det F = J is the volume ratio;
//! J ≤ 0 means the element is inverted.
//!
//! **Material.** Young's modulus E (Pa) and Poisson's ratio ν (−1 < ν < ½) give the Lamé
//! parameters μ = E / (2 (1 + ν)) and λ = E ν / ((1 + ν)(1 − 2ν)) ([`Material::lame`]).
//!
//! **Strain models** ([`StrainModel`]), each an energy density Ψ(F) (J/m³) whose derivative
//! is the first Piola–Kirchhoff stress P = ∂Ψ/∂F (Pa); the nodal forces of an element of rest
//! volume V are f = −V P Dm⁻ᵀ on corners 1..3 and minus their sum on corner 0.
//!
//! | model | strain | Ψ | P | use it for |
//! |---|---|---|---|---|
//! | [`StrainModel::Green`] (St. Venant–Kirchhoff) | E = ½ (FᵀF − I) | μ E:E + ½ λ tr(E)² | F (λ tr(E) I + 2 μ E) | moderate stretch with large rotation; it softens and collapses under strong compression |
//! | [`StrainModel::Cauchy`] (linear) | ε = ½ (F + Fᵀ) − I | μ ε:ε + ½ λ tr(ε)² | λ tr(ε) I + 2 μ ε | small displacements without rotation (the cheapest); a rotation by θ stores the *ghost* energy density 2 (μ + λ)(1 − cos θ)², 1.923 E at 90° and ν = 0.3 — why the lecture moves on to co-rotated strain |
//! | [`StrainModel::Corotated`] (default) | ε = S − I, F = R S | μ ε:ε + ½ λ tr(ε)² | 2 μ (F − R) + λ tr(ε) R | games: rotation-exact, cheap, finite through inversion (R from an SVD with the inversion kept in S); a body started inverted or crushed turns back (explicit steps alone, without damping, would keep the energy an inversion stores ringing through inversion: at the defaults a body with inverted elements is solved by BDF2) |
//! | [`StrainModel::StableNeoHookean`] | — | ½ μ′ (I_C − 3) + ½ λ′ (J − α)² − ½ μ′ log(I_C + 1) − Ψ₀, I_C = ‖F‖² | μ′ (1 − 1/(I_C + 1)) F + λ′ (J − α) ∂J/∂F | rubber, flesh, large deformation: nonlinear and volume-preserving, finite and restoring at J ≤ 0; a body started inverted or crushed to 1 % of its volume turns back (the log term makes F = 0 a saddle, not a minimum) |
//!
//! Stable Neo-Hookean is the energy of Smith, de Goes and Kim (2018, eq. 14–16) with its log
//! term: μ′ = 4/3 μ and λ′ = λ + 5/6 μ so that small strains match linear elasticity,
//! α = 1 + 3 μ′ / (4 λ′) so that F = I is stress-free, and Ψ₀ = ½ λ′ (1 − α)² − ½ μ′ log 4 so
//! that its energy is zero there. Without the log term F = 0 is a local minimum (Hessian
//! μ I) and an element crushed below J ≈ 0.024 stays a point. Units: Pa for E, μ, λ, P; J/m³
//! for Ψ.

mod attach;
mod implicit;
mod io;
pub mod mesh;
mod plugin;
pub mod stability;
pub mod strain;
mod targets;

pub use crate::integrator::ImplicitReport;
pub use attach::{MAX_ATTACHED_NODES, NodeAttachments};
pub use mesh::{CellSplit, TetMesh};
pub use plugin::SoftBodyPlugin;
pub use stability::SoftStability;
pub use strain::{StrainModel, Stress};
pub use targets::NodeTargets;

use bevy_ecs::prelude::*;
use glam::{Mat3, Vec3, Vec3A};

use crate::core::error::{Error, Result, finite, non_negative, positive};
use crate::particles::Nodes;

/// The Lamé parameters μ (shear modulus) and λ (Pa).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct Lame {
    /// μ (Pa).
    pub mu: f32,
    /// λ (Pa).
    pub lambda: f32,
}

/// An isotropic elastic material: Young's modulus, Poisson's ratio, density and Rayleigh
/// damping.
/// Read from a file (a snapshot) it is checked as [`Material::new`] checks its input.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(try_from = "MaterialRecord")]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct Material {
    young: f32,
    poisson: f32,
    density: f32,
    mass_damping: f32,
    stiffness_damping: f32,
}

/// [`Material`] as a file holds it.
#[derive(serde::Deserialize)]
struct MaterialRecord {
    young: f32,
    poisson: f32,
    density: f32,
    mass_damping: f32,
    stiffness_damping: f32,
}

impl TryFrom<MaterialRecord> for Material {
    type Error = Error;

    fn try_from(r: MaterialRecord) -> Result<Self> {
        Material::new(r.young, r.poisson, r.density)?
            .with_damping(r.mass_damping, r.stiffness_damping)
    }
}

impl Material {
    /// A material of Young's modulus `young` (Pa), Poisson ratio `poisson` and `density`
    /// (kg/m³), undamped.
    ///
    /// # Errors
    /// [`Error::NotPositive`] / [`Error::NonFinite`] for a bad E or density;
    /// [`Error::OutOfRange`] unless −1 < ν < 0.5.
    pub fn new(young: f32, poisson: f32, density: f32) -> Result<Self> {
        positive("Young's modulus", young)?;
        positive("density", density)?;
        finite("Poisson ratio", poisson)?;
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(Error::OutOfRange {
                what: "Poisson ratio",
                value: poisson,
                range: "-1 < ν < 0.5",
            });
        }
        Ok(Self {
            young,
            poisson,
            density,
            mass_damping: 0.0,
            stiffness_damping: 0.0,
        })
    }

    /// Rayleigh damping D = α M + β K: `mass` α (1/s) and `stiffness` β (s).
    ///
    /// # Errors
    /// [`Error::Negative`] / [`Error::NonFinite`].
    pub fn with_damping(mut self, mass: f32, stiffness: f32) -> Result<Self> {
        self.mass_damping = non_negative("mass damping", mass)?;
        self.stiffness_damping = non_negative("stiffness damping", stiffness)?;
        Ok(self)
    }

    /// E (Pa).
    #[must_use]
    pub fn young(&self) -> f32 {
        self.young
    }

    /// ν.
    #[must_use]
    pub fn poisson(&self) -> f32 {
        self.poisson
    }

    /// ρ (kg/m³).
    #[must_use]
    pub fn density(&self) -> f32 {
        self.density
    }

    /// Rayleigh (α, β).
    #[must_use]
    pub fn damping(&self) -> (f32, f32) {
        (self.mass_damping, self.stiffness_damping)
    }

    /// μ = E / (2 (1 + ν)), λ = E ν / ((1 + ν)(1 − 2ν)).
    #[must_use]
    pub fn lame(&self) -> Lame {
        let (e, nu) = (self.young, self.poisson);
        Lame {
            mu: e / (2.0 * (1.0 + nu)),
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        }
    }
}

/// What a soft body's last force evaluation found: elastic energy, volume and inversion.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub struct SoftBodyStats {
    /// Elastic energy Σ V Ψ(F) (J).
    pub elastic_energy: f64,
    /// Current volume over rest volume, Σ V J / Σ V.
    pub volume_ratio: f32,
    /// Tetrahedra with det F ≤ 0.
    pub inverted: usize,
    /// The last implicit substep's solve (zero under the explicit integrators).
    pub implicit: ImplicitReport,
}

/// A tetrahedral soft body: the cold state of one mesh (tetrahedra, Dm⁻¹, rest volumes,
/// material, strain model). Its hot state is the [`Nodes`] component on the same entity
/// (positions, velocities, forces, inverse lumped masses), so gravity, damping, velocity
/// fields, every integrator and the quarantine act on its nodes as on any mesh. Spawn both
/// with [`SoftBody::build`].
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[require(Nodes, SoftStability)]
pub struct SoftBody {
    tets: Vec<[u32; 4]>,
    dm_inv: Vec<Mat3>,
    volume: Vec<f32>,
    material: Material,
    lame: Lame,
    model: StrainModel,
    stats: SoftBodyStats,
    contact_thickness: f32,
    /// The contacts of the last substep, for the implicit solve to respect.
    contacts: Vec<NodeContact>,
    /// Whether its nodes have pressed on a dynamic body: its local substeps (a rescue) then
    /// give way to BDF2, whose solve takes the body's response with the contact.
    #[serde(default)]
    pub(crate) touched_a_body: bool,
}

/// Adds an element's nodal forces: the columns of H = −V P Dm⁻ᵀ to corners 1..3, their
/// negated sum to corner 0.
#[inline]
pub(crate) fn scatter_element_forces(f: &mut [Vec3A], t: [u32; 4], h: Mat3) {
    let (h1, h2, h3) = (
        Vec3A::from(h.x_axis),
        Vec3A::from(h.y_axis),
        Vec3A::from(h.z_axis),
    );
    f[t[1] as usize] += h1;
    f[t[2] as usize] += h2;
    f[t[3] as usize] += h3;
    f[t[0] as usize] -= h1 + h2 + h3;
}

/// A node held outside a static or kinematic collider: the plane n·x ≥ d at the node's
/// contact, moving with the collider over the next substep.
pub(crate) type NodeContact = crate::integrator::implicit::ContactPlane;

impl crate::collision::nodes::NodeLayer for SoftBody {
    fn thickness(&self) -> f32 {
        self.contact_thickness
    }

    fn contacts_mut(&mut self) -> &mut Vec<NodeContact> {
        &mut self.contacts
    }

    fn touched_a_body(&mut self) {
        self.touched_a_body = true;
    }
}

impl SoftBody {
    /// The nodes and the body of `mesh` placed at `offset` (m), with masses lumped from the
    /// material's density (each tetrahedron gives a quarter of ρ V to each corner).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a bad offset; [`Error::InvalidMass`] if a node gets no mass.
    pub fn build(
        mesh: &TetMesh,
        offset: Vec3,
        material: Material,
        model: StrainModel,
    ) -> Result<(Nodes, SoftBody)> {
        let offset = crate::core::error::finite_vec("soft body offset", offset)?;
        let points = mesh.points();
        let mut mass = vec![0.0f32; points.len()];
        let (mut dm_inv, mut volume) = (Vec::new(), Vec::new());
        for t in mesh.tets() {
            let p = |i: usize| points[t[i] as usize];
            let dm = Mat3::from_cols(p(1) - p(0), p(2) - p(0), p(3) - p(0));
            let v = dm.determinant() / 6.0;
            dm_inv.push(dm.inverse());
            volume.push(v);
            for &i in t {
                mass[i as usize] += 0.25 * material.density() * v;
            }
        }
        let mut nodes = Nodes::with_capacity(points.len());
        for (p, m) in points.iter().zip(mass) {
            nodes.push(*p + offset, Vec3::ZERO, m)?;
        }
        let body = SoftBody {
            tets: mesh.tets().to_vec(),
            dm_inv,
            volume,
            material,
            lame: material.lame(),
            model,
            stats: SoftBodyStats::default(),
            contact_thickness: 0.005,
            contacts: Vec::new(),
            touched_a_body: false,
        };
        Ok((nodes, body))
    }

    /// Whether every element has its rest data and indexes into `nodes` (see
    /// [`Nodes::consistent`]).
    pub(crate) fn fits(&self, nodes: usize) -> bool {
        self.dm_inv.len() == self.tets.len()
            && self.volume.len() == self.tets.len()
            && self.tets.iter().flatten().all(|&i| (i as usize) < nodes)
            && self.contacts.iter().all(|c| (c.node as usize) < nodes)
    }

    /// The largest node index its elements name (None without elements).
    pub(crate) fn largest_node(&self) -> Option<u32> {
        self.tets.iter().flatten().copied().max()
    }

    /// How far from a collider's surface its nodes are kept (m; default 5 mm).
    ///
    /// # Errors
    /// [`Error::Negative`] / [`Error::NonFinite`].
    pub fn with_contact_thickness(mut self, metres: f32) -> Result<Self> {
        self.contact_thickness = non_negative("contact thickness", metres)?;
        Ok(self)
    }

    /// The tetrahedra (indices into the nodes).
    #[must_use]
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// The material.
    #[must_use]
    pub fn material(&self) -> Material {
        self.material
    }

    /// The strain model.
    #[must_use]
    pub fn model(&self) -> StrainModel {
        self.model
    }

    /// Changes the strain model (takes effect at the next force evaluation).
    pub fn set_model(&mut self, model: StrainModel) {
        self.model = model;
    }

    /// What the last force evaluation found.
    #[must_use]
    pub fn stats(&self) -> SoftBodyStats {
        self.stats
    }

    /// Total rest volume (m³).
    #[must_use]
    pub fn rest_volume(&self) -> f32 {
        self.volume.iter().sum()
    }

    /// F = Ds Dm⁻¹ of tetrahedron `k` at positions `x`.
    #[must_use]
    pub fn deformation_gradient(&self, x: &[Vec3A], k: usize) -> Mat3 {
        let t = self.tets[k];
        let p = |i: usize| Vec3::from(x[t[i] as usize]);
        Mat3::from_cols(p(1) - p(0), p(2) - p(0), p(3) - p(0)) * self.dm_inv[k]
    }

    /// Adds this body's elastic and damping forces (N) into `nodes`' force accumulator, as
    /// the plugin does in every force evaluation; records [`SoftBody::stats`]. Returns false
    /// if a force came out non-finite.
    pub fn add_elastic_forces(&mut self, nodes: &mut Nodes) -> bool {
        self.accumulate(&nodes.x, &nodes.v, &nodes.mass, &mut nodes.f)
    }

    /// Adds the elastic (and Rayleigh stiffness-damping) forces of every tetrahedron into
    /// `f`, and the mass damping −α m v; records the stats. Returns false if a force came out
    /// non-finite (nothing is then trusted).
    pub(crate) fn accumulate(
        &mut self,
        x: &[Vec3A],
        v: &[Vec3A],
        m: &[f32],
        f: &mut [Vec3A],
    ) -> bool {
        let (alpha, beta) = self.material.damping();
        let mut stats = SoftBodyStats::default();
        let (mut vj, mut vsum) = (0.0f32, 0.0f32);
        let mut finite = true;
        for k in 0..self.tets.len() {
            let t = self.tets[k];
            let (dm_inv, vol) = (self.dm_inv[k], self.volume[k]);
            let f_k = self.deformation_gradient(x, k);
            let s = self.model.stress(f_k, self.lame);
            let mut p = s.piola;
            if beta > 0.0 {
                let dv = |i: usize| Vec3::from(v[t[i] as usize] - v[t[0] as usize]);
                let df = Mat3::from_cols(dv(1), dv(2), dv(3)) * dm_inv;
                p += beta * self.model.differential(f_k, df, self.lame);
            }
            let h = -vol * p * dm_inv.transpose();
            scatter_element_forces(f, t, h);
            finite &= h.is_finite();
            let j = f_k.determinant();
            stats.elastic_energy += f64::from(vol) * f64::from(s.energy);
            stats.inverted += usize::from(j <= 0.0);
            vj += vol * j;
            vsum += vol;
        }
        if alpha > 0.0 {
            for i in 0..f.len() {
                f[i] -= alpha * m[i] * v[i];
            }
        }
        stats.volume_ratio = vj / vsum;
        stats.implicit = self.stats.implicit;
        self.stats = stats;
        finite
    }
}
