//! The soft body's side of the backward-Euler solve ([`crate::integrator::implicit`]): its
//! tetrahedra as [`ImplicitElements`]. An element's matrix is its 9 × 9 ∂P/∂F (column-major
//! vec of F); its stiffness is K_k = V Bᵀ [∂P/∂F] B with dF = Σ_b dx_b b_bᵀ, and its damping
//! the Rayleigh β K₀ of the projected stiffness at the step's start.

// Parallel arrays (positions, masses, gradients) are walked by one index together.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3, Mat3, Vec3A};
use nalgebra::{SMatrix, SVector};

use super::SoftBody;
use super::strain::Prepared;
use crate::integrator::implicit::{ContactPlane, ImplicitElements};

type M9 = SMatrix<f64, 9, 9>;

fn vec9(m: DMat3) -> [f64; 9] {
    m.to_cols_array()
}

/// ∂P/∂F at F as a 9 × 9 matrix (column-major vec of F), and whether it is indefinite.
fn element_hessian(body: &SoftBody, prep: &Prepared) -> ([f64; 81], bool) {
    let mut h = M9::zeros();
    for (j, dp) in prep.differentials(body.lame).into_iter().enumerate() {
        for (i, v) in dp.to_cols_array().into_iter().enumerate() {
            h[(i, j)] = f64::from(v);
        }
    }
    let h = 0.5 * (h + h.transpose());
    // A Cholesky factorisation is a tenth of an eigen-decomposition's cost and proves the
    // common case, a positive definite element, without one.
    let scale = h.diagonal().amax().max(f64::MIN_POSITIVE);
    let definite = (h + M9::identity() * (1e-9 * scale)).cholesky().is_some();
    (flat(&h), !definite)
}

fn flat(m: &M9) -> [f64; 81] {
    std::array::from_fn(|k| m[(k % 9, k / 9)])
}

/// `h` with its negative eigenvalues set to zero. Only computed for the elements and the
/// Newton steps that need it: the eigen-decomposition is the solve's most expensive part.
fn project(h: &[f64; 81]) -> [f64; 81] {
    let mut eig = M9::from_column_slice(h).symmetric_eigen();
    eig.eigenvalues.iter_mut().for_each(|l| *l = l.max(0.0));
    flat(&eig.recompose())
}

/// The element's 4 × 4 node blocks V Bᵀ [∂P/∂F] B of K (K_ab = ∂f_a/∂x_b with a sign: the
/// stiffness, positive for a stable element), from dF = Σ_b dx_b b_bᵀ.
fn element_blocks(b: &[DVec3; 4], hess: &[f64; 81], vol: f64) -> [[DMat3; 4]; 4] {
    // w[a][c][s]: Σ_k b_a[k] H[(r + 3k), s] for row r = c, i.e. row c of bₐ's 3 × 9 slab.
    let mut w = [[[0.0f64; 9]; 3]; 4];
    for a in 0..4 {
        for r in 0..3 {
            for col in 0..9 {
                let mut acc = 0.0;
                for k in 0..3 {
                    acc += b[a][k] * hess[col * 9 + r + 3 * k];
                }
                w[a][r][col] = vol * acc;
            }
        }
    }
    let mut out = [[DMat3::ZERO; 4]; 4];
    for a in 0..4 {
        for bb in 0..=a {
            let mut m = DMat3::ZERO;
            for r in 0..3 {
                for s2 in 0..3 {
                    let mut acc = 0.0;
                    for d in 0..3 {
                        acc += w[a][r][s2 + 3 * d] * b[bb][d];
                    }
                    m.col_mut(s2)[r] = acc;
                }
            }
            out[a][bb] = m;
            out[bb][a] = m.transpose();
        }
    }
    out
}

fn mul9(h: &[f64; 81], v: [f64; 9]) -> [f64; 9] {
    (M9::from_column_slice(h) * SVector::<f64, 9>::from(v)).into()
}

/// The rows b₀..b₃ of the element's shape-function gradients: dF = Σₐ dxₐ bₐᵀ.
fn gradients(dm_inv: DMat3) -> [DVec3; 4] {
    let t = dm_inv.transpose();
    let (b1, b2, b3) = (t.x_axis, t.y_axis, t.z_axis);
    [-(b1 + b2 + b3), b1, b2, b3]
}

