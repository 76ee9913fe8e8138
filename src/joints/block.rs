//! Joint rows solved together: each joint's rows as one block, or a whole connected group of
//! joints as one system ([`super::envelope`] factors it); what a row's solution does to its
//! bodies and its joint.
//!
//! A row p holds its Jacobian on each side (linear and angular parts) and the row's position
//! error. The coupled effective mass is A_pq = Σ_s J_p,s M_s⁻¹ J_q,sᵀ over the moving bodies s
//! that rows p and q share; a pass solves A Δλ = −S_m (Ċ + β C), then subtracts S_i λ_acc
//! row by row (the soft step of [`super::solve`], with the group's A for the single K).
//!
//! Why whole groups: one joint after another, each joint disturbs the ones solved before it,
//! and a chain leaves every relax pass with relative velocity at its anchors, which the soft
//! correction then damps: a two-rod pendulum lost 37 J of 517 J in 60 s that way, 17.7 J
//! solved as one system (after which the group's anchors have no relative velocity).

use glam::Vec3A;

use super::solve::{Accumulated, Angular, Linear, Mode, Rows, Side};

/// What a row's impulse adds to: the joint's linear or angular accumulator (a vector, along
/// the row's direction), or one of its limits' (a one-sided row: its total stays ≥ 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Held {
    Linear,
    Angular,
    Lower,
    Upper,
    /// A ball joint's cone (one-sided too).
    Swing,
}

impl Held {
    /// Whether its row is a limit: one-sided, its total impulse ≥ 0.
    pub fn one_sided(self) -> bool {
        matches!(self, Held::Lower | Held::Upper | Held::Swing)
    }
}

/// One constraint row: its Jacobian on each side, the joint it belongs to and what its
/// impulse adds to.
#[derive(Debug, Clone, Copy)]
pub(super) struct Row {
    pub joint: usize,
    pub a: Option<usize>,
    pub b: Option<usize>,
    pub lin_a: Vec3A,
    pub ang_a: Vec3A,
    pub lin_b: Vec3A,
    pub ang_b: Vec3A,
    /// The row's direction (world frame): its impulse is this times λ.
    pub dir: Vec3A,
    pub held: Held,
    /// Position error (m or rad).
    pub c: f32,
    /// A limit short of its stop: the rate that closes the gap within the substep, C / h
    /// (rigid in every pass, Box2D's speculative row).
    pub speculative: Option<f32>,
    /// The row's speed from its immovable sides (m/s or rad/s): a kinematic body moves the
    /// anchor it holds, and the rows must follow it.
    pub carried: f32,
}

