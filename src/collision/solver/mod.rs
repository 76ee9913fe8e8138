//! The soft-step contact solver (after Box2D v3, extended to 3D friction), four manifolds
//! at a time.
//!
//! Per contact point, with normal n from a to b, lever arms r_a, r_b from the centres of
//! mass and relative normal velocity v_n:
//!
//! ```text
//! m_n = 1 / (1/m_a + 1/m_b + n·(I_a⁻¹(r_a×n))×r_a + n·(I_b⁻¹(r_b×n))×r_b)
//! s > 0 (speculative):  λ = −m_n (v_n + s/h)
//! s ≤ 0, with bias:     λ = −m_n·S_m (v_n + max(β s, −v_push)) − S_i λ_acc
//! ```
//!
//! with the soft-constraint coefficients of a spring of frequency f and damping ratio ζ,
//! ω = 2πf: a₁ = 2ζ + hω, a₂ = hω a₁, β = ω/a₁, S_m = a₂/(1 + a₂), S_i = 1/(1 + a₂). The
//! accumulated normal impulse stays ≥ 0; friction clamps the tangent impulse vector to
//! μ λ_n.
//!
//! **Batches.** The manifolds are coloured so that no dynamic body appears twice in a colour
//! (static and kinematic bodies take no impulse, so they may), and each colour is cut into
//! batches of four that are solved together in SIMD lanes: the four manifolds of a batch
//! touch four different bodies on each side, so solving them at once gives exactly what
//! solving them one after another would. Manifolds that find no colour are solved one per
//! batch, after the colours. The order is fixed by the order of the manifolds, so results
//! are bit-identical from run to run.

mod colour;
pub(crate) mod exchange;
pub(crate) mod plugin;
pub(crate) mod prepare;
mod turning;
pub(crate) mod whole_step;

use bevy_ecs::prelude::*;
use glam::{Mat3A, Quat, Vec3A};

use crate::collision::lanes::{F4, M3, Q4, V3};

/// Index of the immovable "body" that stands for every static collider.
pub(crate) const FIXED: u32 = u32::MAX;

/// Colours tried before a manifold goes to the one-per-batch overflow.
const COLOURS: usize = 12;

/// What a body brings to the step's contacts: set once per step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolverBody {
    pub entity: Entity,
    /// Zero for kinematic bodies: they drive contacts but are never pushed.
    pub inv_mass: f32,
    /// World inverse inertia the contact axes were last formed with (zero for kinematic
    /// bodies): at the start of the step, then at the rotation `q_axes`.
    pub inv_i: Mat3A,
    /// World inertia matching `inv_i` (zero for kinematic bodies and particles): an impulse
    /// pass's change of ω times it is the angular impulse it gave.
    pub i0: Mat3A,
    /// World inverse inertia and inertia at the start of the step.
    pub inv_i_start: Mat3A,
    pub i_start: Mat3A,
    /// The rotation at which `inv_i` was formed.
    pub q_axes: Quat,
    /// Centre of mass and rotation at the start of the step.
    pub x0: Vec3A,
    pub q0: Quat,
    /// The rotation at which the state's ΔR was last formed.
    pub q_seen: Quat,
    /// How close (squared quaternion distance) a rotation must be to `q_seen` to reuse
    /// that ΔR (see `exchange::same_turn`).
    pub same_turn: f32,
    /// Angular velocity when the current pass began: the pass's change of ω, times the
    /// inertia, is the angular impulse it applied.
    pub w_in: Vec3A,
    /// False for kinematic bodies and for bodies frozen out of the step.
    pub dynamic: bool,
    /// Three equal principal moments: I⁻¹ is `inv_i`'s diagonal in every orientation.
    pub isotropic: bool,
    /// It overlaps something deeply this step (see [`ContactSolver::limit_deep_speed`]).
    pub deep: bool,
    /// Speed entering the current substep's contact passes (m/s).
    pub speed_in: f32,
}

