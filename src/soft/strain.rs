//! The material math of soft bodies, as pure functions of the deformation gradient F.
//!
//! For each [`StrainModel`]: the energy density Ψ(F) (J/m³), the first Piola–Kirchhoff stress
//! P = ∂Ψ/∂F (Pa), and its differential dP\[dF\] = (∂P/∂F) : dF (Pa), which the implicit
//! solver needs. The strains and the linear stress σ = λ tr(ε) I + 2 μ ε are the lecture's;
//! see the [module docs](super) for the equations of each model and when to use it.

use glam::{DMat3, Mat3, Vec3};

use super::Lame;

/// Green's finite strain E = ½ (FᵀF − I): exact under rotation, quadratic in positions.
#[must_use]
pub fn green_strain(f: Mat3) -> Mat3 {
    0.5 * (f.transpose() * f - Mat3::IDENTITY)
}

/// Cauchy's infinitesimal strain ε = ½ (F + Fᵀ) − I: linear, but a rotation reads as strain.
#[must_use]
pub fn cauchy_strain(f: Mat3) -> Mat3 {
    0.5 * (f + f.transpose()) - Mat3::IDENTITY
}

/// The co-rotated strain ε = S − I, with F = R S the polar decomposition: Cauchy's strain
/// with the rotation taken out.
#[must_use]
pub fn corotated_strain(f: Mat3) -> Mat3 {
    polar_decomposition(f).1 - Mat3::IDENTITY
}

/// The linear (isotropic, Hookean) stress σ = λ tr(ε) I + 2 μ ε (Pa).
#[must_use]
pub fn linear_stress(strain: Mat3, lame: Lame) -> Mat3 {
    lame.lambda * trace(strain) * Mat3::IDENTITY + 2.0 * lame.mu * strain
}

/// F = R S with R a proper rotation (det R = +1) and S symmetric, through the SVD
/// F = U Σ Vᵀ: R = U Vᵀ, S = V Σ Vᵀ. When det F < 0 (an inverted element) the smallest
/// singular value is negated instead of letting R reflect, so S carries the inversion and
/// the restoring force pushes the element back through (Irving, Teran and Fedkiw 2004).
/// Computed in f64.
#[must_use]
pub fn polar_decomposition(f: Mat3) -> (Mat3, Mat3) {
    let (r, s) = polar_f64(f.as_dmat3());
    (r.as_mat3(), s.as_mat3())
}

fn polar_f64(f: DMat3) -> (DMat3, DMat3) {
    // Away from inversion, Higham's scaled Newton iteration X ← ½(γX + X⁻ᵀ/γ) converges
    // quadratically to the same R as the SVD (the polar factor of a non-singular F is
    // unique) at a fifth of its cost: no trigonometry, three or four 3 × 3 inverses for the
    // strains an elastic body sees. Near and through inversion the SVD path below decides
    // the sign convention.
    let norm2 = f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared();
    let det = f.determinant();
    let mean2 = norm2 / 3.0;
    if det > 0.05 * mean2 * mean2.sqrt() {
        let mut x = f;
        for k in 0..16 {
            let inv = x.inverse();
            // Scaling pays on the first step of a large stretch; near R, γ is 1 anyway.
            let gamma = if k == 0 {
                (frobenius2(inv) / frobenius2(x)).sqrt().sqrt()
            } else {
                1.0
            };
            let next = 0.5 * (gamma * x + inv.transpose() / gamma);
            let change = frobenius2(next - x);
            x = next;
            // The error after a step is about the square of the step: 1e-7 leaves 1e-14,
            // far below the f32 the result is used in.
            if change < 1e-14 {
                return (x, symmetric(x.transpose() * f));
            }
        }
    }
    let Some((mut u, mut sigma, mut v)) = svd(f) else {
        // Not reached for finite F; a non-finite F is its body's quarantine.
        return (DMat3::IDENTITY, symmetric(f));
    };
    // Make U and V proper rotations; each flip keeps F = U Σ Vᵀ by moving the sign into the
    // smallest singular value (they come sorted descending), which ends with the sign of
    // det F.
    if u.determinant() < 0.0 {
        u.z_axis = -u.z_axis;
        sigma.z = -sigma.z;
    }
    if v.determinant() < 0.0 {
        v.z_axis = -v.z_axis;
        sigma.z = -sigma.z;
    }
    let r = u * v.transpose();
    let s = v * DMat3::from_diagonal(sigma) * v.transpose();
    (r, symmetric(s))
}

