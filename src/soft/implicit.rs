//! Backward Euler for soft bodies: Newton on the incremental potential with a matrix-free,
//! Jacobi-preconditioned conjugate-gradient solve (see [`crate::ImplicitEuler`]).
//!
//! For a substep h, with y = x₀ + h v₀ and D = α M + β K₀ (Rayleigh damping, K₀ the projected
//! stiffness at the step's first iterate):
//!
//! ```text
//! E(x) = ½ (x − y)ᵀ M (x − y) / h² + U(x) − f_extᵀ x + ½ (x − x₀)ᵀ D (x − x₀) / h
//! g(x) = M (x − y) / h² + ∇U(x) − f_ext + D (x − x₀) / h
//! H(x) = M / h² + K(x) + D / h,        K = Σₑ Vₑ Bₑᵀ [∂P/∂F]₊ Bₑ
//! ```
//!
//! [∂P/∂F]₊ is the element's 9 × 9 stress derivative with its negative eigenvalues set to
//! zero, so H is positive definite and each Newton direction descends E; a backtracking line
//! search on E then makes every step lower the potential, which is what makes the scheme
//! stable at any stiffness and step.

// Parallel arrays (positions, masses, gradients) are walked by one index together.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3, Mat3, Vec3, Vec3A};
use nalgebra::{SMatrix, SVector};

use super::SoftBody;
use super::strain::Prepared;
use crate::integrator::skyline::SkylineCholesky;
use crate::integrator::{ImplicitEuler, ImplicitState};
use crate::particles::Nodes;

/// What one implicit substep did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImplicitReport {
    /// Newton iterations taken.
    pub newton_iterations: u32,
    /// Conjugate-gradient iterations, summed over the Newton iterations.
    pub cg_iterations: u32,
    /// ‖g‖ at the end over ‖g‖ at the start (0 when the start was already at rest).
    pub residual: f32,
}

/// Buffers kept between substeps, so a step allocates nothing once warm. The linear algebra
/// runs in f64: a beam's stiffness matrix is ill-conditioned enough that f32 conjugate
/// gradients stall at a relative residual of about 1e-2.
#[derive(Default)]
pub(crate) struct Scratch {
    x0: Vec<Vec3A>,
    y: Vec<Vec3A>,
    trial: Vec<Vec3A>,
    elastic: Vec<Vec3A>,
    zero: Vec<Vec3A>,
    g: Vec<DVec3>,
    dx: Vec<DVec3>,
    r: Vec<DVec3>,
    z: Vec<DVec3>,
    p: Vec<DVec3>,
    q: Vec<DVec3>,
    diag: Vec<DVec3>,
    d: Vec<DVec3>,
    kd: Vec<DVec3>,
    /// ∂P/∂F per element at the current iterate, as is and projected; the projected one at
    /// the first iterate (for D).
    raw: Vec<[f64; 81]>,
    hess: Vec<[f64; 81]>,
    hess0: Vec<[f64; 81]>,
    /// Per node, whether it moves (not pinned).
    free: Vec<bool>,
    /// Per node, the normal of a contact holding it (zero for none).
    filter: Vec<DVec3>,
    /// Whether any element is indefinite this iteration, which ones, and whether `hess`
    /// holds this iteration's projections yet.
    indefinite: bool,
    negative: Vec<bool>,
    projected: bool,
    /// The factor's triangular-solve buffer.
    work: Vec<f64>,
    /// The elements decomposed at the current iterate and at the line search's trial, and
    /// their P.
    prep: Vec<Prepared>,
    prep_trial: Vec<Prepared>,
    piola: Vec<Mat3>,
    piola_trial: Vec<Mat3>,
}

/// `s.hess` ← the projections of `s.raw` (once per Newton iteration).
fn project_hessians(s: &mut Scratch) {
    if s.projected {
        return;
    }
    for k in 0..s.raw.len() {
        s.hess[k] = if s.negative[k] {
            project(&s.raw[k])
        } else {
            s.raw[k]
        };
    }
    s.projected = true;
}