#[cfg(test)]
impl SolverBody {
    /// A dynamic body at the origin, unturned, for tests.
    pub fn at_origin(entity: Entity, inv_mass: f32, inv_i: Mat3A) -> Self {
        Self {
            entity,
            inv_mass,
            inv_i,
            i0: inv_i,
            inv_i_start: inv_i,
            i_start: inv_i,
            q_axes: Quat::IDENTITY,
            x0: Vec3A::ZERO,
            q0: Quat::IDENTITY,
            q_seen: Quat::IDENTITY,
            same_turn: crate::collision::solver::exchange::ROUNDING_TURN,
            w_in: Vec3A::ZERO,
            dynamic: true,
            isotropic: false,
            deep: false,
            speed_in: 0.0,
        }
    }
}

/// The velocity state of one body during a pass: one cache line. (With ΔR as a matrix it
/// took 96 bytes, and most bodies two lines; the passes load it for every contact.)
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct BodyState {
    pub v: Vec3A,
    pub w: Vec3A,
    /// Displacement and rotation since the start of the step.
    pub dx: Vec3A,
    pub dq: Quat,
}

const _: () = assert!(size_of::<BodyState>() == 64);

impl BodyState {
    /// A body that does not move: every static collider reads this.
    pub const REST: Self = Self {
        v: Vec3A::ZERO,
        w: Vec3A::ZERO,
        dx: Vec3A::ZERO,
        dq: Quat::IDENTITY,
    };
}

/// One manifold as the narrow phase gave it; its points are `first..first + count` of
/// [`ContactSolver::inputs`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct ManifoldConstraint {
    pub a: u32,
    pub b: u32,
    pub n: Vec3A,
    pub t: [Vec3A; 2],
    pub friction: f32,
    pub restitution: f32,
    /// Approach speed below which this manifold does not bounce (m/s).
    pub threshold: f32,
    pub first: u32,
    pub count: u32,
    /// The pair's slot in the pair table, where its impulses are written back.
    pub pair: u32,
    pub manifold: u32,
    /// Lever arms from each centre of mass to the manifold's centre, where friction acts.
    pub centre_a: Vec3A,
    pub centre_b: Vec3A,
    /// Mean distance of the points from the centre (m): the twist friction's arm.
    pub radius: f32,
    /// Warm-start friction impulses: along the two tangents, and the twist about n.
    pub t_imp: [f32; 2],
    pub twist: f32,
    /// The relative tangential velocity friction drives the manifold to, along each
    /// tangent (m/s; zero but for a conveyor's surface, see [`crate::collision::ContactEdit`]).
    pub surface: [f32; 2],
    /// The sides that take no impulse from this manifold for [`crate::rigid::Dominance`]:
    /// bit 0 `a`, bit 1 `b`.
    pub held: u8,
}

/// One contact point as the narrow phase gave it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PointInput {
    pub r_a: Vec3A,
    pub r_b: Vec3A,
    /// Separation minus n·(r_b − r_a) at the start: the current separation is
    /// n·(Δx_b + ΔR_b r_b − Δx_a − ΔR_a r_a) + base.
    pub base: f32,
    /// Warm-start normal impulse.
    pub n_imp: f32,
    /// Relative normal velocity at the start of the step (negative when approaching).
    pub approach: f32,
    /// Index of the point in the narrow phase's manifold (where its impulses are kept).
    pub source: u32,
}

/// One direction (normal or tangent) of four contact points, with what the solver needs
/// precomputed: the angular velocity change per unit impulse I⁻¹(r × d) of each side, and
/// the effective mass.
#[derive(Debug, Clone, Copy, Default)]
struct Axis {
    ird_a: V3,
    ird_b: V3,
    mass: F4,
}

