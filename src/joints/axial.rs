//! A joint's free axis: the turn of a hinge, the slide of a slider, the length of a
//! distance joint. Its motor and its limits are rows of their own, solved one at a time
//! before the joint's locked rows (Box2D v3's order: motor, lower limit, upper limit, then
//! the rest), so the locked rows keep what these leave.
//!
//! A limit is a one-sided row (its impulse pushes only away from the limit). Short of its
//! limit, it lets the axis close the distance left within the substep and no more (Box2D's
//! speculative row); past it, the soft step pulls back as the locked rows do.

use glam::{Quat, Vec3, Vec3A};

use super::solve::{Accumulated, Axis, Mode, Rows, Side};

/// The axis as it stands: its direction (world), whether it is linear, the lever arms its
/// impulse acts at, and its value.
#[derive(Debug, Clone, Copy)]
pub(super) struct Measured {
    pub n: Vec3A,
    pub linear: bool,
    pub r_a: Vec3A,
    pub r_b: Vec3A,
    pub value: f32,
}

impl Measured {
    /// The rate of change of the value.
    pub fn rate(&self, a: &Side, b: &Side) -> f32 {
        if self.linear {
            let va = a.v + a.w.cross(self.r_a);
            let vb = b.v + b.w.cross(self.r_b);
            self.n.dot(vb - va)
        } else {
            self.n.dot(b.w - a.w)
        }
    }

    /// The inverse effective mass along the axis, or None when nothing moves it.
    fn inverse_mass(&self, a: &Side, b: &Side) -> Option<f32> {
        let mut k = 0.0;
        for (side, r) in [(a, self.r_a), (b, self.r_b)] {
            if !side.moves {
                continue;
            }
            if self.linear {
                let rn = r.cross(self.n);
                k += side.inv_m + rn.dot(side.inv_i * rn);
            } else {
                k += self.n.dot(side.inv_i * self.n);
            }
        }
        (k > 0.0 && k.is_finite()).then_some(k)
    }

    /// Applies `lambda` along the axis to `b` and its opposite to `a`.
    fn apply(&self, a: &mut Side, b: &mut Side, lambda: f32) {
        let p = lambda * self.n;
        if self.linear {
            a.push(-p, self.r_a, Vec3A::ZERO);
            b.push(p, self.r_b, Vec3A::ZERO);
        } else {
            a.push(Vec3A::ZERO, Vec3A::ZERO, -p);
            b.push(Vec3A::ZERO, Vec3A::ZERO, p);
        }
    }
}

/// `angle` brought into (−π, π].
fn wrap_angle(angle: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let a = angle.rem_euclid(TAU);
    if a > PI { a - TAU } else { a }
}

/// The hinge angle (rad, in (−π, π]): the turn of `b` relative to `a` about `a`'s axis,
/// zero where `b` stands as `a` does once its axis is turned onto `a`'s by the shortest arc.
#[must_use]
pub(super) fn hinge_angle(qa: Quat, qb: Quat, axis_a: Vec3, axis_b: Vec3) -> f32 {
    let relative = qa.inverse() * qb;
    let mut twist = relative * Quat::from_rotation_arc(axis_b, axis_a).inverse();
    if twist.w < 0.0 {
        twist = -twist;
    }
    let along = Vec3::new(twist.x, twist.y, twist.z).dot(axis_a);
    2.0 * along.atan2(twist.w)
}

/// The free axis as it stands between `a` and `b`, when the joint has one.
pub(super) fn measure(rows: &Rows, a: &Side, b: &Side) -> Option<Measured> {
    let r_a = a.q * rows.local_a;
    let r_b = b.q * rows.local_b;
    let d = (b.x + r_b) - (a.x + r_a);
    match rows.axial.axis? {
        Axis::Turn { axis_a, axis_b } => Some(Measured {
            n: a.q * Vec3A::from(axis_a),
            linear: false,
            r_a,
            r_b,
            value: hinge_angle(a.q, b.q, axis_a, axis_b),
        }),
        Axis::Slide { axis_a } => {
            let n = a.q * Vec3A::from(axis_a);
            Some(Measured {
                n,
                linear: true,
                // a's impulse acts at b's anchor: the slide's lever arm on a.
                r_a: r_a + d,
                r_b,
                value: n.dot(d),
            })
        }
        Axis::Length => {
            let length = d.length();
            (length > 1e-6).then(|| Measured {
                n: d / length,
                linear: true,
                r_a,
                r_b,
                value: length,
            })
        }
    }
}

/// The axis's value as it stands (rad or m), when it has one.
#[must_use]
pub(super) fn value(rows: &Rows, a: &Side, b: &Side) -> Option<f32> {
    measure(rows, a, b).map(|m| m.value)
}

