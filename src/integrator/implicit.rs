//! Backward Euler for meshes: Newton on the incremental potential with a preconditioned
//! conjugate-gradient solve, shared by every effect whose elements can say their energy,
//! forces and stiffness ([`ImplicitElements`]: soft bodies' tetrahedra, spring networks'
//! springs). See [`crate::integrator::ImplicitEuler`].
//!
//! For a substep h, with y = x₀ + h v₀ and D = α M + Σₖ Dₖ (mass-proportional damping and the
//! elements' own damping matrices at the step's start):
//!
//! ```text
//! E(x) = ½ (x − y)ᵀ M (x − y) / h² + U(x) − f_extᵀ x + ½ (x − x₀)ᵀ D (x − x₀) / h
//! g(x) = M (x − y) / h² + ∇U(x) − f_ext + D (x − x₀) / h
//! H(x) = M / h² + K(x) + D / h,        K = Σₖ Kₖ
//! ```
//!
//! Element matrices with negative curvature are projected to positive semi-definite when
//! the exact H fails to give a descent direction, so each Newton direction descends E; a
//! backtracking line search on E then makes every step lower the potential, which is what
//! makes the scheme stable at any stiffness and step. The conjugate gradients are
//! preconditioned by a skyline Cholesky factor of H ([`super::skyline`]) kept from step to
//! step, or by its diagonal for a mesh too large for one.

// Parallel arrays (positions, masses, gradients) are walked by one index together.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3, Vec3, Vec3A};

use super::skyline::SkylineCholesky;
use super::{ImplicitEuler, ImplicitState};
use crate::particles::Nodes;

/// A plane n·x ≥ offset a node may not cross during the solve (a contact with a static or
/// kinematic collider, moving with it over the substep).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub(crate) struct ContactPlane {
    pub node: u32,
    pub normal: Vec3,
    pub offset: f32,
}

/// What an effect gives the backward-Euler solve: its elements' energy, forces and
/// stiffness matrices over the nodes of one [`Nodes`] mesh. A soft body's elements are its
/// tetrahedra; a spring network's, its springs.
pub(crate) trait ImplicitElements {
    /// An element's stiffness matrix, in the element's own parametrisation.
    type Hess: Copy;
    /// What an element computes once per iterate (a decomposition) for energy, forces and
    /// its matrix.
    type Prep: Clone;
    /// The number of elements.
    fn count(&self) -> usize;
    /// A zero element matrix.
    fn zero() -> Self::Hess;
    /// Element k's nodes.
    fn nodes(&self, k: usize) -> &[u32];
    /// Mass-proportional damping α (1/s).
    fn mass_damping(&self) -> f64;
    /// Whether [`ImplicitElements::damping`] gives matrices.
    fn has_damping(&self) -> bool;
    /// Planes the solve holds nodes to.
    fn planes(&self) -> &[ContactPlane];
    /// Decomposes every element at `x` into `prep`; the elastic energy (J).
    fn prepare(&self, x: &[Vec3A], prep: &mut Vec<Self::Prep>) -> f64;
    /// The elastic forces of the prepared elements into `out` (zeroed first); false if
    /// non-finite.
    fn forces(&self, prep: &[Self::Prep], out: &mut [Vec3A]) -> bool;
    /// Element k's stiffness at its prepared state, and whether it is indefinite.
    fn hessian(&self, k: usize, prep: &Self::Prep) -> (Self::Hess, bool);
    /// A matrix with its negative eigenvalues set to zero.
    fn project(h: &Self::Hess) -> Self::Hess;
    /// Element k's damping matrix (N·s/m) from its prepared state at the step's start and
    /// its projected stiffness there; None without damping.
    fn damping(&self, k: usize, prep: &Self::Prep, projected: &Self::Hess) -> Option<Self::Hess>;
    /// out += scale · K_k dx.
    fn apply(&self, k: usize, h: &Self::Hess, dx: &[DVec3], scale: f64, out: &mut [DVec3]);
    /// out += scale · diag(K_k).
    fn add_diagonal(&self, k: usize, h: &Self::Hess, scale: f64, out: &mut [DVec3]);
    /// Whether element k goes into the preconditioner's factor (all by default). Leaving
    /// out weak elements that couple far nodes (a cloth's bending springs) narrows the
    /// factor's envelope; the conjugate gradients still solve with every element.
    fn in_factor(&self, _k: usize) -> bool {
        true
    }
    /// Calls `add(i, j, block)` for element k's node blocks of scale · K_k.
    fn blocks(&self, k: usize, h: &Self::Hess, scale: f64, add: &mut dyn FnMut(u32, u32, DMat3));
    /// Called at the end of a solve with the end state's elements and energy.
    fn finish(&mut self, prep: &[Self::Prep], energy: f64);
}