/// F = U Σ Vᵀ with the singular values sorted descending, by nalgebra's SVD, which holds on
/// rank-deficient F: `glamx::DSvd3` goes through the eigenvectors of FᵀF and gave a NaN U
/// for an element collapsed onto a line (a jelly thrown at the ground at 150 m/s went
/// non-finite) and a U that was not orthogonal for another of rank 1.
fn svd(f: DMat3) -> Option<(DMat3, glam::DVec3, DMat3)> {
    let m = nalgebra::Matrix3::from_column_slice(&f.to_cols_array());
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let (u, v) = (
        DMat3::from_cols_slice(u.as_slice()),
        DMat3::from_cols_slice(vt.transpose().as_slice()),
    );
    let s = svd.singular_values;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    let pick = |m: DMat3| DMat3::from_cols(m.col(order[0]), m.col(order[1]), m.col(order[2]));
    let sigma = glam::DVec3::new(s[order[0]], s[order[1]], s[order[2]]);
    let (u, v) = (pick(u), pick(v));
    (u.is_finite() && v.is_finite() && sigma.is_finite()).then_some((u, sigma, v))
}

fn frobenius2(m: DMat3) -> f64 {
    m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()
}

fn symmetric(m: DMat3) -> DMat3 {
    0.5 * (m + m.transpose())
}

fn trace(m: Mat3) -> f32 {
    m.x_axis.x + m.y_axis.y + m.z_axis.z
}

/// A : B = Σ Aᵢⱼ Bᵢⱼ.
#[must_use]
pub fn ddot(a: Mat3, b: Mat3) -> f32 {
    a.x_axis.dot(b.x_axis) + a.y_axis.dot(b.y_axis) + a.z_axis.dot(b.z_axis)
}

/// ∂J/∂F for J = det F: the cofactor matrix, column i the cross product of the other two.
#[must_use]
pub fn cofactor(f: Mat3) -> Mat3 {
    Mat3::from_cols(
        f.y_axis.cross(f.z_axis),
        f.z_axis.cross(f.x_axis),
        f.x_axis.cross(f.y_axis),
    )
}

/// d(cof F)[dF], the derivative of [`cofactor`] along dF.
fn cofactor_differential(f: Mat3, df: Mat3) -> Mat3 {
    Mat3::from_cols(
        df.y_axis.cross(f.z_axis) + f.y_axis.cross(df.z_axis),
        df.z_axis.cross(f.x_axis) + f.z_axis.cross(df.x_axis),
        df.x_axis.cross(f.y_axis) + f.x_axis.cross(df.y_axis),
    )
}

/// The skew matrix [w]× with [w]× v = w × v.
fn cross_matrix(w: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, w.z, -w.y),
        Vec3::new(-w.z, 0.0, w.x),
        Vec3::new(w.y, -w.x, 0.0),
    )
}

/// How a soft body's material measures strain: the dial between cost and fidelity. See the
/// [module docs](super).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub enum StrainModel {
    /// Green's strain with the linear stress (St. Venant–Kirchhoff): rotation-exact, stiffens
    /// in stretch, and collapses under strong compression (no resistance to inversion).
    Green,
    /// Cauchy's strain with the linear stress: the cheapest, exact for small displacements,
    /// but a rigid rotation by θ stores the ghost energy density 2 (μ + λ)(1 − cos θ)².
    Cauchy,
    /// Co-rotated: Cauchy's strain after the polar decomposition removes the rotation. The
    /// graphics workhorse; recovers from inversion.
    #[default]
    Corotated,
    /// Stable Neo-Hookean: nonlinear, volume-preserving, defined and restoring through
    /// inversion, with no singularity at J = 0.
    StableNeoHookean,
}

/// Ψ and P of one model at one F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stress {
    /// Energy density Ψ (J/m³).
    pub energy: f32,
    /// First Piola–Kirchhoff stress P = ∂Ψ/∂F (Pa).
    pub piola: Mat3,
}

impl StrainModel {
    /// Every model, in order of the enum.
    pub const ALL: [StrainModel; 4] = [
        StrainModel::Green,
        StrainModel::Cauchy,
        StrainModel::Corotated,
        StrainModel::StableNeoHookean,
    ];

