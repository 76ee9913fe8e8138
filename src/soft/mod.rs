//! Soft bodies: the material models of tetrahedral FEM.
//!
//! **This module holds the material math only** (issue 12 builds the rest on it: meshes, the
//! `SoftBody` component and plugin, the implicit solver). Everything here is a pure function
//! of the deformation gradient, tested against closed forms.
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
//! | [`StrainModel::Corotated`] (default) | ε = S − I, F = R S | μ ε:ε + ½ λ tr(ε)² | 2 μ (F − R) + λ tr(ε) R | games: rotation-exact, cheap, robust through inversion (R from an SVD with the inversion kept in S) |
//! | [`StrainModel::StableNeoHookean`] | — | ½ μ (‖F‖² − 3) − μ (J − 1) + ½ λ′ (J − 1)² | μ F + (λ′ (J − 1) − μ) ∂J/∂F | rubber, flesh, large deformation: nonlinear and volume-preserving, finite and restoring at J ≤ 0 |
//!
//! Stable Neo-Hookean is the form of Smith, de Goes and Kim (2018) as given in Kim and
//! Eberle's course notes (2020), without the −½ μ log(I_C + 1) term, with λ′ = λ + μ so that
//! small strains match linear elasticity. Units: Pa for E, μ, λ, P; J/m³ for Ψ.

pub mod strain;

pub use strain::{StrainModel, Stress};

use crate::error::{Error, Result, finite, non_negative, positive};

/// The Lamé parameters μ (shear modulus) and λ (Pa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lame {
    /// μ (Pa).
    pub mu: f32,
    /// λ (Pa).
    pub lambda: f32,
}

/// An isotropic elastic material: Young's modulus, Poisson's ratio, density and Rayleigh
/// damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    young: f32,
    poisson: f32,
    density: f32,
    mass_damping: f32,
    stiffness_damping: f32,
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