impl Axis {
    /// `live` is all-ones for lanes that hold a point, zero for padding (mass 0: no impulse).
    #[inline]
    #[allow(clippy::too_many_arguments)] // the two sides of one formula
    fn new(ma: F4, ia: &M3, ra: V3, mb: F4, ib: &M3, rb: V3, d: V3, live: F4) -> Self {
        let (rd_a, rd_b) = (ra.cross(d), rb.cross(d));
        let (ird_a, ird_b) = (ia.mul_vec(rd_a), ib.mul_vec(rd_b));
        let k = ma + mb + rd_a.dot(ird_a) + rd_b.dot(ird_b);
        let usable = k.simd_gt(F4::ZERO) & live;
        Self {
            ird_a,
            ird_b,
            mass: usable.select(F4::ONE / k, F4::ZERO),
        }
    }
}

/// Four contact points, the k-th of each manifold of a batch: what every pass reads.
///
/// The restitution's record of the same points is kept apart, in a [`Track`]: a pass over
/// a batch that does not bounce never reads it, and with it inline a point took six cache
/// lines instead of four. The 50-row pyramid's points (about 635 batches of up to four, up
/// to 1 MB) then outgrew a 2 MB L2 along with the rest of the step, and its step ran 9 %
/// slower than rapier's on the wall clock with 0.8 % more instructions.
#[derive(Debug, Clone, Copy, Default)]
struct Point {
    r_a: V3,
    r_b: V3,
    base: F4,
    normal: Axis,
    n_imp: F4,
}

/// The restitution's record of a [`Point`]'s four lanes (kept only in bouncy batches, see
/// [`Batch::bouncy`]).
#[derive(Debug, Clone, Copy, Default)]
struct Track {
    /// Largest normal impulse of one pass this step (zero: the point never pushed).
    max_n: F4,
    /// Relative normal velocity at the start of the step, then the speed of impact once the
    /// contact first pushes.
    approach: F4,
    /// Normal velocity seen by the last two biased passes (one substep apart): their
    /// difference is the approach acceleration, used to extrapolate the speed of impact.
    vn_seen: [F4; 2],
    /// The normal impulse the point gave over this step's substeps (each substep's total,
    /// warm start included): the compression impulse that bounds its restitution.
    absorbed: F4,
    /// Kinetic energy its normal impulses took out of the two bodies this step (J; negative
    /// for energy they put in): what its restitution may give back.
    lost: F4,
    /// Half the inverse of the normal's effective mass (zero on padding lanes).
    half_w: F4,
    /// The relative normal velocity the last pass left (for the next warm start's work).
    vn_end: F4,
    /// What extrapolating the impact speed at the point's first push added to the square of
    /// its normal velocity (m²/s²): the restitution's budget credits this much kinetic
    /// energy, and nothing for a start-of-step `approach` faster than the first push (other
    /// contacts' impulses slowed the pair in between, and their work is already counted).
    gain: F4,
}

/// The kinetic energy an impulse λ along a point's normal adds to its two bodies, with vn
/// their relative normal velocity before it: λ (vn + λ / 2m), m the point's effective mass
/// (`half_w` = 1 / 2m).
#[inline]
fn work(lambda: F4, vn: F4, half_w: F4) -> F4 {
    lambda * (vn + lambda * half_w)
}

/// Up to four manifolds with no dynamic body in common, solved together.
#[derive(Debug, Clone, Copy)]
struct Batch {
    /// Manifold per lane (`u32::MAX` for an empty lane).
    lanes: [u32; 4],
    /// Body state indices per lane; the rest state for static sides and empty lanes.
    a: [u32; 4],
    b: [u32; 4],
    /// Points `first..first + count` of [`ContactSolver::points`].
    first: u32,
    count: u32,
    /// Its points' restitution records start at this index of [`ContactSolver::tracks`];
    /// [`Batch::UNTRACKED`] for a batch that does not bounce, which keeps none.
    tracked: u32,
    n: V3,
    t: [V3; 2],
    inv_m_a: F4,
    inv_m_b: F4,
    friction: F4,
    restitution: F4,
    /// Minus the restitution threshold (m/s): an approach (negative) below it, faster than
    /// the threshold, bounces.
    threshold: F4,
    /// All-ones in lanes where one side is static: they use the stiffer static softness.
    fixed: F4,
    /// Its lanes' [`ManifoldConstraint::held`] sides, two bits per lane (lane l at bit 2l).
    held: u8,
}