/// What one implicit substep did.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
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
pub(crate) struct Scratch<E: ImplicitElements> {
    x0: Vec<Vec3A>,
    /// Each node's displacement from `x0` in f64 (the iterate is x0 + disp rounded), so that
    /// the velocity it gives keeps resolution below an f32 position's ulp over h.
    disp: Vec<DVec3>,
    /// The velocity's origin x̂ − x0: zero for backward Euler, ⅓ of the last increment for
    /// BDF2.
    base: Vec<DVec3>,
    y: Vec<Vec3A>,
    trial: Vec<Vec3A>,
    elastic: Vec<Vec3A>,
    g: Vec<DVec3>,
    dx: Vec<DVec3>,
    r: Vec<DVec3>,
    z: Vec<DVec3>,
    p: Vec<DVec3>,
    q: Vec<DVec3>,
    diag: Vec<DVec3>,
    d: Vec<DVec3>,
    kd: Vec<DVec3>,
    /// Each element's stiffness at the current iterate, as is and projected; its damping
    /// matrix (from the step's start).
    raw: Vec<E::Hess>,
    hess: Vec<E::Hess>,
    hess0: Vec<E::Hess>,
    /// Per node, whether it moves (not pinned).
    free: Vec<bool>,
    /// Per node, the normal of a contact holding it (zero for none).
    filter: Vec<DVec3>,
    /// Per node, whether a contact plane holds it at the end of the solve.
    contact: Vec<bool>,
    /// Whether any element is indefinite this iteration, which ones, and whether `hess`
    /// holds this iteration's projections yet.
    indefinite: bool,
    negative: Vec<bool>,
    projected: bool,
    /// The factor's triangular-solve buffer.
    work: Vec<f64>,
    /// The elements prepared at the current iterate and at the line search's trial.
    prep: Vec<E::Prep>,
    prep_trial: Vec<E::Prep>,
}

impl<E: ImplicitElements> Default for Scratch<E> {
    fn default() -> Self {
        Self {
            x0: Vec::new(),
            disp: Vec::new(),
            base: Vec::new(),
            y: Vec::new(),
            trial: Vec::new(),
            elastic: Vec::new(),
            g: Vec::new(),
            dx: Vec::new(),
            r: Vec::new(),
            z: Vec::new(),
            p: Vec::new(),
            q: Vec::new(),
            diag: Vec::new(),
            d: Vec::new(),
            kd: Vec::new(),
            raw: Vec::new(),
            hess: Vec::new(),
            hess0: Vec::new(),
            free: Vec::new(),
            filter: Vec::new(),
            contact: Vec::new(),
            indefinite: false,
            negative: Vec::new(),
            projected: false,
            work: Vec::new(),
            prep: Vec::new(),
            prep_trial: Vec::new(),
        }
    }
}

/// `s.hess` ← the projections of `s.raw` (once per Newton iteration).
fn project_hessians<E: ImplicitElements>(s: &mut Scratch<E>) {
    if s.projected {
        return;
    }
    for k in 0..s.raw.len() {
        s.hess[k] = if s.negative[k] {
            E::project(&s.raw[k])
        } else {
            s.raw[k]
        };
    }
    s.projected = true;
}

