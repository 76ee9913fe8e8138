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
mod passes;
pub(crate) mod plugin;
pub(crate) mod prepare;
mod side;
mod turning;
pub(crate) mod whole_step;

use bevy_ecs::prelude::*;
use glam::{Mat3A, Quat, Vec3A};

use crate::collision::lanes::{F4, M3, Q4, V3};
use side::LinearMass;

/// Index of the immovable "body" that stands for every static collider.
pub(crate) const FIXED: u32 = u32::MAX;

/// The share of an unlocked body's response below which a contact direction counts as
/// vacuous for bodies with [`crate::rigid::LockedAxes`] (see [`Axis::new`]): a normal
/// within about 6° of a locked axis.
const VACUOUS: f32 = 0.01;

/// Colours tried before a manifold goes to the one-per-batch overflow.
const COLOURS: usize = 12;

/// What a body brings to the step's contacts: set once per step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolverBody {
    pub entity: Entity,
    /// Zero for kinematic bodies: they drive contacts but are never pushed.
    pub inv_mass: f32,
    /// The world axes its translation is locked along (bits 0–2, see
    /// [`crate::rigid::LockedAxes`]): zero inverse mass along them.
    pub translation_locks: u8,
    /// Its [`crate::rigid::Inertia`] in [`ContactSolver::locked_inertias`] when a rotation is
    /// locked ([`Self::UNLOCKED`] otherwise): ω = (P I P)⁺ L is formed from it again as it
    /// turns.
    pub locked_inertia: u32,
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

impl SolverBody {
    /// [`Self::locked_inertia`] of a body with no locked rotation.
    pub const UNLOCKED: u32 = u32::MAX;

    /// Its inverse mass per world axis.
    #[must_use]
    pub fn inverse_mass(&self) -> Vec3A {
        crate::rigid::translation_mask(self.translation_locks) * self.inv_mass
    }
}

#[cfg(test)]
impl SolverBody {
    /// A dynamic body at the origin, unturned, for tests.
    pub fn at_origin(entity: Entity, inv_mass: f32, inv_i: Mat3A) -> Self {
        Self {
            entity,
            inv_mass,
            translation_locks: 0,
            locked_inertia: Self::UNLOCKED,
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
    fn new<M: LinearMass>(ma: M, ia: &M3, ra: V3, mb: M, ib: &M3, rb: V3, d: V3, live: F4) -> Self {
        let (rd_a, rd_b) = (ra.cross(d), rb.cross(d));
        let (ird_a, ird_b) = (ia.mul_vec(rd_a), ib.mul_vec(rd_b));
        let k = ma.along(d) + mb.along(d) + rd_a.dot(ird_a) + rd_b.dot(ird_b);
        let floor = if M::LOCKS {
            // A direction within a few degrees of one that locks hold both sides along: an
            // impulse could move it only sideways, by the inverse of that small share (two
            // bodies locked in neighbouring planes that overlap in depth were flung at
            // thousands of m/s). It is left unsolved, as an exactly locked one is.
            F4::splat(VACUOUS) * (ma.largest() + mb.largest())
        } else {
            F4::ZERO
        };
        let usable = k.simd_gt(floor) & live;
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
    /// Its sides' per-axis inverse masses are at this index of
    /// [`ContactSolver::lock_masses`] when some lane's body has a locked translation;
    /// [`Batch::UNLOCKED`] otherwise (the scalar `inv_m_a`, `inv_m_b` then hold).
    locked: u32,
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

    /// [`Batch::locked`] of a batch whose bodies lock no translation.
    const UNLOCKED: u32 = u32::MAX;

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
    /// Per batch with a locked translation (see [`Batch::locked`]), its sides' inverse
    /// masses per axis.
    lock_masses: Vec<[V3; 2]>,
    /// The inertias of the bodies with a locked rotation (see [`SolverBody::locked_inertia`]).
    pub locked_inertias: Vec<crate::rigid::Inertia>,
    /// Some body of the step has a locked translation.
    pub translation_locks: bool,
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
        self.lock_masses.clear();
        self.locked_inertias.clear();
        self.translation_locks = false;
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
        let (ia, ib) = (inv_i(a), inv_i(b));
        let locked = self.translation_locks
            && (a.iter().chain(&b)).any(|&i| body(i).is_some_and(|b| b.translation_locks != 0));
        if locked {
            let inv_m = |ix: [u32; 4]| {
                V3::from_lanes(ix.map(|i| body(i).map_or(Vec3A::ZERO, SolverBody::inverse_mass)))
            };
            let masses = [inv_m(a), inv_m(b)];
            self.fill_axes(bi, (masses[0], &ia), (masses[1], &ib));
            let batch = &mut self.batches[bi];
            match batch.locked {
                Batch::UNLOCKED => {
                    batch.locked = self.lock_masses.len() as u32;
                    self.lock_masses.push(masses);
                }
                i => self.lock_masses[i as usize] = masses,
            }
        } else {
            let (ma, mb) = (inv_m(a), inv_m(b));
            self.fill_axes(bi, (ma, &ia), (mb, &ib));
            let batch = &mut self.batches[bi];
            (batch.inv_m_a, batch.inv_m_b) = (ma, mb);
            batch.locked = Batch::UNLOCKED;
        }
    }

    /// [`Self::compute_axes`] from the sides' inverse masses and inertias.
    fn fill_axes<M: LinearMass>(&mut self, bi: usize, (ma, ia): (M, &M3), (mb, ib): (M, &M3)) {
        let batch = self.batches[bi];
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
            p.normal = Axis::new(ma, ia, p.r_a, mb, ib, p.r_b, batch.n, live);
            if let Some(t) = tracks.get_mut(k) {
                t.half_w = p
                    .normal
                    .mass
                    .simd_gt(F4::ZERO)
                    .select(F4::splat(0.5) / p.normal.mass, F4::ZERO);
            }
        }
        let lanes = F4::new(counts.map(|c| if c > 0 { f32::from_bits(!0) } else { 0.0 }));
        self.friction[bi].compute(&batch, (ma, ia), (mb, ib), lanes);
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
}

mod friction;
mod limits;
mod restitution;
mod write_back;

#[cfg(test)]
mod tests;