impl ImplicitElements for SoftBody {
    type Hess = [f64; 81];
    type Prep = (Prepared, Mat3);

    fn count(&self) -> usize {
        self.tets.len()
    }

    fn zero() -> Self::Hess {
        [0.0; 81]
    }

    fn nodes(&self, k: usize) -> &[u32] {
        &self.tets[k]
    }

    fn mass_damping(&self) -> f64 {
        f64::from(self.material.damping().0)
    }

    fn has_damping(&self) -> bool {
        self.material.damping().1 > 0.0
    }

    fn planes(&self) -> &[ContactPlane] {
        &self.contacts
    }

    fn prepare(&self, x: &[Vec3A], prep: &mut Vec<Self::Prep>) -> f64 {
        prepare_elements(self, x, prep)
    }

    fn forces(&self, prep: &[Self::Prep], out: &mut [Vec3A]) -> bool {
        elastic_from(self, prep, out)
    }

    fn hessian(&self, _k: usize, prep: &Self::Prep) -> (Self::Hess, bool) {
        element_hessian(self, &prep.0)
    }

    fn project(h: &Self::Hess) -> Self::Hess {
        project(h)
    }

    fn damping(&self, _k: usize, _prep: &Self::Prep, projected: &Self::Hess) -> Option<Self::Hess> {
        let beta = f64::from(self.material.damping().1);
        (beta > 0.0).then(|| projected.map(|v| beta * v))
    }

    fn apply(&self, k: usize, h: &Self::Hess, dx: &[DVec3], scale: f64, out: &mut [DVec3]) {
        let t = self.tets[k];
        let dm_inv = self.dm_inv[k].as_dmat3();
        let d = |i: usize| dx[t[i] as usize] - dx[t[0] as usize];
        let df = DMat3::from_cols(d(1), d(2), d(3)) * dm_inv;
        let dp = DMat3::from_cols_array(&mul9(h, vec9(df)));
        let f = (scale * f64::from(self.volume[k])) * dp * dm_inv.transpose();
        out[t[1] as usize] += f.x_axis;
        out[t[2] as usize] += f.y_axis;
        out[t[3] as usize] += f.z_axis;
        out[t[0] as usize] -= f.x_axis + f.y_axis + f.z_axis;
    }

    fn add_diagonal(&self, k: usize, h: &Self::Hess, scale: f64, out: &mut [DVec3]) {
        let t = self.tets[k];
        let b = gradients(self.dm_inv[k].as_dmat3());
        let vol = scale * f64::from(self.volume[k]);
        for (a, &node) in t.iter().enumerate() {
            let mut d = [0.0f64; 3];
            for (c, slot) in d.iter_mut().enumerate() {
                // dF = e_c bₐᵀ: row c of dF is bₐ.
                let mut e = DMat3::ZERO;
                e.x_axis[c] = b[a].x;
                e.y_axis[c] = b[a].y;
                e.z_axis[c] = b[a].z;
                let v = vec9(e);
                let hv = mul9(h, v);
                *slot = vol * v.iter().zip(hv).map(|(x, y)| x * y).sum::<f64>();
            }
            out[node as usize] += DVec3::from_array(d);
        }
    }

    fn blocks(&self, k: usize, h: &Self::Hess, scale: f64, add: &mut dyn FnMut(u32, u32, DMat3)) {
        let t = self.tets[k];
        let b = gradients(self.dm_inv[k].as_dmat3());
        let blocks = element_blocks(&b, h, scale * f64::from(self.volume[k]));
        for a in 0..4 {
            for c in 0..4 {
                add(t[a], t[c], blocks[a][c]);
            }
        }
    }

    fn finish(&mut self, prep: &[Self::Prep], energy: f64) {
        record_stats(self, prep, energy);
    }
}