/// The rows of one joint between sides `a` and `b` (indices into the pass's bodies; `None`
/// for an immovable side), with its limits' rows when `limits` holds the substep length
/// and its accumulated impulses.
pub(super) fn joint_rows(
    joint: usize,
    rows: &Rows,
    (ia, a): (Option<usize>, &Side),
    (ib, b): (Option<usize>, &Side),
    limits: Option<(f32, &Accumulated)>,
    out: &mut Vec<Row>,
) {
    let base = Row {
        joint,
        a: ia,
        b: ib,
        lin_a: Vec3A::ZERO,
        ang_a: Vec3A::ZERO,
        lin_b: Vec3A::ZERO,
        ang_b: Vec3A::ZERO,
        dir: Vec3A::ZERO,
        held: Held::Angular,
        c: 0.0,
        speculative: None,
        carried: 0.0,
    };
    let start = out.len();
    let angular = |d: Vec3A, c: f32| Row {
        ang_a: -d,
        ang_b: d,
        dir: d,
        c,
        ..base
    };
    match rows.angular {
        Angular::Free => {}
        Angular::Hinge { axis_a, axis_b, .. } => {
            let axis_a = a.q * Vec3A::from(axis_a);
            let axis_b = b.q * Vec3A::from(axis_b);
            let (u, v) = glam::Vec3::from(axis_a).any_orthonormal_pair();
            let c = axis_a.cross(axis_b);
            for d in [Vec3A::from(u), Vec3A::from(v)] {
                out.push(angular(d, d.dot(c)));
            }
        }
        Angular::Weld { relative } => {
            let mut e = b.q * (a.q * relative).inverse();
            if e.w < 0.0 {
                e = -e;
            }
            let c = 2.0 * Vec3A::new(e.x, e.y, e.z);
            for d in [Vec3A::X, Vec3A::Y, Vec3A::Z] {
                out.push(angular(d, d.dot(c)));
            }
        }
    }
    let r_a = a.q * rows.local_a;
    let r_b = b.q * rows.local_b;
    let gap = (b.x + r_b) - (a.x + r_a);
    let arm_a = super::solve::lever_a(rows, r_a, gap);
    let mut linear = |e: Vec3A| {
        out.push(Row {
            lin_a: -e,
            ang_a: -arm_a.cross(e),
            lin_b: e,
            ang_b: r_b.cross(e),
            dir: e,
            held: Held::Linear,
            c: e.dot(gap),
            ..base
        });
    };
    match rows.linear {
        Linear::Point => [Vec3A::X, Vec3A::Y, Vec3A::Z].into_iter().for_each(linear),
        Linear::Slide { axis_a } => {
            let (u, v) = (a.q * axis_a).any_orthonormal_pair();
            linear(u.into());
            linear(v.into());
        }
        Linear::Free => {}
    }
    if let Some((h, acc)) = limits {
        if let Some((min, max)) = rows.axial.limits
            && let Some(m) = super::axial::measure(rows, a, b)
        {
            // The nearer stop only (or the one pushing): the two cannot both hold.
            let near_lower = if acc.lower > 0.0 || acc.upper > 0.0 {
                acc.lower >= acc.upper
            } else {
                m.value - min <= max - m.value
            };
            let stop = if near_lower {
                (Held::Lower, 1.0, m.value - min, acc.lower)
            } else {
                (Held::Upper, -1.0, max - m.value, acc.upper)
            };
            push_stop(&base, &m, stop, (a, b, h), out);
        }
        if let Some((m, max)) = super::axial::measure_swing(rows, a, b) {
            let stop = (Held::Swing, -1.0, max - m.value, acc.swing);
            push_stop(&base, &m, stop, (a, b, h), out);
        }
    }
    for row in &mut out[start..] {
        if ia.is_none() {
            row.carried += row.lin_a.dot(a.v) + row.ang_a.dot(a.w);
        }
        if ib.is_none() {
            row.carried += row.lin_b.dot(b.v) + row.ang_b.dot(b.w);
        }
    }
}

/// Appends the one-sided row of a stop on the axis `m`: `held` what it adds to, `sign` +1
/// for a lower stop and −1 for an upper one, `c` the distance left to it, `acc` the impulse
/// it holds. Left out while it is far from its stop and not pushing: it cannot reach the
/// stop in this substep.
fn push_stop(
    base: &Row,
    m: &super::axial::Measured,
    (held, sign, c, acc): (Held, f32, f32, f32),
    (a, b, h): (&Side, &Side, f32),
    out: &mut Vec<Row>,
) {
    let n = sign * m.n;
    let closing = -sign * m.rate(a, b);
    if acc > 0.0 || c <= 2.0 * h * closing.max(0.0) {
        let (lin_a, ang_a, lin_b, ang_b) = if m.linear {
            (-n, -m.r_a.cross(n), n, m.r_b.cross(n))
        } else {
            (Vec3A::ZERO, -n, Vec3A::ZERO, n)
        };
        out.push(Row {
            lin_a,
            ang_a,
            lin_b,
            ang_b,
            dir: n,
            held,
            c,
            speculative: (c > 0.0).then(|| c / h),
            ..*base
        });
    }
}

/// M⁻¹ Jᵀ of a row on one side: the velocity change per unit impulse.
#[inline]
pub(super) fn response(side: &Side, lin: Vec3A, ang: Vec3A) -> (Vec3A, Vec3A) {
    (side.inv_m * lin, side.inv_i * ang)
}

/// Whether one-sided row `rp` would pull with the solution `x`: its held impulse plus its new
/// λ below zero (the active set lets it go then).
pub(super) fn pulls(rp: &Row, x: f64, acc: &[Accumulated], mode: Mode) -> bool {
    rp.held.one_sided() && held(rp, acc) + lambda(rp, x, acc, mode) < 0.0
}

/// Takes back the impulse one-sided row `rp` holds.
pub(super) fn let_go(rp: &Row, bodies: &mut [Side], acc: &mut [Accumulated]) {
    let h = held(rp, acc);
    if h != 0.0 {
        push(rp, -h, bodies, acc);
    }
}