/// Builds (once per mesh) the factor's envelope, and asks for a new factor when h changed.
fn prepare_factor(
    body: &SoftBody,
    settings: &ImplicitEuler,
    state: &mut ImplicitState,
    len: usize,
    h: f32,
) {
    let key = (len, body.tets.len());
    if state.built_for != Some(key) {
        state.built_for = Some(key);
        state.factor = None;
        if settings.max_factor_entries > 0 {
            let mut adjacency = vec![Vec::new(); len];
            for t in &body.tets {
                for &a in t {
                    adjacency[a as usize].extend_from_slice(t);
                }
            }
            for list in &mut adjacency {
                list.sort_unstable();
                list.dedup();
            }
            state.factor = SkylineCholesky::new(&adjacency, settings.max_factor_entries);
        }
    }
    if state.h != h {
        state.h = h;
        state.refactor = true;
    }
}

/// The factor to precondition this solve with: renewed from H (`hess` elements, D from
/// `s.hess0`) when asked for or when none is held; None (Jacobi) when the body has no
/// envelope or H is not positive definite.
#[allow(clippy::too_many_arguments)] // the solve's whole state, passed once per Newton step
fn refresh_factor<'a>(
    body: &SoftBody,
    n: &Nodes,
    s: &Scratch,
    state: &'a mut ImplicitState,
    hess: &[[f64; 81]],
    free: &[bool],
    hd: f64,
    alpha: f64,
    beta: f64,
) -> Option<&'a SkylineCholesky> {
    let renew = state.refactor || !state.factor.as_ref()?.is_factored();
    let factor = state.factor.as_mut()?;
    if renew {
        state.refactor = false;
        let mass_term = |m: f32| f64::from(m) * (1.0 / (hd * hd) + alpha / hd);
        factor.factor(|add| {
            for i in 0..free.len() {
                // A pinned node's row is the identity times a mass-like scale, so the
                // factor stays well conditioned; its unknowns are zero anyway.
                let m = mass_term(n.mass[i]).max(1.0);
                add(i as u32, i as u32, DMat3::from_diagonal(DVec3::splat(m)));
            }
            let mut element = |k: usize, t: &[u32; 4], h: &[f64; 81], scale: f64| {
                let b = gradients(body.dm_inv[k].as_dmat3());
                let blocks = element_blocks(&b, h, scale * f64::from(body.volume[k]));
                for a in 0..4 {
                    for c in 0..4 {
                        let (i, j) = (t[a] as usize, t[c] as usize);
                        if free[i] && free[j] {
                            add(t[a], t[c], blocks[a][c]);
                        }
                    }
                }
            };
            for (k, t) in body.tets.iter().enumerate() {
                element(k, t, &hess[k], 1.0);
                if beta > 0.0 {
                    element(k, t, &s.hess0[k], beta / hd);
                }
            }
        });
    }
    factor.is_factored().then_some(&*factor)
}

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

/// out += scale · K dx with K from the per-element 9 × 9 matrices `hess`.
fn add_stiffness(body: &SoftBody, hess: &[[f64; 81]], dx: &[DVec3], scale: f64, out: &mut [DVec3]) {
    for (k, t) in body.tets.iter().enumerate() {
        let dm_inv = body.dm_inv[k].as_dmat3();
        let d = |i: usize| dx[t[i] as usize] - dx[t[0] as usize];
        let df = DMat3::from_cols(d(1), d(2), d(3)) * dm_inv;
        let dp = DMat3::from_cols_array(&mul9(&hess[k], vec9(df)));
        let h = (scale * f64::from(body.volume[k])) * dp * dm_inv.transpose();
        out[t[1] as usize] += h.x_axis;
        out[t[2] as usize] += h.y_axis;
        out[t[3] as usize] += h.z_axis;
        out[t[0] as usize] -= h.x_axis + h.y_axis + h.z_axis;
    }
}