impl Batch {
    /// [`Batch::tracked`] of a batch without restitution records.
    const UNTRACKED: u32 = u32::MAX;

    /// Where its points' restitution records are in [`ContactSolver::tracks`] (empty for a
    /// batch that does not bounce).
    #[inline]
    fn tracks(&self) -> std::ops::Range<usize> {
        match self.tracked {
            Self::UNTRACKED => 0..0,
            t => t as usize..(t + self.count) as usize,
        }
    }

    /// Some lane bounces (restitution > 0; empty lanes hold 0): only then do the passes
    /// keep the record the restitution reads (impact speeds, the energy the impulses took
    /// out). A batch without restitution gives it nothing either way, so skipping it
    /// changes no result.
    #[inline]
    fn bouncy(&self) -> bool {
        self.restitution.simd_gt(F4::ZERO).any()
    }
}

/// The step's contact constraints and the bodies they touch.
#[derive(Resource, Default)]
pub(crate) struct ContactSolver {
    pub bodies: Vec<SolverBody>,
    /// Per body, then one [`BodyState::REST`] for every static side and empty lane.
    pub states: Vec<BodyState>,
    pub manifolds: Vec<ManifoldConstraint>,
    pub inputs: Vec<PointInput>,
    pub index: BodyMap,
    /// Where the bodies sit in the ECS storage order (see [`crate::collision::solver::exchange`]).
    pub order: crate::collision::solver::exchange::StorageOrder,
    batches: Vec<Batch>,
    points: Vec<Point>,
    /// Per point of a bouncy batch, its restitution record (see [`Batch::tracked`]).
    tracks: Vec<Track>,
    /// Per batch: its manifolds' friction.
    friction: Vec<friction::Friction>,
    /// Some body overlaps something deeply this step (see [`Self::solve_grounded`]).
    any_deep: bool,
    /// Passes visit only the batches with a static or kinematic side.
    grounded_only: bool,
    /// Colouring scratch, kept to reuse its memory.
    colours: Vec<Vec<u32>>,
    used: Vec<u32>,
    /// Bodies whose inertia a gather turned (see [`Self::after_gather`]), and a per-body
    /// mark for the batch scan.
    pub turned: Vec<u32>,
    turned_mark: Vec<bool>,
    /// Per manifold, its impulses at the end of the step (see [`write_back`]).
    solved: Vec<write_back::Solved>,
    /// Some collider asks for [`crate::collision::ContactReport`]s: the substeps add up
    /// each manifold's impulses into `totals`.
    pub reporting: bool,
    totals: Vec<write_back::Solved>,
    /// Some manifold of the step has a side held for dominance or a surface velocity: only
    /// then are those read into the batches.
    pub edited: bool,
}

/// Solver index per entity.
#[derive(Debug, Default)]
pub(crate) struct BodyMap(crate::collision::slots::EntitySlots);

impl BodyMap {
    /// The solver index of `e`, if it has one this step.
    #[inline]
    pub fn get(&self, e: Entity, bodies: &[SolverBody]) -> Option<u32> {
        self.0.find(e, |i| bodies.get(i).map(|b| b.entity))
    }

    pub fn insert(&mut self, e: Entity, i: u32) {
        self.0.insert(e, i);
    }

    /// Empties the map of the step's `bodies`.
    fn clear(&mut self, bodies: &[SolverBody]) {
        self.0.clear(bodies.iter().map(|b| b.entity));
    }
}

/// The soft-constraint coefficients for frequency `hertz`, damping ratio `zeta` and step `h`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Softness {
    pub bias_rate: f32,
    pub mass_scale: f32,
    pub impulse_scale: f32,
}

