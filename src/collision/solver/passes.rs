//! The passes over the batches: warm start, the biased and relax passes, and loading and
//! storing a batch's two sides.
//!
//! Each pass is written once, generic over the side's inverse mass ([`LinearMass`]), and a
//! batch picks its copy: a world with no locks runs the scalar copy only, with a test per
//! batch and nothing per point.

use glam::Vec3A;

use super::friction::Friction;
use super::side::{LinearMass, Side};
use super::{Batch, BodyState, ContactSolver, F4, Point, Q4, Softness, Track, V3, work};

/// A pass over the batches, visiting each with its two sides loaded, in whichever form of
/// inverse mass the batch takes.
pub(super) trait BatchPass {
    fn visit<M: LinearMass>(
        &mut self,
        batch: &Batch,
        friction: &mut Friction,
        points: (&mut [Point], &mut [Track]),
        states: &[BodyState],
        sides: &mut [Side<M>; 2],
    );
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
    fn point<const BIAS: bool, const TRACK: bool, M: LinearMass>(
        &self,
        p: &mut Point,
        t: &mut Track,
        a: &mut Side<M>,
        b: &mut Side<M>,
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
                let hit = super::impact_speed(vn, s, t.vn_seen, self.inv_h);
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

/// The warm start: every accumulated impulse applied once.
struct WarmStart;

impl BatchPass for WarmStart {
    #[inline(always)]
    fn visit<M: LinearMass>(
        &mut self,
        batch: &Batch,
        friction: &mut Friction,
        (points, tracks): (&mut [Point], &mut [Track]),
        _: &[BodyState],
        [a, b]: &mut [Side<M>; 2],
    ) {
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
    }
}

/// A biased (`BIAS`) or relax pass.
struct SolvePass<const BIAS: bool> {
    inv_h: F4,
    max_push: F4,
    soft: Softness,
    fixed_soft: Softness,
}

impl<const BIAS: bool> BatchPass for SolvePass<BIAS> {
    #[inline(always)]
    fn visit<M: LinearMass>(
        &mut self,
        batch: &Batch,
        friction: &mut Friction,
        (points, tracks): (&mut [Point], &mut [Track]),
        states: &[BodyState],
        [a, b]: &mut [Side<M>; 2],
    ) {
        let (zero, one) = (F4::ZERO, F4::ONE);
        let (dx_a, dq_a) = ContactSolver::motion(states, batch.a);
        let (dx_b, dq_b) = ContactSolver::motion(states, batch.b);
        let pick = |f: fn(&Softness) -> f32| {
            batch
                .fixed
                .select(F4::splat(f(&self.fixed_soft)), F4::splat(f(&self.soft)))
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
            inv_h: self.inv_h,
            bias_rate,
            mass_scale,
            impulse_scale,
            max_push: self.max_push,
        };
        if batch.bouncy() {
            let mut visit = |(p, t): (&mut Point, &mut Track)| {
                pass.point::<BIAS, true, M>(p, t, a, b);
            };
            let pairs = points.iter_mut().zip(tracks.iter_mut());
            match BIAS {
                true => pairs.for_each(&mut visit),
                false => pairs.rev().for_each(&mut visit),
            }
        } else {
            // A batch that does not bounce keeps no record: this one is not read.
            let mut unread = Track::default();
            let mut visit = |p: &mut Point| pass.point::<BIAS, false, M>(p, &mut unread, a, b);
            match BIAS {
                true => points.iter_mut().for_each(&mut visit),
                false => points.iter_mut().rev().for_each(&mut visit),
            }
        }
        if !BIAS {
            let normal = points.iter().fold(F4::ZERO, |s, p| s + p.n_imp);
            friction.solve(batch, normal, a, b);
        }
    }
}

impl ContactSolver {
    #[inline]
    pub(super) fn load<M>(states: &[BodyState], ix: [u32; 4], inv_m: M) -> Side<M> {
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
    pub(super) fn store<M>(states: &mut [BodyState], ix: [u32; 4], side: &Side<M>) {
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
    pub(super) fn settle_rest(states: &mut [BodyState], rest: u32) {
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

    /// Runs `pass` on every batch with both sides loaded, then stores the sides back.
    /// Borrows field by field: a batch is a few hundred bytes, and copying it out of `self`
    /// for each pass cost a memcpy call per batch.
    #[inline(always)]
    fn for_each_batch(&mut self, pass: &mut impl BatchPass) {
        let rest = self.rest();
        let Self {
            batches,
            points,
            tracks,
            states,
            friction,
            grounded_only,
            lock_masses,
            ..
        } = self;
        // A step without locks runs a loop that never asks.
        let locks = !lock_masses.is_empty();
        for (batch, friction) in batches.iter().zip(friction.iter_mut()) {
            if *grounded_only && !batch.fixed.any() {
                continue;
            }
            let range = batch.first as usize..(batch.first + batch.count) as usize;
            let points = (&mut points[range], &mut tracks[batch.tracks()]);
            if !locks || batch.locked == Batch::UNLOCKED {
                let mut sides = [
                    Self::load(states, batch.a, batch.inv_m_a),
                    Self::load(states, batch.b, batch.inv_m_b),
                ];
                pass.visit(batch, friction, points, states, &mut sides);
                Self::store(states, batch.a, &sides[0]);
                Self::store(states, batch.b, &sides[1]);
            } else {
                Self::visit_locked(pass, batch, friction, points, states, lock_masses);
            }
            Self::settle_rest(states, rest);
        }
    }

    /// [`Self::for_each_batch`]'s visit of a batch with a locked translation, out of line
    /// and marked cold: laid out apart, it leaves the scalar loop as it was (measured: the
    /// Box3D large pyramid's step took 0.67 % more instructions with it inline, 0.47 % now).
    #[inline(never)]
    #[cold]
    fn visit_locked(
        pass: &mut impl BatchPass,
        batch: &Batch,
        friction: &mut Friction,
        points: (&mut [Point], &mut [Track]),
        states: &mut [BodyState],
        lock_masses: &[[V3; 2]],
    ) {
        let [ma, mb] = lock_masses[batch.locked as usize];
        let mut sides = [
            Self::load(states, batch.a, ma),
            Self::load(states, batch.b, mb),
        ];
        pass.visit(batch, friction, points, states, &mut sides);
        Self::store(states, batch.a, &sides[0]);
        Self::store(states, batch.b, &sides[1]);
    }

    /// Applies every accumulated impulse once (warm start).
    pub fn warm_start(&mut self) {
        self.for_each_batch(&mut WarmStart);
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
        let (inv_h, max_push) = (F4::splat(1.0 / h), F4::splat(-max_push));
        // One copy of the pass per kind, so that neither tests the kind per point.
        if use_bias {
            self.for_each_batch(&mut SolvePass::<true> {
                inv_h,
                max_push,
                soft,
                fixed_soft,
            });
        } else {
            self.for_each_batch(&mut SolvePass::<false> {
                inv_h,
                max_push,
                soft,
                fixed_soft,
            });
        }
    }
}
