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
                k += self.n.dot(side.inv_m * self.n) + rn.dot(side.inv_i * rn);
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
        Axis::Twist { axis_a, axis_b } => {
            let (n_a, n_b) = (a.q * Vec3A::from(axis_a), b.q * Vec3A::from(axis_b));
            // The twist's rate is (n_a + n_b)·(ω_b − ω_a) / (1 + n_a·n_b): it is 1 for a turn
            // about either axis and 0 for the swing about n_a × n_b.
            let denominator = 1.0 + n_a.dot(n_b);
            (denominator > 1e-3).then(|| Measured {
                n: (n_a + n_b) / denominator,
                linear: false,
                r_a,
                r_b,
                value: hinge_angle(a.q, b.q, axis_a, axis_b),
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

/// A ball joint's swing as it stands with its cone's half-angle, when it has a cone and
/// the axes are not aligned: the angle θ between them, whose rate is n·(ω_b − ω_a) for
/// n = n_a × n_b / |n_a × n_b|.
pub(super) fn measure_swing(rows: &Rows, a: &Side, b: &Side) -> Option<(Measured, f32)> {
    let swing = rows.axial.swing?;
    let (n_a, n_b) = (
        a.q * Vec3A::from(swing.axis_a),
        b.q * Vec3A::from(swing.axis_b),
    );
    let cross = n_a.cross(n_b);
    let sin = cross.length();
    (sin > 1e-6).then(|| {
        let m = Measured {
            n: cross / sin,
            linear: false,
            r_a: Vec3A::ZERO,
            r_b: Vec3A::ZERO,
            value: sin.atan2(n_a.dot(n_b)),
        };
        (m, swing.max)
    })
}

/// The axis's value as it stands (rad or m), when it has one.
#[must_use]
pub(super) fn value(rows: &Rows, a: &Side, b: &Side) -> Option<f32> {
    measure(rows, a, b).map(|m| m.value)
}

/// Applies the accumulated motor and limit impulses again along the axis as it now stands.
pub(super) fn warm_start(rows: &Rows, acc: &Accumulated, a: &mut Side, b: &mut Side) {
    let total = acc.motor + acc.lower - acc.upper;
    if total != 0.0
        && let Some(m) = measure(rows, a, b)
    {
        m.apply(a, b, total);
    }
    if acc.swing != 0.0
        && let Some((m, _)) = measure_swing(rows, a, b)
    {
        m.apply(a, b, -acc.swing);
    }
    if acc.friction != Vec3A::ZERO {
        a.push(Vec3A::ZERO, Vec3A::ZERO, -acc.friction);
        b.push(Vec3A::ZERO, Vec3A::ZERO, acc.friction);
    }
}

/// The accumulated motor and limit impulses as world vectors: (linear, angular).
#[must_use]
pub(super) fn world_impulse(rows: &Rows, acc: &Accumulated, a: &Side, b: &Side) -> (Vec3, Vec3) {
    let total = acc.motor + acc.lower - acc.upper;
    // Measured only where an impulse needs its axis: most joints hold none.
    let swing = match (acc.swing != 0.0).then(|| measure_swing(rows, a, b)) {
        Some(Some((m, _))) => Vec3::from(-acc.swing * m.n),
        _ => Vec3::ZERO,
    } + Vec3::from(acc.friction);
    if total == 0.0 {
        return (Vec3::ZERO, swing);
    }
    match measure(rows, a, b) {
        Some(m) if total != 0.0 && m.linear => ((total * m.n).into(), swing),
        Some(m) if total != 0.0 => (Vec3::ZERO, Vec3::from(total * m.n) + swing),
        _ => (Vec3::ZERO, swing),
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
/// lower and upper limits and a ball joint's cone, each on its own. `first`: the substep's
/// first (biased) pass.
pub(super) fn solve(
    rows: &Rows,
    (a, b): (&mut Side, &mut Side),
    acc: &mut Accumulated,
    (mode, h, first): (Mode, f32, bool),
    limits: bool,
) {
    if let Some(max) = rows.axial.friction {
        friction(max * h, (a, b), &mut acc.friction);
    }
    if let Some(m) = measure(rows, a, b)
        && let Some(k) = m.inverse_mass(a, b)
    {
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
        if let Some((min, max)) = rows.axial.limits.filter(|_| limits) {
            stop(
                &m,
                k,
                (a, b),
                (1.0, m.value - min),
                &mut acc.lower,
                (mode, h),
            );
            stop(
                &m,
                k,
                (a, b),
                (-1.0, max - m.value),
                &mut acc.upper,
                (mode, h),
            );
        }
    }
    if limits
        && let Some((m, max)) = measure_swing(rows, a, b)
        && let Some(k) = m.inverse_mass(a, b)
    {
        stop(
            &m,
            k,
            (a, b),
            (-1.0, max - m.value),
            &mut acc.swing,
            (mode, h),
        );
    }
}

/// A ball joint's friction: the angular impulse that stops the sides' relative spin,
/// its accumulated total `held` kept within `limit` (N·m·s) in length.
fn friction(limit: f32, (a, b): (&mut Side, &mut Side), held: &mut Vec3A) {
    let mut k = glam::Mat3A::ZERO;
    for side in [&*a, &*b] {
        if side.moves {
            k += side.inv_i;
        }
    }
    let k = super::solve::free_of_locks(k);
    let det = k.determinant();
    if !(det.is_finite() && det > 0.0) {
        return;
    }
    let lambda = k.inverse() * (a.w - b.w);
    let total = (*held + lambda).clamp_length_max(limit);
    if !total.is_finite() {
        return;
    }
    let delta = total - *held;
    a.push(Vec3A::ZERO, Vec3A::ZERO, -delta);
    b.push(Vec3A::ZERO, Vec3A::ZERO, delta);
    *held = total;
}

/// One limit of the axis `m` (inverse mass `k`) as a one-sided row: `sign` +1 for a lower
/// stop, −1 for an upper one, `c` the distance left to it, `held` its accumulated impulse.
fn stop(
    m: &Measured,
    k: f32,
    (a, b): (&mut Side, &mut Side),
    (sign, c): (f32, f32),
    held: &mut f32,
    (mode, h): (Mode, f32),
) {
    let (bias, mass_scale, impulse_scale) = if c > 0.0 {
        (c / h, 1.0, 0.0)
    } else {
        (mode.bias_rate * c, mode.mass_scale, mode.impulse_scale)
    };
    let rate = sign * m.rate(a, b);
    let lambda = -mass_scale * (rate + bias) / k - impulse_scale * *held;
    let total = (*held + lambda).max(0.0);
    if !total.is_finite() {
        return;
    }
    m.apply(a, b, sign * (total - *held));
    *held = total;
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

    #[test]
    fn the_twist_and_swing_rates_are_the_derivatives_of_their_angles() {
        use super::super::solve::{Angular, Axial, Linear, Swing};
        let (axis_a, axis_b) = (Vec3::new(0.0, -0.6, 0.8), Vec3::NEG_Y);
        let rows = Rows {
            local_a: Vec3A::ZERO,
            local_b: Vec3A::ZERO,
            angular: Angular::Free,
            linear: Linear::Point,
            axial: Axial {
                axis: Some(Axis::Twist { axis_a, axis_b }),
                limits: Some((-1.0, 1.0)),
                swing: Some(Swing {
                    axis_a,
                    axis_b,
                    max: 1.0,
                }),
                ..Axial::NONE
            },
        };
        let side = |q: Quat, w: Vec3| Side {
            q,
            w: w.into(),
            ..Side::WORLD
        };
        let (qa, qb) = (
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.5, 0.9),
            Quat::from_euler(glam::EulerRot::XYZ, -0.2, 0.4, 1.3),
        );
        let (wa, wb) = (Vec3::new(0.4, -1.1, 0.7), Vec3::new(-0.9, 0.3, 1.6));
        let (a, b) = (side(qa, wa), side(qb, wb));
        let eps = 1e-3;
        let turn = |q: Quat, w: Vec3, t: f32| Quat::from_scaled_axis(w * t) * q;
        let later = |t: f32| (side(turn(qa, wa, t), wa), side(turn(qb, wb, t), wb));
        let ((a1, b1), (a0, b0)) = (later(eps), later(-eps));
        let twist = measure(&rows, &a, &b).unwrap();
        let numeric = (measure(&rows, &a1, &b1).unwrap().value
            - measure(&rows, &a0, &b0).unwrap().value)
            / (2.0 * eps);
        assert!(
            (twist.rate(&a, &b) - numeric).abs() < 2e-3,
            "{} against {numeric}",
            twist.rate(&a, &b)
        );
        let (swing, _) = measure_swing(&rows, &a, &b).unwrap();
        let numeric = (measure_swing(&rows, &a1, &b1).unwrap().0.value
            - measure_swing(&rows, &a0, &b0).unwrap().0.value)
            / (2.0 * eps);
        assert!(
            (swing.rate(&a, &b) - numeric).abs() < 2e-3,
            "{} against {numeric}",
            swing.rate(&a, &b)
        );
    }
}