/// Builds (once per mesh) the factor's envelope, and asks for a new factor when h changed.
fn prepare_factor<E: ImplicitElements>(
    body: &E,
    settings: &ImplicitEuler,
    state: &mut ImplicitState,
    len: usize,
    h: f32,
) {
    let key = (len, body.count());
    // A factor for another node count (read from a file that says otherwise) is rebuilt too.
    let misfit = state.factor.as_ref().is_some_and(|f| f.nodes() != len);
    if state.built_for != Some(key) || misfit {
        state.built_for = Some(key);
        state.factor = None;
        if settings.max_factor_entries > 0 {
            let mut adjacency = vec![Vec::new(); len];
            for k in (0..body.count()).filter(|&k| body.in_factor(k)) {
                let t = body.nodes(k);
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
fn refresh_factor<'a, E: ImplicitElements>(
    body: &E,
    n: &Nodes,
    s: &Scratch<E>,
    state: &'a mut ImplicitState,
    hess: &[E::Hess],
    free: &[bool],
    hd: f64,
    alpha: f64,
) -> Option<&'a SkylineCholesky> {
    let renew = state.refactor || !state.factor.as_ref()?.is_factored();
    let factor = state.factor.as_mut()?;
    if renew {
        factor.step = hd as f32;
        state.refactor = false;
        state.excess = 0.0;
        let mass_term = |m: f32| f64::from(m) * (1.0 / (hd * hd) + alpha / hd);
        factor.factor(|add| {
            for i in 0..free.len() {
                // A pinned node's row is the identity times a mass-like scale, so the
                // factor stays well conditioned; its unknowns are zero anyway.
                let m = mass_term(n.mass[i]).max(1.0);
                add(i as u32, i as u32, DMat3::from_diagonal(DVec3::splat(m)));
            }
            // Only the blocks between moving nodes: a pinned row keeps its identity.
            let mut free_only = |i: u32, j: u32, b: DMat3| {
                if free[i as usize] && free[j as usize] {
                    add(i, j, b);
                }
            };
            for k in (0..body.count()).filter(|&k| body.in_factor(k)) {
                body.blocks(k, &hess[k], 1.0, &mut free_only);
                if let Some(d) = s.hess0.get(k) {
                    body.blocks(k, d, 1.0 / hd, &mut free_only);
                }
            }
        });
    }
    factor.is_factored().then_some(&*factor)
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

fn d3(v: Vec3A) -> DVec3 {
    Vec3::from(v).as_dvec3()
}

/// The incremental potential E(x) (J) but its elastic part, without the constant terms.
fn potential_rest<E: ImplicitElements>(
    body: &E,
    n: &Nodes,
    s: &mut Scratch<E>,
    x: &[Vec3A],
    h: f64,
    alpha: f64,
) -> f64 {
    let mut e = 0.0f64;
    let inv_h2 = 1.0 / (h * h);
    for i in 0..x.len() {
        if n.inv_mass[i] == 0.0 {
            continue;
        }
        let m = f64::from(n.mass[i]);
        let (xi, yi) = (d3(x[i]), d3(s.y[i]));
        let moved = xi - d3(s.x0[i]) - s.base[i];
        e += 0.5 * m * inv_h2 * (xi - yi).length_squared()
            + 0.5 * alpha * m / h * moved.length_squared()
            - d3(n.f[i]).dot(xi);
    }
    if !s.hess0.is_empty() {
        // ½ (x − x̂)ᵀ D (x − x̂) / h
        for i in 0..x.len() {
            s.d[i] = d3(x[i]) - d3(s.x0[i]) - s.base[i];
            s.kd[i] = DVec3::ZERO;
        }
        let (d, mut kd) = (std::mem::take(&mut s.d), std::mem::take(&mut s.kd));
        for k in 0..body.count() {
            body.apply(k, &s.hess0[k], &d, 1.0, &mut kd);
        }
        e += 0.5 / h * dot(&d, &kd);
        (s.d, s.kd) = (d, kd);
    }
    e
}

/// out += scale · Σ K_k dx.
fn add_stiffness<E: ImplicitElements>(
    body: &E,
    hess: &[E::Hess],
    dx: &[DVec3],
    scale: f64,
    out: &mut [DVec3],
) {
    for (k, h) in hess.iter().enumerate().take(body.count()) {
        body.apply(k, h, dx, scale, out);
    }
}

/// One backward-Euler substep of length `h` for `body`'s nodes. `n.f` holds the step's
/// constant forces (gravity, external, damping), not the elastic ones. Returns None if the
/// state turned non-finite.
pub(crate) fn step<E: ImplicitElements>(
    body: &mut E,
    n: &mut Nodes,
    settings: &ImplicitEuler,
    state: &mut ImplicitState,
    h: f32,
    s: &mut Scratch<E>,
    account: bool,
) -> Option<ImplicitReport> {
    let len = n.x.len();
    // BDF2 with a history from the same step: the backward-Euler potential about
    // x̂ = (4x₀ − x₋₁)/3 with velocity v̂ = (4v₀ − v₋₁)/3 and step ⅔h.
    let bdf2 = settings.scheme == super::ImplicitScheme::Bdf2
        && state.history_h == h
        && state.history.len() == len;
    let h_solve = if bdf2 { h * (2.0 / 3.0) } else { h };
    prepare_factor(body, settings, state, len, h_solve);
    let (alpha, hd) = (body.mass_damping(), f64::from(h_solve));
    let count = body.count();
    for buf in [&mut s.x0, &mut s.y, &mut s.trial, &mut s.elastic] {
        buf.clear();
        buf.resize(len, Vec3A::ZERO);
    }
    for buf in [
        &mut s.disp,
        &mut s.base,
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
    let carried = state.remainder.len() == len;
    for i in 0..len {
        if n.inv_mass[i] == 0.0 {
            // A pinned (or steered) node moves with its velocity over the whole substep.
            s.disp[i] = f64::from(h) * d3(n.v[i]);
            s.y[i] = at(s.x0[i], s.disp[i]);
            continue;
        }
        if carried {
            s.base[i] = state.remainder[i].as_dvec3();
        }
        let v = if bdf2 {
            // The last solve's own increments, not the states: an impulse a contact or an
            // attachment gave a node since is a jump, which the formula would extrapolate
            // as a trend (by 4/3) and so pump energy into every contact.
            let (dx, dv) = state.history[i];
            s.base[i] += dx / 3.0;
            d3(n.v[i]) + dv / 3.0
        } else {
            d3(n.v[i])
        };
        s.disp[i] = s.base[i] + hd * v;
        s.y[i] = at(s.x0[i], s.disp[i]);
    }
    // The inertial predictor is the first iterate; pinned nodes stay there.
    // Contacts found at the end of the last substep: planes n·x ≥ d the nodes may not cross.
    clamp_to_contacts(body.planes(), &mut s.y, &s.x0, &mut s.disp);
    n.x.copy_from_slice(&s.y);
    let mut free = std::mem::take(&mut s.free);
    free.clear();
    free.extend(n.inv_mass.iter().map(|&w| w != 0.0));
    let inv_h2 = 1.0 / (hd * hd);
    let mut report = ImplicitReport::default();
    let (mut g0, mut previous) = (0.0f64, f64::INFINITY);
    let mut clamped = false;
    s.hess.resize(count, E::zero());
    s.raw.resize(count, E::zero());
    s.negative.resize(count, false);
    // The energy at the start (kinetic and elastic), for the numerical damping's account: an
    // element pass more per substep, made only while the energy diagnostics are on.
    let mut energy_before = if account {
        body.prepare(&s.x0, &mut s.prep_trial)
    } else {
        0.0
    };
    for i in (0..len).filter(|_| account) {
        if n.inv_mass[i] != 0.0 {
            energy_before += 0.5 * f64::from(n.mass[i]) * d3(n.v[i]).length_squared();
        }
    }
    let mut elastic_now = body.prepare(&n.x, &mut s.prep);
    for it in 0..settings.max_newton {
        s.indefinite = false;
        for k in 0..count {
            let (raw, negative) = body.hessian(k, &s.prep[k]);
            s.indefinite |= negative;
            s.raw[k] = raw;
            s.negative[k] = negative;
        }
        s.projected = false;
        if it == 0 {
            // The damping matrices D_k at the step's start (positive semi-definite: a
            // Rayleigh term takes the projected stiffness).
            s.hess0.clear();
            if body.has_damping() {
                project_hessians(s);
                for k in 0..count {
                    let d = body.damping(k, &s.prep[k], &s.hess[k]);
                    s.hess0.push(d.unwrap_or_else(E::zero));
                }
            }
        }
        if !body.forces(&s.prep, &mut s.elastic) {
            return None;
        }
        for i in 0..len {
            s.g[i] = if free[i] {
                let m = f64::from(n.mass[i]);
                m * inv_h2 * (d3(n.x[i]) - d3(s.y[i])) - d3(s.elastic[i]) - d3(n.f[i])
                    + alpha * m / hd * (d3(n.x[i]) - d3(s.x0[i]) - s.base[i])
            } else {
                DVec3::ZERO
            };
        }
        if !s.hess0.is_empty() {
            for i in 0..len {
                s.d[i] = d3(n.x[i]) - d3(s.x0[i]) - s.base[i];
                s.kd[i] = DVec3::ZERO;
            }
            let (d, mut kd) = (std::mem::take(&mut s.d), std::mem::take(&mut s.kd));
            add_stiffness(body, &s.hess0, &d, 1.0 / hd, &mut kd);
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
        for c in body.planes() {
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
        // The forces on the nodes at this iterate: external and elastic.
        let mut load = 0.0f64;
        for i in 0..len {
            if free[i] {
                load += (d3(n.f[i]).length() + d3(s.elastic[i]).length()).powi(2);
            }
        }
        let load = load.sqrt();
        if it == 0 {
            // The force scale of the step: the first gradient, or, for a body already at rest
            // (where that is only rounding), the forces on its nodes. Not its momentum over
            // h: at small h that dwarfs the forces, and a tolerance on it would accept the
            // predictor without any elastic force at all.
            g0 = gnorm.max(load);
        }
        // The tolerance is relative to the smaller of that and the forces now: a stiff rod
        // swinging round is predicted far off its length, and its first gradient (k times
        // that) dwarfs the weight and tension the swing runs on; a residual of 1e-3 of it
        // would be a force the size of gravity, and the pendulum would run 1% slow.
        let scale = g0.min(load.max(f64::MIN_POSITIVE));
        report.residual = if g0 > 0.0 { (gnorm / g0) as f32 } else { 0.0 };
        // Converged; or stalled at the floor that f32 positions set (near 1e-4 of the first
        // gradient on a stiff body), where Newton can only shuffle rounding.
        // (Or no progress at all: at rest on a stiff body the rounding floor can lie above
        // 1e-2 of the scale.) A gradient that grew because the last step put nodes back on
        // their contact planes is not a stall: the next Newton step answers the contact.
        let stalled =
            (gnorm > 0.5 * previous && gnorm < 1e-2 * g0) || (gnorm > 0.9 * previous && !clamped);
        if g0 == 0.0 || gnorm <= f64::from(settings.tolerance) * scale || stalled {
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
            let factor = refresh_factor(body, n, s, state, &hess, &free, hd, alpha);
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
                settings,
                &mut report,
            );
            // With a lagged factor, CG on an indefinite H need not meet its negative
            // curvature and can return a direction that climbs E: that is a failure too.
            let ok = ok && dot(&s.g, &s.dx) < 0.0;
            // The lagged factor is kept while the iterations it costs past `refactor_after`
            // add up to less than a new factorisation would.
            let extra = (report.cg_iterations - before).saturating_sub(settings.refactor_after);
            if extra > 0
                && let Some(f) = state.factor.as_ref()
            {
                state.excess += f64::from(extra);
                if state.excess >= f.solves_per_factor() {
                    state.refactor = true;
                }
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
        // extent) is the last one that can change anything: take it whole and stop. A line
        // search there compares energies at their rounding floor and would only backtrack
        // twelve times, each a full element pass.
        let scale = n.x.iter().fold(0.0f32, |m, x| m.max(x.abs().max_element()));
        let resolution = 16.0 * f64::from(f32::EPSILON) * f64::from(scale.max(1e-3));
        let last =
            s.dx.iter()
                .zip(&free)
                .all(|(d, &f)| !f || d.abs().max_element() <= resolution);
        if last {
            for i in 0..len {
                s.disp[i] += s.dx[i];
                n.x[i] = at(s.x0[i], s.disp[i]);
            }
            clamp_to_contacts(body.planes(), &mut n.x, &s.x0, &mut s.disp);
            elastic_now = body.prepare(&n.x, &mut s.prep);
            break;
        }

        // Backtracking line search on E.
        let e_now = elastic_now + potential_rest(body, n, s, &n.x, hd, alpha);
        let slope = dot(&s.g, &s.dx);
        let mut step = 1.0f64;
        let mut accepted = false;
        for _ in 0..12 {
            let mut trial = std::mem::take(&mut s.trial);
            for i in 0..len {
                trial[i] = at(s.x0[i], s.disp[i] + step * s.dx[i]);
            }
            let elastic = body.prepare(&trial, &mut s.prep_trial);
            let e_new = elastic + potential_rest(body, n, s, &trial, hd, alpha);
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
        for i in 0..len {
            s.disp[i] += step * s.dx[i];
        }
        std::mem::swap(&mut s.prep, &mut s.prep_trial);
        let moved = clamp_to_contacts(body.planes(), &mut s.trial, &s.x0, &mut s.disp);
        clamped = moved;
        n.x.copy_from_slice(&s.trial);
        if moved {
            elastic_now = body.prepare(&n.x, &mut s.prep);
        }
    }
    s.contact.clear();
    s.contact.resize(len, false);
    for c in body.planes() {
        let i = c.node as usize;
        s.contact[i] = c.normal.dot(Vec3::from(n.x[i])) <= c.offset + 1e-6;
    }
    // The velocity from the f64 displacement, (x₁ − x̂)/h: an f32 difference of positions
    // would resolve only ulp(x)/h, and a small vibration would stick at its turning points.
    if settings.scheme == super::ImplicitScheme::Bdf2 {
        state.history.resize(len, (DVec3::ZERO, DVec3::ZERO));
        state.history_h = h;
    } else {
        state.history.clear();
        state.history_h = 0.0;
    }
    state.remainder.resize(len, Vec3::ZERO);
    for i in 0..len {
        if !free[i] {
            state.remainder[i] = Vec3::ZERO;
            if let Some(slot) = state.history.get_mut(i) {
                *slot = (DVec3::ZERO, DVec3::ZERO);
            }
            continue;
        }
        let before = if carried {
            state.remainder[i].as_dvec3()
        } else {
            DVec3::ZERO
        };
        // A node held on a contact plane takes backward Euler's velocity, (x₁ − x₀)/h: BDF2's
        // (x₁ − x̂)/⅔h would bounce a node that arrives at the plane back at half its speed.
        let v = if s.contact[i] {
            (s.disp[i] - before) / f64::from(h)
        } else {
            (s.disp[i] - s.base[i]) / hd
        };
        if let Some(slot) = state.history.get_mut(i) {
            *slot = if s.contact[i] {
                (DVec3::ZERO, DVec3::ZERO)
            } else {
                (s.disp[i] - before, v - d3(n.v[i]))
            };
        }
        n.v[i] = Vec3A::from(v.as_vec3());
        let exact = d3(s.x0[i]) + s.disp[i];
        state.remainder[i] = if free[i] {
            (exact - d3(n.x[i])).as_vec3()
        } else {
            Vec3::ZERO
        };
    }
    if account {
        account_numerical_damping(
            body,
            n,
            s,
            state,
            &free,
            (h, alpha),
            energy_before,
            elastic_now,
        );
    } else {
        state.numerical_damping = 0.0;
    }
    s.free = free;
    // Stats at the end state, whose elements the last accepted trial prepared.
    body.finish(&s.prep, elastic_now);
    (elastic_now.is_finite() && n.x.iter().all(|x| x.is_finite())).then_some(report)
}

/// The energy the scheme took this substep beyond the model's damping, into the state's
/// average (see [`super::ImplicitState::numerical_damping`]).
#[allow(clippy::too_many_arguments)] // the solve's end state, passed once per substep
fn account_numerical_damping<E: ImplicitElements>(
    body: &E,
    n: &Nodes,
    s: &mut Scratch<E>,
    state: &mut ImplicitState,
    free: &[bool],
    (h, alpha): (f32, f64),
    energy_before: f64,
    elastic_now: f64,
) {
    let len = n.x.len();
    // What the scheme took: the start's energy and the constant forces' work, less the
    // model's own damping (α M and the elements' D, at the new velocity) and the end's energy.
    let (mut work, mut energy_after, mut damped) = (0.0f64, elastic_now, 0.0f64);
    for i in 0..len {
        s.d[i] = DVec3::ZERO;
        s.kd[i] = DVec3::ZERO;
        if free[i] {
            let m = f64::from(n.mass[i]);
            let v = d3(n.v[i]);
            s.d[i] = v;
            energy_after += 0.5 * m * v.length_squared();
            damped += alpha * m * v.length_squared();
            let moved = d3(n.x[i]) + d3(Vec3A::from(state.remainder[i])) - d3(s.x0[i]);
            work += d3(n.f[i]).dot(moved);
        }
    }
    if !s.hess0.is_empty() {
        let (d, mut kd) = (std::mem::take(&mut s.d), std::mem::take(&mut s.kd));
        add_stiffness(body, &s.hess0, &d, 1.0, &mut kd);
        damped += dot(&d, &kd);
        (s.d, s.kd) = (d, kd);
    }
    let lost = energy_before + work - f64::from(h) * damped - energy_after;
    // Averaged over about a second of simulated time (BDF2's account is not monotone step by
    // step, only over a period).
    let weight = (f64::from(h) / 1.0).min(1.0);
    let rate = lost / f64::from(h);
    if rate.is_finite() {
        let now = f64::from(state.numerical_damping);
        state.numerical_damping = (now + (rate - now) * weight) as f32;
    }
}

/// CG on H dx = −g with the element matrices `hess` (and D from `s.hess0`, K₀'s); false if it met
/// negative curvature.
#[allow(clippy::too_many_arguments)] // the solve's whole state, passed once per Newton step
fn conjugate_gradients<E: ImplicitElements>(
    body: &E,
    n: &Nodes,
    s: &mut Scratch<E>,
    hess: &[E::Hess],
    factor: Option<&SkylineCholesky>,
    free: &[bool],
    hd: f64,
    alpha: f64,
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
        for (k, h) in hess.iter().enumerate() {
            body.add_diagonal(k, h, 1.0, &mut s.diag);
        }
        for (k, d) in s.hess0.iter().enumerate() {
            body.add_diagonal(k, d, 1.0 / hd, &mut s.diag);
        }
    }
    // z = S P⁻¹ S r, S the contact filter (symmetric, so CG still applies).
    let apply = |s: &mut Scratch<E>| {
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
        if !s.hess0.is_empty() {
            let (p, mut q, d) = (
                std::mem::take(&mut s.p),
                std::mem::take(&mut s.q),
                std::mem::take(&mut s.hess0),
            );
            add_stiffness(body, &d, &p, 1.0 / hd, &mut q);
            (s.p, s.q, s.hess0) = (p, q, d);
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

/// x₀ + d, rounded to f32.
fn at(x0: Vec3A, d: DVec3) -> Vec3A {
    Vec3A::from((d3(x0) + d).as_vec3())
}

/// Moves every contact node that crossed its plane back onto it (and its displacement from
/// `x0` with it); whether any moved.
fn clamp_to_contacts(
    contacts: &[ContactPlane],
    x: &mut [Vec3A],
    x0: &[Vec3A],
    disp: &mut [DVec3],
) -> bool {
    let mut moved = false;
    for c in contacts {
        let i = c.node as usize;
        let gap = c.normal.dot(Vec3::from(x[i])) - c.offset;
        if gap < 0.0 {
            x[i] -= Vec3A::from(gap * c.normal);
            disp[i] = d3(x[i]) - d3(x0[i]);
            moved = true;
        }
    }
    moved
}