/// The right-hand side of row `rp`: −S_m (Ċ + β C).
pub(super) fn target(rp: &Row, bodies: &[Side], mode: Mode) -> f64 {
    let speed = |body: Option<usize>, lin: Vec3A, ang: Vec3A| {
        body.map_or(0.0, |s| lin.dot(bodies[s].v) + ang.dot(bodies[s].w))
    };
    let cdot = speed(rp.a, rp.lin_a, rp.ang_a) + speed(rp.b, rp.lin_b, rp.ang_b) + rp.carried;
    f64::from(match rp.speculative {
        Some(bias) => -(cdot + bias),
        None => -mode.mass_scale * (cdot + mode.bias_rate * rp.c),
    })
}

/// The impulse row `rp` holds from before this solve (its share of the joint's
/// accumulator).
fn held(rp: &Row, acc: &[Accumulated]) -> f32 {
    let acc = &acc[rp.joint];
    match rp.held {
        Held::Linear => rp.dir.dot(acc.linear),
        Held::Angular => rp.dir.dot(acc.angular),
        Held::Lower => acc.lower,
        Held::Upper => acc.upper,
        Held::Swing => acc.swing,
    }
}

/// The new impulse λ of row `rp` for the solution `x`: x − S_i held (a speculative row
/// keeps nothing of what it held).
fn lambda(rp: &Row, x: f64, acc: &[Accumulated], mode: Mode) -> f32 {
    let scale = if rp.speculative.is_some() {
        0.0
    } else {
        mode.impulse_scale
    };
    x as f32 - scale * held(rp, acc)
}

/// Applies `lambda` along row `rp` to its bodies and adds it to the joint's accumulator.
fn push(rp: &Row, lambda: f32, bodies: &mut [Side], acc: &mut [Accumulated]) {
    for (body, lin, ang) in [(rp.a, rp.lin_a, rp.ang_a), (rp.b, rp.lin_b, rp.ang_b)] {
        if let Some(s) = body {
            let side = &mut bodies[s];
            let (dv, dw) = response(side, lin, ang);
            side.v += lambda * dv;
            side.w += lambda * dw;
            side.dl += lambda * ang;
        }
    }
    let acc = &mut acc[rp.joint];
    match rp.held {
        Held::Linear => acc.linear += lambda * rp.dir,
        Held::Angular => acc.angular += lambda * rp.dir,
        Held::Lower => acc.lower += lambda,
        Held::Upper => acc.upper += lambda,
        Held::Swing => acc.swing += lambda,
    }
}

/// Applies row `rp`'s part `x` of the solution of A x = b: λ = x − S_i (the row's share of
/// the accumulated impulse), added to its joint's accumulator.
pub(super) fn apply_one(
    rp: &Row,
    x: f64,
    bodies: &mut [Side],
    acc: &mut [Accumulated],
    mode: Mode,
) {
    let lambda = lambda(rp, x, acc, mode);
    if lambda.is_finite() {
        push(rp, lambda, bodies, acc);
    }
}

/// The smallest pivot a row may leave after the rows before it and still count as
/// independent of them, under the regularisation `eps` (1e-10 of the largest effective mass
/// of the system's rows): 10⁴ eps.
///
/// A row that repeats what other rows hold (a loop of hinges with parallel axes locks its
/// out-of-plane motion twice: a plank bridge hinged at both ends) leaves a pivot of about
/// eps. Kept, any mismatch between the rows it repeats (f32 rounding) comes back as an
/// impulse 1 / eps times larger, one that moves nothing but builds up in the warm start
/// until its own rounding moves everything: a kicked bridge of 16 planks ran away at once,
/// one of 20 to forces of meganewtons within seconds. Left out (its λ zero), the rows
/// before it hold what it held. An independent row leaves a pivot of about its effective
/// mass in what the rows before it left free; that falls to the floor only at mass ratios
/// near 10⁶.
pub(super) fn redundancy_floor(eps: f64) -> f64 {
    1e4 * eps
}

#[cfg(test)]
pub(super) mod tests {
    use glam::{Mat3A, Vec3};

    use super::super::envelope::{Envelope, solve};
    use super::*;

    fn body(x: Vec3A) -> Side {
        Side {
            x,
            inv_m: Vec3A::ONE,
            inv_i: Mat3A::from_diagonal(Vec3::splat(6.0)),
            moves: true,
            ..Side::WORLD
        }
    }

    /// The largest relative speed any of `rows` leaves between its bodies.
    pub(in crate::joints) fn relative_speed(rows: &[Row], sides: &[Side]) -> f32 {
        let speed = |body: Option<usize>, lin: Vec3A, ang: Vec3A| {
            body.map_or(0.0, |s| lin.dot(sides[s].v) + ang.dot(sides[s].w))
        };
        rows.iter()
            .map(|r| (speed(r.a, r.lin_a, r.ang_a) + speed(r.b, r.lin_b, r.ang_b)).abs())
            .fold(0.0, f32::max)
    }