/// Applies the accumulated motor and limit impulses again along the axis as it now stands.
pub(super) fn warm_start(rows: &Rows, acc: &Accumulated, a: &mut Side, b: &mut Side) {
    let total = acc.motor + acc.lower - acc.upper;
    if total == 0.0 {
        return;
    }
    if let Some(m) = measure(rows, a, b) {
        m.apply(a, b, total);
    }
}

/// The accumulated motor and limit impulses as world vectors: (linear, angular).
#[must_use]
pub(super) fn world_impulse(rows: &Rows, acc: &Accumulated, a: &Side, b: &Side) -> (Vec3, Vec3) {
    let total = acc.motor + acc.lower - acc.upper;
    match measure(rows, a, b) {
        Some(m) if total != 0.0 && m.linear => ((total * m.n).into(), Vec3::ZERO),
        Some(m) if total != 0.0 => (Vec3::ZERO, (total * m.n).into()),
        _ => (Vec3::ZERO, Vec3::ZERO),
    }
}

/// A motor spring's impulse over the substep for the axis `m` moving at `rate` (relative to
/// the motor's target velocity, before any motor impulse of this substep), `k` the axis's
/// inverse mass: `h (s (x* − x) − d rate′)` with the damping implicit. Explicit in the
/// position while h² s k ≤ 1 (symplectic Euler: no numerical damping; its period is off by
/// (ωh)²/24 at most 4 %), the implicit soft step past that (stable at any stiffness, damped).
fn spring_impulse(spring: (f32, f32, f32), m: &Measured, rate: f32, k: f32, h: f32) -> f32 {
    let (x, stiffness, damping) = spring;
    let mut c = m.value - x;
    if !m.linear {
        c = wrap_angle(c);
    }
    if h * h * stiffness * k <= 1.0 {
        return -h * (stiffness * c + damping * rate) / (1.0 + h * damping * k);
    }
    -h * (stiffness * (c + h * rate) + damping * rate) / (1.0 + h * k * (damping + h * stiffness))
}

/// Solves the axis's motor, then (with `limits`; a group solve takes them otherwise) its
/// lower and upper limits, each on its own. `first`: the substep's first (biased) pass.
pub(super) fn solve(
    rows: &Rows,
    (a, b): (&mut Side, &mut Side),
    acc: &mut Accumulated,
    (mode, h, first): (Mode, f32, bool),
    limits: bool,
) {
    let Some(m) = measure(rows, a, b) else {
        return;
    };
    let Some(k) = m.inverse_mass(a, b) else {
        return;
    };
    if let Some((target, max, spring)) = rows.axial.motor {
        let limit = max * h;
        let held = acc.motor;
        let rate = m.rate(a, b) - target;
        let total = match spring {
            // Rigid in every pass: a velocity target, with no position to correct.
            None => Some(held - rate / k),
            // A spring–damper is a force: applied once a substep, in the first pass (a
            // second solve after the positions move would damp it).
            Some(spring) => first.then(|| spring_impulse(spring, &m, rate - k * held, k, h)),
        };
        if let Some(total) = total {
            acc.motor = total.clamp(-limit, limit);
            m.apply(a, b, acc.motor - held);
        }
    }
    let Some((min, max)) = rows.axial.limits.filter(|_| limits) else {
        return;
    };
    for (sign, c, held) in [
        (1.0, m.value - min, &mut acc.lower),
        (-1.0, max - m.value, &mut acc.upper),
    ] {
        let (bias, mass_scale, impulse_scale) = if c > 0.0 {
            (c / h, 1.0, 0.0)
        } else {
            (mode.bias_rate * c, mode.mass_scale, mode.impulse_scale)
        };
        let rate = sign * m.rate(a, b);
        let lambda = -mass_scale * (rate + bias) / k - impulse_scale * *held;
        let total = (*held + lambda).max(0.0);
        if !total.is_finite() {
            continue;
        }
        m.apply(a, b, sign * (total - *held));
        *held = total;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hinge_angle_is_the_turn_about_the_axis() {
        let z = Vec3::Z;
        for angle in [-3.0, -1.0, 0.0, 0.4, 2.5, 3.1] {
            let qa = Quat::from_rotation_x(0.7);
            let qb = qa * Quat::from_rotation_z(angle);
            assert!((hinge_angle(qa, qb, z, z) - angle).abs() < 1e-5, "{angle}");
        }
        // b's axis given as x in its own frame: zero turn is b's x on a's z by the shortest arc.
        let arc = Quat::from_rotation_arc(Vec3::X, Vec3::Z);
        let qb = Quat::from_rotation_z(0.5) * arc;
        assert!((hinge_angle(Quat::IDENTITY, qb, Vec3::Z, Vec3::X) - 0.5).abs() < 1e-5);
    }
}
