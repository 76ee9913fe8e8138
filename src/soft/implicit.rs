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
use crate::integrator::ImplicitEuler;
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
    /// Whether any element needed projecting this iteration.
    indefinite: bool,
}

type M9 = SMatrix<f64, 9, 9>;

fn vec9(m: DMat3) -> [f64; 9] {
    m.to_cols_array()
}

/// ∂P/∂F at F as a 9 × 9 matrix (column-major vec of F), and the same projected to positive
/// semi-definite (`None` when it already is).
fn element_hessian(body: &SoftBody, f: Mat3) -> ([f64; 81], Option<[f64; 81]>) {
    let mut h = M9::zeros();
    for (j, dp) in body
        .model
        .differentials(f, body.lame)
        .into_iter()
        .enumerate()
    {
        for (i, v) in dp.to_cols_array().into_iter().enumerate() {
            h[(i, j)] = f64::from(v);
        }
    }
    let h = 0.5 * (h + h.transpose());
    let flat = |m: &M9| std::array::from_fn(|k| m[(k % 9, k / 9)]);
    // A Cholesky factorisation is a tenth of an eigen-decomposition's cost and proves the
    // common case, a positive definite element, without one.
    let scale = h.diagonal().amax().max(f64::MIN_POSITIVE);
    if (h + M9::identity() * (1e-9 * scale)).cholesky().is_some() {
        return (flat(&h), None);
    }
    let mut eig = h.symmetric_eigen();
    let mut negative = false;
    for l in eig.eigenvalues.iter_mut() {
        if *l < 0.0 {
            *l = 0.0;
            negative = true;
        }
    }
    (flat(&h), negative.then(|| flat(&eig.recompose())))
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

/// The incremental potential E(x) (J), without the constant terms.
fn potential(
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
    for k in 0..body.tets.len() {
        let f = body.deformation_gradient(x, k);
        e += f64::from(body.volume[k]) * f64::from(body.model.energy_density(f, body.lame));
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

/// The elastic forces alone (no damping) at the nodes' positions into `s.elastic`; false if
/// non-finite.
fn elastic_forces(body: &mut SoftBody, n: &Nodes, s: &mut Scratch) -> bool {
    s.elastic.iter_mut().for_each(|f| *f = Vec3A::ZERO);
    // At zero velocity both Rayleigh terms vanish: what is left is the elastic force.
    body.accumulate(&n.x, &s.zero, &n.mass, &mut s.elastic)
}

/// One backward-Euler substep of length `h` for `body`'s nodes. `n.f` holds the step's
/// constant forces (gravity, external, damping), not the elastic ones. Returns None if the
/// state turned non-finite.
pub(crate) fn step(
    body: &mut SoftBody,
    n: &mut Nodes,
    settings: &ImplicitEuler,
    h: f32,
    s: &mut Scratch,
) -> Option<ImplicitReport> {
    let len = n.x.len();
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
    s.hess.resize(body.tets.len(), [0.0; 81]);
    s.raw.resize(body.tets.len(), [0.0; 81]);
    for it in 0..settings.max_newton {
        s.indefinite = false;
        for k in 0..body.tets.len() {
            let f = body.deformation_gradient(&n.x, k);
            let (raw, projected) = element_hessian(body, f);
            s.indefinite |= projected.is_some();
            s.raw[k] = raw;
            s.hess[k] = projected.unwrap_or(raw);
        }
        if it == 0 {
            s.hess0.clone_from(&s.hess);
        }
        let ok = elastic_forces(body, n, s);
        if !ok {
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
        // 1e-2 of the scale.)
        let stalled = (gnorm > 0.5 * previous && gnorm < 1e-2 * g0) || gnorm > 0.9 * previous;
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
            &[true]
        };
        for &projected in attempts {
            let hess = if projected {
                std::mem::take(&mut s.hess)
            } else {
                std::mem::take(&mut s.raw)
            };
            let ok = conjugate_gradients(
                body,
                n,
                s,
                &hess,
                &free,
                hd,
                alpha,
                beta,
                settings,
                &mut report,
            );
            if projected {
                s.hess = hess;
            } else {
                s.raw = hess;
            }
            if ok {
                break;
            }
        }

        // Backtracking line search on E.
        let e_now = potential(body, n, s, &n.x, hd, alpha, beta);
        let slope = dot(&s.g, &s.dx);
        let mut step = 1.0f64;
        let mut accepted = false;
        for _ in 0..12 {
            let mut trial = std::mem::take(&mut s.trial);
            for i in 0..len {
                trial[i] = Vec3A::from((d3(n.x[i]) + step * s.dx[i]).as_vec3());
            }
            let e_new = potential(body, n, s, &trial, hd, alpha, beta);
            s.trial = trial;
            if e_new.is_finite() && e_new <= e_now + 1e-4 * step * slope {
                accepted = true;
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
        clamp_to_contacts(&body.contacts, &mut s.trial);
        n.x.copy_from_slice(&s.trial);
    }
    for i in 0..len {
        n.v[i] = (n.x[i] - s.x0[i]) / h;
    }
    s.free = free;
    // Stats at the end state.
    let ok = elastic_forces(body, n, s);
    (ok && n.x.iter().all(|x| x.is_finite())).then_some(report)
}

/// CG on H dx = −g with the element matrices `hess` (and D from `s.hess0`, K₀'s); false if it met
/// negative curvature.
#[allow(clippy::too_many_arguments)] // the solve's whole state, passed once per Newton step
fn conjugate_gradients(
    body: &SoftBody,
    n: &Nodes,
    s: &mut Scratch,
    hess: &[[f64; 81]],
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
    // Jacobi preconditioner: diag(H).
    for i in 0..len {
        s.diag[i] = DVec3::splat(mass_term(n.mass[i]));
    }
    add_stiffness_diagonal(body, hess, 1.0, &mut s.diag);
    if beta > 0.0 {
        add_stiffness_diagonal(body, &s.hess0, beta / hd, &mut s.diag);
    }
    for i in 0..len {
        s.dx[i] = DVec3::ZERO;
        s.r[i] = -s.g[i];
        s.z[i] = filtered(precondition(s.r[i], s.diag[i]), s.filter[i]);
    }
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
        for i in 0..len {
            s.z[i] = filtered(precondition(s.r[i], s.diag[i]), s.filter[i]);
        }
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

/// Moves every contact node that crossed its plane back onto it.
fn clamp_to_contacts(contacts: &[super::NodeContact], x: &mut [Vec3A]) {
    for c in contacts {
        let i = c.node as usize;
        let gap = c.normal.dot(Vec3::from(x[i])) - c.offset;
        if gap < 0.0 {
            x[i] -= Vec3A::from(gap * c.normal);
        }
    }
}