    #[test]
    fn a_rigid_pass_leaves_a_chain_without_relative_velocity_and_keeps_momentum() {
        // Three bodies in a row, two ball joints: solved as one system.
        let geometry = Rows::ball(Vec3A::new(0.5, 0.0, 0.0), Vec3A::new(-0.5, 0.0, 0.0));
        let mut sides = vec![
            body(Vec3A::ZERO),
            body(Vec3A::new(1.0, 0.0, 0.0)),
            body(Vec3A::new(2.0, 0.0, 0.0)),
        ];
        sides[0].v = Vec3A::new(0.0, 1.0, 0.0);
        sides[1].w = Vec3A::new(0.3, -2.0, 0.7);
        sides[2].v = Vec3A::new(0.5, 0.0, -1.0);
        let momentum: Vec3A = sides.iter().map(|s| s.v).sum();
        let mut rows = Vec::new();
        for (j, (a, b)) in [(0, 1), (1, 2)].into_iter().enumerate() {
            joint_rows(
                j,
                &geometry,
                (Some(a), &sides[a]),
                (Some(b), &sides[b]),
                None,
                &mut rows,
            );
        }
        let mut acc = vec![Accumulated::default(); 2];
        solve(
            &rows,
            &mut sides,
            &mut acc,
            Mode::RIGID,
            &mut Envelope::default(),
        );
        assert!(relative_speed(&rows, &sides) < 1e-5);
        let after: Vec3A = sides.iter().map(|s| s.v).sum();
        assert!(
            (after - momentum).length() < 1e-5,
            "{after} against {momentum}"
        );
    }

    #[test]
    fn a_ball_joint_alone_is_solved_as_its_rows_are() {
        let geometry = Rows::ball(Vec3A::new(0.5, 0.1, 0.0), Vec3A::new(-0.4, 0.0, 0.2));
        let mut sides = vec![body(Vec3A::ZERO), body(Vec3A::new(0.9, 0.2, -0.1))];
        sides[0].v = Vec3A::new(0.0, 1.0, 0.0);
        sides[1].w = Vec3A::new(0.3, -2.0, 0.7);
        sides[1].inv_m = Vec3A::splat(0.25);
        let mode = Mode {
            bias_rate: 20.0,
            mass_scale: 0.9,
            impulse_scale: 0.1,
        };
        let start = Accumulated {
            linear: Vec3A::new(0.2, -0.1, 0.3),
            ..Default::default()
        };
        let mut rows = Vec::new();
        joint_rows(
            0,
            &geometry,
            (Some(0), &sides[0]),
            (Some(1), &sides[1]),
            None,
            &mut rows,
        );
        let (mut dense, mut acc_dense) = (sides.clone(), vec![start]);
        solve(
            &rows,
            &mut dense,
            &mut acc_dense,
            mode,
            &mut Envelope::default(),
        );
        let mut acc = start;
        let [a, b] = sides.get_disjoint_mut([0, 1]).unwrap();
        super::super::solve::solve_ball(&geometry, a, b, &mut acc, mode);
        assert!((acc.linear - acc_dense[0].linear).length() < 1e-4);
        for (d, s) in dense.iter().zip(&sides) {
            assert!((d.v - s.v).length() < 1e-4 && (d.w - s.w).length() < 1e-4);
        }
    }

    #[test]
    fn a_rigid_hinge_pass_leaves_only_the_turn_about_its_axis() {
        let geometry = Rows {
            angular: Angular::Hinge {
                axis_a: Vec3::Z,
                axis_b: Vec3::Z,
            },
            ..Rows::ball(Vec3A::ZERO, Vec3A::ZERO)
        };
        let mut sides = vec![Side::WORLD, body(Vec3A::ZERO)];
        sides[1].w = Vec3A::new(1.0, -2.0, 3.0);
        let mut rows = Vec::new();
        joint_rows(
            0,
            &geometry,
            (None, &sides[0]),
            (Some(1), &sides[1]),
            None,
            &mut rows,
        );
        let mut acc = vec![Accumulated::default()];
        solve(
            &rows,
            &mut sides,
            &mut acc,
            Mode::RIGID,
            &mut Envelope::default(),
        );
        assert!(
            (sides[1].w - Vec3A::new(0.0, 0.0, 3.0)).length() < 1e-5,
            "{}",
            sides[1].w
        );
    }
}