impl Softness {
    #[must_use]
    pub fn new(hertz: f32, zeta: f32, h: f32) -> Self {
        if hertz <= 0.0 {
            return Self {
                bias_rate: 0.0,
                mass_scale: 1.0,
                impulse_scale: 0.0,
            };
        }
        let omega = std::f32::consts::TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// The normal velocity of impact for a contact's first push. A speculative contact (gap
/// `s` > 0 still open) stops the body up to a substep before it would have arrived, while
/// it was still accelerating: with the approach acceleration a measured between the last two
/// biased passes (one substep apart), the speed it would have hit with is √(vn² + 2|a|s).
/// Restitution bounces from that speed (without it a ball dropped 1 m with e = 0.8 rose
/// 0.617 m instead of 0.64 at 4 substeps).
#[inline]
fn impact_speed(vn: F4, s: F4, seen: [F4; 2], inv_h: F4) -> F4 {
    let a = (seen[1] - seen[0]) * inv_h;
    // A NaN (no second pass yet) fails every comparison, so it never extrapolates.
    let extrapolate = s.simd_gt(F4::ZERO)
        & vn.simd_lt(F4::ZERO)
        & a.simd_lt(F4::ZERO)
        & a.simd_gt(F4::splat(f32::MIN));
    extrapolate.select(-(vn * vn - (a + a) * s).sqrt(), vn)
}

/// One side of four manifolds during a pass.
#[derive(Clone, Copy)]
struct Side {
    v: V3,
    w: V3,
    inv_m: F4,
}

impl Side {
    /// Velocity of b's material point against a's at the contact points (lever arms `r_a`,
    /// `r_b`). Its component along a direction d equals d·(v_b − v_a) + ω_b·(r_b × d) −
    /// ω_a·(r_a × d), so the lever products need not be stored.
    #[inline]
    fn relative(a: &Side, b: &Side, r_a: V3, r_b: V3) -> V3 {
        (b.v + b.w.cross(r_b)) - (a.v + a.w.cross(r_a))
    }

    /// Applies impulse λ along `d`: −λ to a, +λ to b.
    #[inline]
    fn push(a: &mut Side, b: &mut Side, d: V3, axis: &Axis, lambda: F4) {
        a.v -= (a.inv_m * lambda) * d;
        a.w -= lambda * axis.ird_a;
        b.v += (b.inv_m * lambda) * d;
        b.w += lambda * axis.ird_b;
    }
}

/// What a pass knows of one batch before it visits its points.
struct Pass {
    n: V3,
    /// n·(Δx_b − Δx_a), and ΔRᵀn of each side: the separation's change is then two dot
    /// products per point (n·(ΔR r) = (ΔRᵀn)·r).
    shift: F4,
    turn_a: V3,
    turn_b: V3,
    inv_h: F4,
    bias_rate: F4,
    mass_scale: F4,
    impulse_scale: F4,
    /// Minus the push-out speed limit (m/s).
    max_push: F4,
}

impl Pass {
    /// One point's normal impulse (see [`ContactSolver::solve`]); `TRACK` keeps the record
    /// the restitution reads in `t`.
    #[inline(always)]
    fn point<const BIAS: bool, const TRACK: bool>(
        &self,
        p: &mut Point,
        t: &mut Track,
        a: &mut Side,
        b: &mut Side,
    ) {
        let zero = F4::ZERO;
        let s = (self.shift + (self.turn_b.dot(p.r_b) - self.turn_a.dot(p.r_a))) + p.base;
        let speculative = s.simd_gt(zero);
        let bias = speculative.select(s * self.inv_h, (self.bias_rate * s).fast_max(self.max_push));
        let m_scale = speculative.select(F4::ONE, self.mass_scale);
        let i_scale = speculative.select(zero, self.impulse_scale);
        let vn = self.n.dot(Side::relative(a, b, p.r_a, p.r_b));
        if BIAS && TRACK {
            t.vn_seen = [t.vn_seen[1], vn];
        }
        let imp = -p.normal.mass * m_scale * (vn + bias) - i_scale * p.n_imp;
        let total = (p.n_imp + imp).fast_max(zero);
        let imp = total - p.n_imp;
        if TRACK {
            let first = t.max_n.simd_eq(zero) & imp.simd_gt(zero);
            if first.any() {
                let hit = impact_speed(vn, s, t.vn_seen, self.inv_h);
                t.approach = first.select(t.approach.fast_min(hit), t.approach);
                t.gain = first.select(hit * hit - vn * vn, t.gain);
            }
            t.max_n = t.max_n.fast_max(imp);
            t.lost -= work(imp, vn, t.half_w);
            if !BIAS {
                // The relax pass is each substep's last: n_imp is that substep's impulse.
                t.vn_end = vn + F4::splat(2.0) * imp * t.half_w;
                t.absorbed += total;
            }
        }
        p.n_imp = total;
        Side::push(a, b, self.n, &p.normal, imp);
    }
}

impl ContactSolver {
    /// Empties the solver for a new step.
    pub fn clear(&mut self) {
        self.index.clear(&self.bodies);
        self.bodies.clear();
        self.states.clear();
        self.manifolds.clear();
        self.inputs.clear();
        self.order.reset();
        self.batches.clear();
        self.points.clear();
        self.tracks.clear();
        self.friction.clear();
        self.turned.clear();
        self.totals.clear();
        self.edited = false;
    }

    /// Index of the rest state (static sides, empty lanes).
    #[inline]
    fn rest(&self) -> u32 {
        self.bodies.len() as u32
    }

    /// The effective masses and lever terms of every point of batch `bi`, from its bodies'
    /// current inverse masses and inertias.
    fn compute_axes(&mut self, bi: usize) {
        const ZERO: Mat3A = Mat3A::ZERO;
        let batch = self.batches[bi];
        let body = |i: u32| self.bodies.get(i as usize);
        let inv_m = |ix: [u32; 4]| F4::new(ix.map(|i| body(i).map_or(0.0, |b| b.inv_mass)));
        let inv_i = |ix: [u32; 4]| M3::from_lanes(ix.map(|i| body(i).map_or(&ZERO, |b| &b.inv_i)));
        // A side held for dominance reads as immovable, like a kinematic body: its lanes
        // point at the rest state's index, which has no solver body.
        let (a, b) = match batch.held {
            0 => (batch.a, batch.b),
            held => {
                let rest = self.rest();
                let keep = |ix: [u32; 4], bit: u8| {
                    std::array::from_fn(|l| match held >> (2 * l) & bit {
                        0 => ix[l],
                        _ => rest,
                    })
                };
                (keep(batch.a, 1), keep(batch.b, 2))
            }
        };
        let (ma, mb, ia, ib) = (inv_m(a), inv_m(b), inv_i(a), inv_i(b));
        let counts = batch
            .lanes
            .map(|mi| self.manifolds.get(mi as usize).map_or(0, |m| m.count));
        let range = batch.first as usize..(batch.first + batch.count) as usize;
        let points = &mut self.points[range];
        let tracks = &mut self.tracks[batch.tracks()];
        for (k, p) in points.iter_mut().enumerate() {
            let live = F4::new(counts.map(|c| {
                if (k as u32) < c {
                    f32::from_bits(!0)
                } else {
                    0.0
                }
            }));
            p.normal = Axis::new(ma, &ia, p.r_a, mb, &ib, p.r_b, batch.n, live);
            if let Some(t) = tracks.get_mut(k) {
                t.half_w = p
                    .normal
                    .mass
                    .simd_gt(F4::ZERO)
                    .select(F4::splat(0.5) / p.normal.mass, F4::ZERO);
            }
        }
        let lanes = F4::new(counts.map(|c| if c > 0 { f32::from_bits(!0) } else { 0.0 }));
        self.friction[bi].compute(&batch, (ma, &ia), (mb, &ib), lanes);
        let batch = &mut self.batches[bi];
        (batch.inv_m_a, batch.inv_m_b) = (ma, mb);
    }

    /// Takes `body` out of the rest of the step: it turned non-finite, and from now on every
    /// contact sees it as an immovable, motionless obstacle.
    pub fn freeze(&mut self, body: u32) {
        let rest = self.rest();
        if let Some(b) = self.bodies.get_mut(body as usize) {
            b.dynamic = false;
        }
        for bi in 0..self.batches.len() {
            let batch = &mut self.batches[bi];
            let mut touched = false;
            for i in batch.a.iter_mut().chain(batch.b.iter_mut()) {
                if *i == body {
                    *i = rest;
                    touched = true;
                }
            }
            if touched {
                self.compute_axes(bi);
            }
        }
    }

    #[inline]
    fn load(states: &[BodyState], ix: [u32; 4], inv_m: F4) -> Side {
        let s = ix.map(|i| &states[i as usize]);
        Side {
            v: V3::from_lanes(s.map(|s| s.v)),
            w: V3::from_lanes(s.map(|s| s.w)),
            inv_m,
        }
    }

    /// Writes a side back. Lanes of static sides and empty lanes write into the rest state:
    /// call [`Self::settle_rest`] after the batch's stores (a store per lane and one reset
    /// is cheaper than a branch per lane).
    #[inline]
    fn store(states: &mut [BodyState], ix: [u32; 4], side: &Side) {
        let (v, w) = (side.v.lanes(), side.w.lanes());
        for l in 0..4 {
            if let Some(s) = states.get_mut(ix[l] as usize) {
                s.v = v[l];
                s.w = w[l];
            }
        }
    }

    /// Puts the rest state (`rest`) back at rest after a batch's stores.
    #[inline]
    fn settle_rest(states: &mut [BodyState], rest: u32) {
        if let Some(s) = states.get_mut(rest as usize) {
            s.v = Vec3A::ZERO;
            s.w = Vec3A::ZERO;
        }
    }

    /// Δx and ΔR of both sides, for the current separations.
    #[inline]
    fn motion(states: &[BodyState], ix: [u32; 4]) -> (V3, Q4) {
        let s = ix.map(|i| &states[i as usize]);
        (
            V3::from_lanes(s.map(|s| s.dx)),
            Q4::from_lanes(s.map(|s| s.dq)),
        )
    }

    /// Runs `f` on every batch with both sides loaded, then stores the sides back. Borrows
    /// field by field: a batch is a few hundred bytes, and copying it out of `self` for
    /// each pass cost a memcpy call per batch.
    #[inline(always)]
    fn for_each_batch(
        &mut self,
        mut f: impl FnMut(
            &Batch,
            &mut friction::Friction,
            (&mut [Point], &mut [Track]),
            &[BodyState],
            &mut [Side; 2],
        ),
    ) {
        let rest = self.rest();
        let Self {
            batches,
            points,
            tracks,
            states,
            friction,
            grounded_only,
            ..
        } = self;
        for (batch, friction) in batches.iter().zip(friction.iter_mut()) {
            if *grounded_only && !batch.fixed.any() {
                continue;
            }
            let mut sides = [
                Self::load(states, batch.a, batch.inv_m_a),
                Self::load(states, batch.b, batch.inv_m_b),
            ];
            let range = batch.first as usize..(batch.first + batch.count) as usize;
            let points = (&mut points[range], &mut tracks[batch.tracks()]);
            f(batch, friction, points, states, &mut sides);
            Self::store(states, batch.a, &sides[0]);
            Self::store(states, batch.b, &sides[1]);
            Self::settle_rest(states, rest);
        }
    }

    /// Applies every accumulated impulse once (warm start).
    pub fn warm_start(&mut self) {
        self.for_each_batch(|batch, friction, (points, tracks), _, [a, b]| {
            if batch.bouncy() {
                // The work at the present relative velocity, point by point as the impulses
                // land: the velocity the last pass left is stale by every impulse other
                // contacts gave the two bodies after it (in a row of touching balls, most of
                // the row's), and a budget credited from it let restitution create energy
                // in some spawn orders.
                for (p, t) in points.iter().zip(tracks.iter_mut()) {
                    let vn = batch.n.dot(Side::relative(a, b, p.r_a, p.r_b));
                    t.lost -= work(p.n_imp, vn, t.half_w);
                    Side::push(a, b, batch.n, &p.normal, p.n_imp);
                }
            } else {
                for p in points.iter() {
                    Side::push(a, b, batch.n, &p.normal, p.n_imp);
                }
            }
            friction.warm_start(batch, a, b);
        });
    }

    /// One pass over every contact: normal impulses, with the soft bias when `use_bias`;
    /// friction (one per manifold, see the `friction` module) only in the relax pass
    /// (without bias), after the normals, so that its limit is the full normal impulse and it
    /// never reacts to push-out velocities. The warm start carries last pass's friction into
    /// the biased pass, which keeps resting bodies from creeping (measured: 0.25 mm in 2 s on
    /// a 30° slope at μ = 0.6). Friction in the biased
    /// pass as well (rapier also leaves it out) cost a fifth of the pass and left a heavy box
    /// on a light one jittering at 8 mm/s instead of 1 mm/s.
    ///
    /// The relax pass takes each manifold's points in reverse order (a symmetric
    /// Gauss–Seidel sweep): in one order every pass, the first corners solved took more of a
    /// landing's impulse, and a cube dropped flat walked 1.5 mm sideways (0.4 mm now).
    pub fn solve(
        &mut self,
        h: f32,
        soft: Softness,
        fixed_soft: Softness,
        use_bias: bool,
        max_push: f32,
    ) {
        // One copy of the pass per kind, so that neither tests the kind per point.
        if use_bias {
            self.solve_pass::<true>(h, soft, fixed_soft, max_push);
        } else {
            self.solve_pass::<false>(h, soft, fixed_soft, max_push);
        }
    }

    fn solve_pass<const BIAS: bool>(
        &mut self,
        h: f32,
        soft: Softness,
        fixed_soft: Softness,
        max_push: f32,
    ) {
        let inv_h = F4::splat(1.0 / h);
        let max_push = F4::splat(-max_push);
        let (zero, one) = (F4::ZERO, F4::ONE);
        self.for_each_batch(|batch, friction, (points, tracks), states, [a, b]| {
            let (dx_a, dq_a) = Self::motion(states, batch.a);
            let (dx_b, dq_b) = Self::motion(states, batch.b);
            let pick = |f: fn(&Softness) -> f32| {
                batch
                    .fixed
                    .select(F4::splat(f(&fixed_soft)), F4::splat(f(&soft)))
            };
            let (bias_rate, mass_scale, impulse_scale) = if BIAS {
                (
                    pick(|s| s.bias_rate),
                    pick(|s| s.mass_scale),
                    pick(|s| s.impulse_scale),
                )
            } else {
                (zero, one, zero)
            };
            // n·(ΔR r) = (ΔRᵀ n)·r: one quaternion turn per side per batch, not per point.
            let (turn_a, turn_b) = (dq_a.inverse_rotate(batch.n), dq_b.inverse_rotate(batch.n));
            let pass = Pass {
                n: batch.n,
                shift: batch.n.dot(dx_b - dx_a),
                turn_a,
                turn_b,
                inv_h,
                bias_rate,
                mass_scale,
                impulse_scale,
                max_push,
            };
            if batch.bouncy() {
                let mut visit = |(p, t): (&mut Point, &mut Track)| {
                    pass.point::<BIAS, true>(p, t, a, b);
                };
                let pairs = points.iter_mut().zip(tracks.iter_mut());
                match BIAS {
                    true => pairs.for_each(&mut visit),
                    false => pairs.rev().for_each(&mut visit),
                }
            } else {
                // A batch that does not bounce keeps no record: this one is not read.
                let mut unread = Track::default();
                let mut visit = |p: &mut Point| pass.point::<BIAS, false>(p, &mut unread, a, b);
                match BIAS {
                    true => points.iter_mut().for_each(&mut visit),
                    false => points.iter_mut().rev().for_each(&mut visit),
                }
            }
            if !BIAS {
                let normal = points.iter().fold(F4::ZERO, |s, p| s + p.n_imp);
                friction.solve(batch, normal, a, b);
            }
        });
    }
}

mod friction;
mod limits;
mod restitution;
mod write_back;

#[cfg(test)]
mod tests;
