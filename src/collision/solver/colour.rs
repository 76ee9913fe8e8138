//! The colouring: manifolds coloured so that no dynamic body appears twice in a colour, each
//! colour cut into batches of four for the SIMD lanes, and the manifolds that find no colour
//! solved one per batch after the colours.

use super::*;

/// How many chunks of four ahead the colouring starts loading constraints.
const AHEAD: usize = 4;

impl ContactSolver {
    /// Colours the manifolds and lays them out in batches, with their effective masses.
    /// Call once per step after every body and manifold was added.
    pub fn build(&mut self) {
        self.build_with(COLOURS);
    }

    /// [`Self::build`] with at most `max_colours` colours (0: every manifold alone).
    pub(super) fn build_with(&mut self, max_colours: usize) {
        self.any_deep = self.bodies.iter().any(|b| b.deep);
        self.states.clear();
        self.states.resize(self.bodies.len() + 1, BodyState::REST);
        // Per body, a bit for each colour it is in: the first free colour of a manifold is
        // the lowest bit clear in both sides' masks.
        let max_colours = max_colours.min(u32::BITS as usize);
        self.used.clear();
        self.used.resize(self.bodies.len(), 0);
        self.colours.resize_with(max_colours, Vec::new);
        for c in &mut self.colours {
            c.clear();
        }
        let mut overflow = Vec::new();
        let (bodies, used) = (&self.bodies, &mut self.used);
        let movable = |i: u32| {
            bodies
                .get(i as usize)
                .filter(|b| b.dynamic)
                .map(|_| i as usize)
        };
        let all = ((1u64 << max_colours) - 1) as u32;
        for (mi, m) in self.manifolds.iter().enumerate() {
            let sides = [movable(m.a), movable(m.b)];
            let taken = sides.iter().flatten().fold(0, |t, &i| t | used[i]);
            let free = !taken & all;
            if free == 0 {
                overflow.push(mi as u32);
                continue;
            }
            let c = free.trailing_zeros();
            for &i in sides.iter().flatten() {
                used[i] |= 1 << c;
            }
            self.colours[c as usize].push(mi as u32);
        }
        let colours = std::mem::take(&mut self.colours);
        for c in &colours {
            for (k, chunk) in c.chunks(4).enumerate() {
                self.prefetch_chunks(c, k);
                self.push_batch(chunk);
            }
        }
        for &mi in &overflow {
            self.push_batch(&[mi]);
        }
        self.colours = colours;
    }

    /// Starts loading the constraints of the chunk of four [`AHEAD`] chunks after the
    /// `k`th of `colour`, and the point inputs of the one half as far: the colouring reads
    /// them in colour order, a jump through memory for each.
    #[inline]
    fn prefetch_chunks(&self, colour: &[u32], k: usize) {
        let chunk = |j: usize| colour.iter().skip(4 * j).take(4);
        for &mi in chunk(k + AHEAD) {
            if let Some(m) = self.manifolds.get(mi as usize) {
                crate::collision::prefetch::lines(m);
            }
        }
        for &mi in chunk(k + AHEAD / 2) {
            if let Some(m) = self.manifolds.get(mi as usize) {
                let inputs = self
                    .inputs
                    .get(m.first as usize..(m.first + m.count) as usize);
                crate::collision::prefetch::lines(inputs.unwrap_or_default());
            }
        }
    }

    fn push_batch(&mut self, chunk: &[u32]) {
        let rest = self.rest();
        let lane = |l: usize| chunk.get(l).map(|&mi| &self.manifolds[mi as usize]);
        let side = |l: usize, pick: fn(&ManifoldConstraint) -> u32| {
            lane(l).map_or(rest, |m| pick(m).min(rest))
        };
        let a: [u32; 4] = std::array::from_fn(|l| side(l, |m| m.a));
        let b: [u32; 4] = std::array::from_fn(|l| side(l, |m| m.b));
        let scalar = |f: fn(&ManifoldConstraint) -> f32| {
            F4::new(std::array::from_fn(|l| lane(l).map_or(0.0, f)))
        };
        let vector = |f: fn(&ManifoldConstraint) -> Vec3A| {
            V3::from_lanes(std::array::from_fn(|l| lane(l).map_or(Vec3A::ZERO, f)))
        };
        let count = chunk
            .iter()
            .map(|&mi| self.manifolds[mi as usize].count)
            .max()
            .unwrap_or(0);
        let fixed = std::array::from_fn(|l| lane(l).is_some_and(|m| m.a == FIXED || m.b == FIXED));
        let mut batch = Batch {
            lanes: std::array::from_fn(|l| chunk.get(l).copied().unwrap_or(u32::MAX)),
            a,
            b,
            first: self.points.len() as u32,
            count,
            // Set below for a batch that bounces.
            tracked: Batch::UNTRACKED,
            // Set with the axes.
            locked: Batch::UNLOCKED,
            n: vector(|m| m.n),
            t: [vector(|m| m.t[0]), vector(|m| m.t[1])],
            // Set with the axes.
            inv_m_a: F4::ZERO,
            inv_m_b: F4::ZERO,
            friction: scalar(|m| m.friction),
            restitution: scalar(|m| m.restitution),
            threshold: scalar(|m| -m.threshold),
            fixed: F4::new(fixed.map(|f| if f { f32::from_bits(!0) } else { 0.0 })),
            held: match self.edited {
                true => (0..4).fold(0, |h, l| h | lane(l).map_or(0, |m| m.held & 3) << (2 * l)),
                false => 0,
            },
        };
        if batch.bouncy() {
            batch.tracked = self.tracks.len() as u32;
        }
        for k in 0..count {
            // Lanes past a manifold's last point stay zero (their masses are zeroed too).
            let (mut r_a, mut r_b) = ([Vec3A::ZERO; 4], [Vec3A::ZERO; 4]);
            let mut s = [[0.0f32; 4]; 3];
            for (l, &mi) in chunk.iter().enumerate() {
                let m = &self.manifolds[mi as usize];
                if k < m.count {
                    let p = &self.inputs[(m.first + k) as usize];
                    (r_a[l], r_b[l]) = (p.r_a, p.r_b);
                    s[0][l] = p.base;
                    s[1][l] = p.n_imp;
                    s[2][l] = p.approach;
                }
            }
            self.points.push(Point {
                r_a: V3::from_lanes(r_a),
                r_b: V3::from_lanes(r_b),
                base: F4::new(s[0]),
                normal: Axis::default(),
                n_imp: F4::new(s[1]),
            });
            if batch.tracked == Batch::UNTRACKED {
                continue;
            }
            self.tracks.push(Track {
                max_n: F4::ZERO,
                approach: F4::new(s[2]),
                vn_seen: [F4::splat(f32::NAN); 2],
                absorbed: F4::ZERO,
                lost: F4::ZERO,
                half_w: F4::ZERO,
                vn_end: F4::ZERO,
                gain: F4::ZERO,
            });
        }
        self.friction
            .push(friction::Friction::new(&self.manifolds, chunk, self.edited));
        self.batches.push(batch);
        self.compute_axes(self.batches.len() - 1);
    }
}
