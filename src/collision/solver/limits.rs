//! The solver's guards for hard cases, each touching only the bodies it is for: the
//! rotation limit of bodies in contact, and the deep-overlap rules (a per-body speed cap and
//! a second look at the contacts with static bodies).

use super::{ContactSolver, Softness};

impl ContactSolver {
    /// Scales down the angular velocity of every dynamic body spinning faster than
    /// `max_w` (rad/s; not a positive number: no limit). The write-back turns the change
    /// into the angular momentum, so the limit only ever takes energy out.
    pub fn limit_rotation(&mut self, max_w: f32) {
        if max_w.is_nan() || max_w <= 0.0 {
            return;
        }
        let max2 = max_w * max_w;
        for (b, s) in self.bodies.iter().zip(&mut self.states) {
            let w2 = s.w.length_squared();
            if b.dynamic && w2 > max2 {
                s.w *= max_w / w2.sqrt();
            }
        }
    }

    /// In a step where some body overlaps something deeply, solves the batches that hold a
    /// static or kinematic side once more, after the pass, so that the ground has the last
    /// word on what rests on it: a box spawned half inside the ground, under a heap that
    /// overlapped it, was pushed down past the ground's middle, where the ground's normal
    /// turns over, and fell through. Other steps are untouched.
    pub fn solve_grounded(
        &mut self,
        h: f32,
        soft: Softness,
        fixed_soft: Softness,
        use_bias: bool,
        max_push: f32,
    ) {
        if !self.any_deep {
            return;
        }
        self.grounded_only = true;
        self.solve(h, soft, fixed_soft, use_bias, max_push);
        self.grounded_only = false;
    }

    /// Records each body's speed as the substep's contact passes begin.
    pub fn record_speeds(&mut self) {
        if !self.any_deep {
            return;
        }
        for (b, s) in self.bodies.iter_mut().zip(&self.states) {
            b.speed_in = s.v.length();
        }
    }

    /// Caps the speed of every body that overlaps something deeply at the larger of its speed
    /// entering the substep and `max_push` (m/s), as PhysX's per-body depenetration velocity
    /// does. Push-out is bounded per contact, but a body overlapping hundreds of others (a
    /// heap spawned at one point) summed their pushes, and Gauss–Seidel pumped them up step
    /// after step: 1,000 boxes spawned at one point left at up to 139 m/s and flew off the
    /// ground. Only deep overlaps are touched, and the cap only takes energy out.
    pub fn limit_deep_speed(&mut self, max_push: f32) {
        if !self.any_deep {
            return;
        }
        for (b, s) in self.bodies.iter().zip(&mut self.states) {
            if !(b.deep && b.dynamic) {
                continue;
            }
            let cap = b.speed_in.max(max_push);
            let speed = s.v.length();
            if speed > cap {
                s.v *= cap / speed;
            }
        }
    }
}