    /// A short lowercase name (for reports).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            StrainModel::Green => "green",
            StrainModel::Cauchy => "cauchy",
            StrainModel::Corotated => "corotated",
            StrainModel::StableNeoHookean => "neohookean",
        }
    }

    /// Uniaxial stretch `stretch` along x with free sides: the lateral stretch s at which the
    /// lateral stress vanishes (found by bisection on [0.5, 1.5]) and the axial P₁₁ (Pa) there.
    #[must_use]
    pub fn uniaxial(self, stretch: f32, lame: Lame) -> (f32, f32) {
        let p = |s: f32| self.first_piola(Mat3::from_diagonal(Vec3::new(stretch, s, s)), lame);
        let (mut lo, mut hi) = (0.5f32, 1.5f32);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if p(mid).y_axis.y < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let s = 0.5 * (lo + hi);
        (s, p(s).x_axis.x)
    }

    /// Ψ(F) and P(F).
    #[must_use]
    pub fn stress(self, f: Mat3, lame: Lame) -> Stress {
        let Lame { mu, lambda } = lame;
        match self {
            StrainModel::Green => {
                let e = green_strain(f);
                let s = linear_stress(e, lame);
                Stress {
                    energy: mu * ddot(e, e) + 0.5 * lambda * trace(e).powi(2),
                    piola: f * s,
                }
            }
            StrainModel::Cauchy => {
                let e = cauchy_strain(f);
                Stress {
                    energy: mu * ddot(e, e) + 0.5 * lambda * trace(e).powi(2),
                    piola: linear_stress(e, lame),
                }
            }
            StrainModel::Corotated => {
                let (r, s) = polar_decomposition(f);
                let e = s - Mat3::IDENTITY;
                Stress {
                    energy: mu * ddot(e, e) + 0.5 * lambda * trace(e).powi(2),
                    piola: 2.0 * mu * (f - r) + lambda * trace(e) * r,
                }
            }
            StrainModel::StableNeoHookean => {
                let p = NeoHookeanParameters::new(lame);
                let j = f.determinant();
                let c = cofactor(f);
                let i_c = ddot(f, f);
                Stress {
                    energy: 0.5 * p.mu * (i_c - 3.0) + 0.5 * p.lambda * (j - p.alpha).powi(2)
                        - 0.5 * p.mu * (i_c + 1.0).ln()
                        - p.rest,
                    piola: p.mu * (1.0 - 1.0 / (i_c + 1.0)) * f + p.lambda * (j - p.alpha) * c,
                }
            }
        }
    }

    /// The energy density Ψ(F) (J/m³).
    #[must_use]
    pub fn energy_density(self, f: Mat3, lame: Lame) -> f32 {
        self.stress(f, lame).energy
    }

    /// The first Piola–Kirchhoff stress P(F) (Pa).
    #[must_use]
    pub fn first_piola(self, f: Mat3, lame: Lame) -> Mat3 {
        self.stress(f, lame).piola
    }

    /// dP\[dF\] = (∂P/∂F) : dF (Pa), the stress differential along dF.
    #[must_use]
    pub fn differential(self, f: Mat3, df: Mat3, lame: Lame) -> Mat3 {
        Prepared::new(self, f, lame).differential(df, lame)
    }

    /// dP\[Eᵢⱼ\] for the nine unit directions Eᵢⱼ (column-major order: entry k is the
    /// derivative along the k-th entry of F's column-major array): the columns of the
    /// 9 × 9 matrix ∂P/∂F. The work shared between directions (a polar decomposition, a
    /// cofactor) is done once.
    #[must_use]
    pub fn differentials(self, f: Mat3, lame: Lame) -> [Mat3; 9] {
        Prepared::new(self, f, lame).differentials(lame)
    }
}

/// The parameters of stable Neo-Hookean's energy
/// Ψ = ½ μ′ (I_C − 3) + ½ λ′ (J − α)² − ½ μ′ log(I_C + 1) − Ψ₀ from the Lamé parameters:
/// μ′ = 4/3 μ and λ′ = λ + 5/6 μ make its small strains those of linear elasticity,
/// α = 1 + 3 μ′ / (4 λ′) makes F = I stress-free, and Ψ₀ = ½ λ′ (1 − α)² − ½ μ′ log 4 its
/// energy zero (Smith, de Goes and Kim 2018, eq. 14–16). The log term is what makes F = 0
/// no minimum: without it the Hessian there is μ I, and an element crushed below
/// J ≈ 0.024 collapsed to a point and stayed there.
#[derive(Debug, Clone, Copy)]
struct NeoHookeanParameters {
    mu: f32,
    lambda: f32,
    alpha: f32,
    rest: f32,
}

impl NeoHookeanParameters {
    fn new(lame: Lame) -> Self {
        let mu = 4.0 / 3.0 * lame.mu;
        let lambda = lame.lambda + 5.0 / 6.0 * lame.mu;
        let alpha = 1.0 + 0.75 * mu / lambda;
        let rest = 0.5 * lambda * (1.0 - alpha).powi(2) - 0.5 * mu * 4f32.ln();
        Self {
            mu,
            lambda,
            alpha,
            rest,
        }
    }
}