/// Decomposes every element at positions `x` (once per iterate: for the co-rotated model
/// the polar decomposition is the solve's dominant cost) into `prep`, its P into `piola`;
/// returns the elastic energy Σ V Ψ (J).
fn prepare_elements(body: &SoftBody, x: &[Vec3A], prep: &mut Vec<(Prepared, Mat3)>) -> f64 {
    prep.clear();
    let mut e = 0.0f64;
    for k in 0..body.tets.len() {
        let f = body.deformation_gradient(x, k);
        let p = Prepared::new(body.model, f, body.lame);
        let stress = p.stress(body.model, body.lame);
        e += f64::from(body.volume[k]) * f64::from(stress.energy);
        prep.push((p, stress.piola));
    }
    e
}

/// The elastic forces −V P Dm⁻ᵀ of the prepared elements into `out`; false if non-finite.
fn elastic_from(body: &SoftBody, prep: &[(Prepared, Mat3)], out: &mut [Vec3A]) -> bool {
    out.iter_mut().for_each(|f| *f = Vec3A::ZERO);
    let mut finite = true;
    for (k, t) in body.tets.iter().enumerate() {
        let h = -body.volume[k] * prep[k].1 * body.dm_inv[k].transpose();
        finite &= h.is_finite();
        super::scatter_element_forces(out, *t, h);
    }
    finite
}

/// The body's stats (energy, volume ratio, inverted count) from the prepared elements.
fn record_stats(body: &mut SoftBody, prep: &[(Prepared, Mat3)], elastic: f64) {
    let (mut vj, mut vsum, mut inverted) = (0.0f64, 0.0f64, 0usize);
    for (p, &vol) in prep.iter().zip(&body.volume) {
        let j = p.0.deformation().determinant();
        inverted += usize::from(j <= 0.0);
        vj += f64::from(vol) * f64::from(j);
        vsum += f64::from(vol);
    }
    body.stats.elastic_energy = elastic;
    body.stats.volume_ratio = (vj / vsum) as f32;
    body.stats.inverted = inverted;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft::{CellSplit, Material, StrainModel, TetMesh};
    use glam::Vec3;

    /// The assembled node blocks (the factor's matrix) apply the same K as the matrix-free
    /// product the conjugate gradients use.
    #[test]
    fn element_blocks_apply_the_matrix_free_stiffness() {
        let mesh = TetMesh::cuboid(Vec3::new(1.0, 0.3, 0.2), [3, 2, 1], CellSplit::Five).unwrap();
        let material = Material::new(1e6, 0.3, 1000.0).unwrap();
        let (nodes, body) =
            SoftBody::build(&mesh, Vec3::ZERO, material, StrainModel::Corotated).unwrap();
        // A bent, twisted state, so that the element matrices are far from the rest ones.
        let x: Vec<Vec3A> = nodes
            .positions()
            .iter()
            .map(|p| {
                let (s, c) = (0.4 * p.x).sin_cos();
                Vec3A::new(
                    p.x + 0.1 * p.y * s,
                    c * p.y - s * p.z,
                    s * p.y + c * p.z + 0.05 * p.x * p.x,
                )
            })
            .collect();
        let hess: Vec<[f64; 81]> = (0..body.tets.len())
            .map(|k| {
                let f = body.deformation_gradient(&x, k);
                element_hessian(&body, &Prepared::new(body.model, f, body.lame)).0
            })
            .collect();
        let dx: Vec<DVec3> = (0..x.len())
            .map(|i| {
                DVec3::new(
                    (i as f64).sin(),
                    (2.0 * i as f64).cos(),
                    0.3 - 0.01 * i as f64,
                )
            })
            .collect();
        let mut free_product = vec![DVec3::ZERO; x.len()];
        for (k, h) in hess.iter().enumerate() {
            body.apply(k, h, &dx, 1.0, &mut free_product);
        }
        let mut assembled = vec![DVec3::ZERO; x.len()];
        for (k, t) in body.tets.iter().enumerate() {
            let b = gradients(body.dm_inv[k].as_dmat3());
            let blocks = element_blocks(&b, &hess[k], f64::from(body.volume[k]));
            for a in 0..4 {
                for c in 0..4 {
                    assembled[t[a] as usize] += blocks[a][c] * dx[t[c] as usize];
                }
            }
        }
        let scale = free_product.iter().map(|v| v.length()).fold(0.0, f64::max);
        for (a, b) in assembled.iter().zip(&free_product) {
            assert!((*a - *b).length() <= 1e-9 * scale, "{a} vs {b}");
        }
    }
}