/// out += scale · diag(K), for the Jacobi preconditioner.
fn add_stiffness_diagonal(body: &SoftBody, hess: &[[f64; 81]], scale: f64, out: &mut [DVec3]) {
    for (k, t) in body.tets.iter().enumerate() {
        let b = gradients(body.dm_inv[k].as_dmat3());
        let vol = scale * f64::from(body.volume[k]);
        for (a, &node) in t.iter().enumerate() {
            let mut d = [0.0f64; 3];
            for (c, slot) in d.iter_mut().enumerate() {
                // dF = e_c bₐᵀ: row c of dF is bₐ.
                let mut e = DMat3::ZERO;
                e.x_axis[c] = b[a].x;
                e.y_axis[c] = b[a].y;
                e.z_axis[c] = b[a].z;
                let v = vec9(e);
                let hv = mul9(&hess[k], v);
                *slot = vol * v.iter().zip(hv).map(|(x, y)| x * y).sum::<f64>();
            }
            out[node as usize] += DVec3::from_array(d);
        }
    }
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

fn d3(v: Vec3A) -> DVec3 {
    Vec3::from(v).as_dvec3()
}

/// The incremental potential E(x) (J) but its elastic part (see [`prepare_elements`]), without
/// the constant terms.
fn potential_rest(
    body: &SoftBody,
    n: &Nodes,
    s: &mut Scratch,
    x: &[Vec3A],
    h: f64,
    alpha: f64,
    beta: f64,
) -> f64 {
    let mut e = 0.0f64;
    let inv_h2 = 1.0 / (h * h);
    for i in 0..x.len() {
        if n.inv_mass[i] == 0.0 {
            continue;
        }
        let m = f64::from(n.mass[i]);
        let (xi, yi, x0) = (d3(x[i]), d3(s.y[i]), d3(s.x0[i]));
        e += 0.5 * m * inv_h2 * (xi - yi).length_squared()
            + 0.5 * alpha * m / h * (xi - x0).length_squared()
            - d3(n.f[i]).dot(xi);
    }
    if beta > 0.0 {
        // ½ β/h (x − x₀)ᵀ K₀ (x − x₀)
        for i in 0..x.len() {
            s.d[i] = d3(x[i]) - d3(s.x0[i]);
            s.kd[i] = DVec3::ZERO;
        }
        let (d, mut kd) = (std::mem::take(&mut s.d), std::mem::take(&mut s.kd));
        add_stiffness(body, &s.hess0, &d, 1.0, &mut kd);
        e += 0.5 * beta / h * dot(&d, &kd);
        (s.d, s.kd) = (d, kd);
    }
    e
}

/// Decomposes every element at positions `x` (once per iterate: for the co-rotated model
/// the polar decomposition is the solve's dominant cost) into `prep`, its P into `piola`;
/// returns the elastic energy Σ V Ψ (J).
fn prepare_elements(
    body: &SoftBody,
    x: &[Vec3A],
    prep: &mut Vec<Prepared>,
    piola: &mut Vec<Mat3>,
) -> f64 {
    prep.clear();
    piola.clear();
    let mut e = 0.0f64;
    for k in 0..body.tets.len() {
        let f = body.deformation_gradient(x, k);
        let p = Prepared::new(body.model, f, body.lame);
        let stress = p.stress(body.model, body.lame);
        e += f64::from(body.volume[k]) * f64::from(stress.energy);
        prep.push(p);
        piola.push(stress.piola);
    }
    e
}

/// The elastic forces −V P Dm⁻ᵀ of the prepared elements into `out`; false if non-finite.
fn elastic_from(body: &SoftBody, piola: &[Mat3], out: &mut [Vec3A]) -> bool {
    out.iter_mut().for_each(|f| *f = Vec3A::ZERO);
    let mut finite = true;
    for (k, t) in body.tets.iter().enumerate() {
        let h = -body.volume[k] * piola[k] * body.dm_inv[k].transpose();
        finite &= h.is_finite();
        super::scatter_element_forces(out, *t, h);
    }
    finite
}

/// The body's stats (energy, volume ratio, inverted count) from the prepared elements.
fn record_stats(body: &mut SoftBody, prep: &[Prepared], elastic: f64) {
    let (mut vj, mut vsum, mut inverted) = (0.0f64, 0.0f64, 0usize);
    for (p, &vol) in prep.iter().zip(&body.volume) {
        let j = p.deformation().determinant();
        inverted += usize::from(j <= 0.0);
        vj += f64::from(vol) * f64::from(j);
        vsum += f64::from(vol);
    }
    body.stats.elastic_energy = elastic as f32;
    body.stats.volume_ratio = (vj / vsum) as f32;
    body.stats.inverted = inverted;
}

/// One backward-Euler substep of length `h` for `body`'s nodes. `n.f` holds the step's
/// constant forces (gravity, external, damping), not the elastic ones. Returns None if the
/// state turned non-finite.
pub(crate) fn step(
    body: &mut SoftBody,
    n: &mut Nodes,
    settings: &ImplicitEuler,
    state: &mut ImplicitState,
    h: f32,
    s: &mut Scratch,
) -> Option<ImplicitReport> {
    let len = n.x.len();
    prepare_factor(body, settings, state, len, h);
    let (alpha, beta) = body.material.damping();
    let (alpha, beta, hd) = (f64::from(alpha), f64::from(beta), f64::from(h));
    for buf in [
        &mut s.x0,
        &mut s.y,
        &mut s.trial,
        &mut s.elastic,
        &mut s.zero,
    ] {
        buf.clear();
        buf.resize(len, Vec3A::ZERO);
    }
    for buf in [
        &mut s.g,
        &mut s.dx,
        &mut s.r,
        &mut s.z,
        &mut s.p,
        &mut s.q,
        &mut s.diag,
        &mut s.d,
        &mut s.kd,
    ] {
        buf.clear();
        buf.resize(len, DVec3::ZERO);
    }
    s.x0.copy_from_slice(&n.x);
    for i in 0..len {
        s.y[i] = n.x[i] + h * n.v[i];
    }
    // The inertial predictor is the first iterate; pinned nodes stay there.
    // Contacts found at the end of the last substep: planes n·x ≥ d the nodes may not cross.
    clamp_to_contacts(&body.contacts, &mut s.y);
    n.x.copy_from_slice(&s.y);
    let mut free = std::mem::take(&mut s.free);
    free.clear();
    free.extend(n.inv_mass.iter().map(|&w| w != 0.0));
    let inv_h2 = 1.0 / (hd * hd);
    let mut report = ImplicitReport::default();
    let (mut g0, mut previous) = (0.0f64, f64::INFINITY);
    let mut clamped = false;
    s.hess.resize(body.tets.len(), [0.0; 81]);
    s.raw.resize(body.tets.len(), [0.0; 81]);
    s.negative.resize(body.tets.len(), false);
    let mut elastic_now = prepare_elements(body, &n.x, &mut s.prep, &mut s.piola);
    for it in 0..settings.max_newton {
        s.indefinite = false;
        for k in 0..body.tets.len() {
            let (raw, negative) = element_hessian(body, &s.prep[k]);
            s.indefinite |= negative;
            s.raw[k] = raw;
            s.negative[k] = negative;
        }
        s.projected = false;
        if it == 0 {
            // D = α M + β K₀ must be positive semi-definite: K₀ from projected elements.
            if beta > 0.0 {
                project_hessians(s);
                s.hess0.clone_from(&s.hess);
            } else {
                s.hess0.clear();
            }
        }
        if !elastic_from(body, &s.piola, &mut s.elastic) {
            return None;
        }
        for i in 0..len {
            s.g[i] = if free[i] {
                let m = f64::from(n.mass[i]);
                m * inv_h2 * (d3(n.x[i]) - d3(s.y[i])) - d3(s.elastic[i]) - d3(n.f[i])
                    + alpha * m / hd * (d3(n.x[i]) - d3(s.x0[i]))
            } else {
                DVec3::ZERO
            };
        }
        if beta > 0.0 {
            for i in 0..len {
                s.d[i] = d3(n.x[i]) - d3(s.x0[i]);
                s.kd[i] = DVec3::ZERO;
            }
            let (d, mut kd) = (std::mem::take(&mut s.d), std::mem::take(&mut s.kd));
            add_stiffness(body, &s.hess0, &d, beta / hd, &mut kd);
            for i in 0..len {
                if free[i] {
                    s.g[i] += kd[i];
                }
            }
            (s.d, s.kd) = (d, kd);
        }
        // A node on its contact plane that the gradient pushes in is held there: the
        // contact takes the normal part (Baraff and Witkin's filter). One pulled away is free.
        s.filter.clear();
        s.filter.resize(len, DVec3::ZERO);
        for c in &body.contacts {
            let i = c.node as usize;
            let normal = c.normal.as_dvec3();
            let on_plane =
                f64::from(c.normal.dot(Vec3::from(n.x[i]))) <= f64::from(c.offset) + 1e-6;
            if on_plane && s.g[i].dot(normal) > 0.0 {
                s.filter[i] = normal;
                let gn = s.g[i].dot(normal);
                s.g[i] -= gn * normal;
            }
        }
        let gnorm = dot(&s.g, &s.g).sqrt();
        if !gnorm.is_finite() {
            return None;
        }
        if it == 0 {
            // The force scale of the step: the first gradient, or, for a body already at rest
            // (where that is only rounding), its weight and momentum over h.
            let mut load = 0.0f64;
            for i in 0..len {
                if free[i] {
                    let momentum = f64::from(n.mass[i]) * d3(n.v[i]) / hd;
                    load += (d3(n.f[i]).length() + momentum.length()).powi(2);
                }
            }
            g0 = gnorm.max(load.sqrt());
        }
        report.residual = if g0 > 0.0 { (gnorm / g0) as f32 } else { 0.0 };
        // Converged; or stalled at the floor that f32 positions set (near 1e-4 of the first
        // gradient on a stiff body), where Newton can only shuffle rounding.
        // (Or no progress at all: at rest on a stiff body the rounding floor can lie above
        // 1e-2 of the scale.) A gradient that grew because the last step put nodes back on
        // their contact planes is not a stall: the next Newton step answers the contact.
        let stalled =
            (gnorm > 0.5 * previous && gnorm < 1e-2 * g0) || (gnorm > 0.9 * previous && !clamped);
        if g0 == 0.0 || gnorm <= f64::from(settings.tolerance) * g0 || stalled {
            break;
        }
        previous = gnorm;
        report.newton_iterations += 1;

        // CG on H dx = −g, dx = 0 on pinned nodes. The element Hessians as they are first:
        // the mass term usually keeps H positive definite, and the exact H converges
        // quadratically where the projected one crawls. On negative curvature, again with
        // the projected ones, which always descend.
        let attempts: &[bool] = if s.indefinite {
            &[false, true]
        } else {
            &[false]
        };
        for &projected in attempts {
            if projected {
                project_hessians(s);
            }
            let hess = if projected {
                std::mem::take(&mut s.hess)
            } else {
                std::mem::take(&mut s.raw)
            };
            let factor = refresh_factor(body, n, s, state, &hess, &free, hd, alpha, beta);
            let before = report.cg_iterations;
            let ok = conjugate_gradients(
                body,
                n,
                s,
                &hess,
                factor,
                &free,
                hd,
                alpha,
                beta,
                settings,
                &mut report,
            );
            // With a lagged factor, CG on an indefinite H need not meet its negative
            // curvature and can return a direction that climbs E: that is a failure too.
            let ok = ok && dot(&s.g, &s.dx) < 0.0;
            if factor.is_some() && report.cg_iterations - before > settings.refactor_after {
                state.refactor = true;
            }
            if projected {
                s.hess = hess;
            } else {
                s.raw = hess;
            }
            if ok {
                break;
            }
            // Negative curvature: the factor (if of the raw matrix) is no use for the
            // projected one.
            state.refactor = true;
        }

        // A correction below the resolution of f32 positions (a few ulps of the body's
        // extent) is the last one that can change anything: take it and stop.
        let scale = n.x.iter().fold(0.0f32, |m, x| m.max(x.abs().max_element()));
        let resolution = 16.0 * f64::from(f32::EPSILON) * f64::from(scale.max(1e-3));
        let last =
            s.dx.iter()
                .zip(&free)
                .all(|(d, &f)| !f || d.abs().max_element() <= resolution);

        // Backtracking line search on E.
        let e_now = elastic_now + potential_rest(body, n, s, &n.x, hd, alpha, beta);
        let slope = dot(&s.g, &s.dx);
        let mut step = 1.0f64;
        let mut accepted = false;
        for _ in 0..12 {
            let mut trial = std::mem::take(&mut s.trial);
            for i in 0..len {
                trial[i] = Vec3A::from((d3(n.x[i]) + step * s.dx[i]).as_vec3());
            }
            let elastic = prepare_elements(body, &trial, &mut s.prep_trial, &mut s.piola_trial);
            let e_new = elastic + potential_rest(body, n, s, &trial, hd, alpha, beta);
            s.trial = trial;
            if e_new.is_finite() && e_new <= e_now + 1e-4 * step * slope {
                accepted = true;
                elastic_now = elastic;
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
        std::mem::swap(&mut s.prep, &mut s.prep_trial);
        std::mem::swap(&mut s.piola, &mut s.piola_trial);
        let moved = clamp_to_contacts(&body.contacts, &mut s.trial);
        clamped = moved;
        n.x.copy_from_slice(&s.trial);
        if moved {
            elastic_now = prepare_elements(body, &n.x, &mut s.prep, &mut s.piola);
        }
        if last {
            break;
        }
    }
    for i in 0..len {
        n.v[i] = (n.x[i] - s.x0[i]) / h;
    }
    s.free = free;
    // Stats at the end state, whose elements the last accepted trial prepared.
    record_stats(body, &s.prep, elastic_now);
    (elastic_now.is_finite() && n.x.iter().all(|x| x.is_finite())).then_some(report)
}

/// CG on H dx = −g with the element matrices `hess` (and D from `s.hess0`, K₀'s); false if it met
/// negative curvature.
#[allow(clippy::too_many_arguments)] // the solve's whole state, passed once per Newton step
fn conjugate_gradients(
    body: &SoftBody,
    n: &Nodes,
    s: &mut Scratch,
    hess: &[[f64; 81]],
    factor: Option<&SkylineCholesky>,
    free: &[bool],
    hd: f64,
    alpha: f64,
    beta: f64,
    settings: &ImplicitEuler,
    report: &mut ImplicitReport,
) -> bool {
    let len = n.x.len();
    let mass_term = |m: f32| f64::from(m) * (1.0 / (hd * hd) + alpha / hd);
    let precondition = |r: DVec3, d: DVec3| r / d.max(DVec3::splat(f64::MIN_POSITIVE));
    // Jacobi preconditioner, diag(H), when there is no factor.
    if factor.is_none() {
        for i in 0..len {
            s.diag[i] = DVec3::splat(mass_term(n.mass[i]));
        }
        add_stiffness_diagonal(body, hess, 1.0, &mut s.diag);
        if beta > 0.0 {
            add_stiffness_diagonal(body, &s.hess0, beta / hd, &mut s.diag);
        }
    }
    // z = S P⁻¹ S r, S the contact filter (symmetric, so CG still applies).
    let apply = |s: &mut Scratch| {
        if let Some(factor) = factor {
            for i in 0..len {
                s.q[i] = filtered(s.r[i], s.filter[i]);
            }
            let mut work = std::mem::take(&mut s.work);
            factor.solve(&s.q, &mut s.z, &mut work);
            s.work = work;
            for i in 0..len {
                s.z[i] = if free[i] {
                    filtered(s.z[i], s.filter[i])
                } else {
                    DVec3::ZERO
                };
            }
        } else {
            for i in 0..len {
                s.z[i] = filtered(precondition(s.r[i], s.diag[i]), s.filter[i]);
            }
        }
    };
    for i in 0..len {
        s.dx[i] = DVec3::ZERO;
        s.r[i] = -s.g[i];
    }
    apply(s);
    s.p.copy_from_slice(&s.z);
    let mut rz = dot(&s.r, &s.z);
    let r0 = dot(&s.r, &s.r).sqrt();
    for _ in 0..settings.max_cg {
        for i in 0..len {
            s.q[i] = mass_term(n.mass[i]) * s.p[i];
        }
        add_stiffness(body, hess, &s.p, 1.0, &mut s.q);
        if beta > 0.0 {
            add_stiffness(body, &s.hess0, &s.p, beta / hd, &mut s.q);
        }
        for i in 0..len {
            if !free[i] {
                s.q[i] = DVec3::ZERO;
            }
            s.q[i] = filtered(s.q[i], s.filter[i]);
        }
        let pq = dot(&s.p, &s.q);
        report.cg_iterations += 1;
        if pq.is_nan() || pq <= 0.0 {
            return false;
        }
        let a = rz / pq;
        for i in 0..len {
            s.dx[i] += a * s.p[i];
            s.r[i] -= a * s.q[i];
        }
        if dot(&s.r, &s.r).sqrt() <= 1e-3 * r0 {
            break;
        }
        apply(s);
        let rz_new = dot(&s.r, &s.z);
        let b = rz_new / rz;
        rz = rz_new;
        for i in 0..len {
            s.p[i] = s.z[i] + b * s.p[i];
        }
    }
    true
}

/// v without its part along the unit normal `n` (v itself for a zero n).
fn filtered(v: DVec3, n: DVec3) -> DVec3 {
    v - v.dot(n) * n
}

/// Moves every contact node that crossed its plane back onto it; whether any moved.
fn clamp_to_contacts(contacts: &[super::NodeContact], x: &mut [Vec3A]) -> bool {
    let mut moved = false;
    for c in contacts {
        let i = c.node as usize;
        let gap = c.normal.dot(Vec3::from(x[i])) - c.offset;
        if gap < 0.0 {
            x[i] -= Vec3A::from(gap * c.normal);
            moved = true;
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft::{CellSplit, Material, StrainModel, TetMesh};

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
        add_stiffness(&body, &hess, &dx, 1.0, &mut free_product);
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