/// What a model's stress and stress differential need of F, computed once per F (for the
/// co-rotated model, the polar decomposition: the expensive part of every evaluation).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Prepared {
    Green {
        f: Mat3,
        stress: Mat3,
    },
    Cauchy {
        f: Mat3,
    },
    Corotated {
        f: Mat3,
        r: Mat3,
        s: Mat3,
        g_inv: Option<Mat3>,
    },
    StableNeoHookean {
        f: Mat3,
        j: f32,
        cofactor: Mat3,
    },
}

impl Prepared {
    /// Ψ(F) and P(F), as [`StrainModel::stress`] but from the prepared decomposition.
    pub(crate) fn stress(&self, model: StrainModel, lame: Lame) -> Stress {
        let Lame { mu, lambda } = lame;
        match *self {
            Prepared::Corotated { f, r, s, .. } => {
                let e = s - Mat3::IDENTITY;
                Stress {
                    energy: mu * ddot(e, e) + 0.5 * lambda * trace(e).powi(2),
                    piola: 2.0 * mu * (f - r) + lambda * trace(e) * r,
                }
            }
            Prepared::Green { f, .. }
            | Prepared::Cauchy { f }
            | Prepared::StableNeoHookean { f, .. } => model.stress(f, lame),
        }
    }

    /// The F it was prepared from.
    pub(crate) fn deformation(&self) -> Mat3 {
        match *self {
            Prepared::Green { f, .. }
            | Prepared::Cauchy { f }
            | Prepared::Corotated { f, .. }
            | Prepared::StableNeoHookean { f, .. } => f,
        }
    }

    /// The columns of ∂P/∂F (see [`StrainModel::differentials`]).
    pub(crate) fn differentials(&self, lame: Lame) -> [Mat3; 9] {
        std::array::from_fn(|k| {
            let mut e = [0.0f32; 9];
            e[k] = 1.0;
            self.differential(Mat3::from_cols_array(&e), lame)
        })
    }

    pub(crate) fn new(model: StrainModel, f: Mat3, lame: Lame) -> Self {
        match model {
            StrainModel::Green => Prepared::Green {
                f,
                stress: linear_stress(green_strain(f), lame),
            },
            StrainModel::Cauchy => Prepared::Cauchy { f },
            StrainModel::Corotated => {
                let (r, s) = polar_decomposition(f);
                Prepared::Corotated {
                    f,
                    r,
                    s,
                    g_inv: rotation_system_inverse(s),
                }
            }
            StrainModel::StableNeoHookean => Prepared::StableNeoHookean {
                f,
                j: f.determinant(),
                cofactor: cofactor(f),
            },
        }
    }

    fn differential(&self, df: Mat3, lame: Lame) -> Mat3 {
        let Lame { mu, lambda } = lame;
        match *self {
            Prepared::Green { f, stress } => {
                let de = 0.5 * (df.transpose() * f + f.transpose() * df);
                df * stress + f * linear_stress(de, lame)
            }
            Prepared::Cauchy { .. } => {
                lambda * trace(df) * Mat3::IDENTITY + mu * (df + df.transpose())
            }
            Prepared::Corotated { r, s, g_inv, .. } => {
                let dr = rotation_differential(r, g_inv, df);
                let e = trace(s) - 3.0;
                2.0 * mu * df
                    + lambda * trace(r.transpose() * df) * r
                    + (lambda * e - 2.0 * mu) * dr
            }
            Prepared::StableNeoHookean { f, j, cofactor: c } => {
                let p = NeoHookeanParameters::new(lame);
                let k = 1.0 / (ddot(f, f) + 1.0);
                p.mu * (1.0 - k) * df
                    + (2.0 * p.mu * k * k * ddot(f, df)) * f
                    + p.lambda * ddot(c, df) * c
                    + p.lambda * (j - p.alpha) * cofactor_differential(f, df)
            }
        }
    }
}

/// dR for F = R S moved by dF: RᵀdR = [ω]× with (tr S · I − S) ω = axial(RᵀdF − dFᵀR), from
/// the skew part of RᵀdF = [ω]× S + dS. Where two singular values sum to zero (a flat
/// element flipping) the system is singular; ω is then taken from its regular part.
fn rotation_differential(r: Mat3, g_inv: Option<Mat3>, df: Mat3) -> Mat3 {
    let m = r.transpose() * df;
    let a = m - m.transpose();
    let axial = Vec3::new(a.y_axis.z, a.z_axis.x, a.x_axis.y);
    let omega = g_inv.map_or(Vec3::ZERO, |g| g * axial);
    r * cross_matrix(omega)
}

/// (tr S · I − S)⁻¹, or None where it is singular.
fn rotation_system_inverse(s: Mat3) -> Option<Mat3> {
    let g = trace(s) * Mat3::IDENTITY - s;
    let det = g.determinant();
    (det.abs() > 1e-12 * (1.0 + trace(s).abs().powi(3))).then(|| g.inverse())
}
