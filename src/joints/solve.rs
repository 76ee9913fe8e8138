//! A joint's sides, geometry and accumulated impulses during a pass, and its warm start (the
//! rows and their solve are in [`super::block`]).
//!
//! With lever arms r_a, r_b from the centres of mass to the anchors (world frame), the
//! point rows keep Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a at zero. The angular rows keep the
//! chosen components of ω_b − ω_a at zero: both perpendiculars of the hinge axis for a hinge,
//! all three for a weld. A biased pass solves λ = −S_m K⁻¹ (Ċ + β C) − S_i λ_acc (the soft
//! step's coefficients, see [`crate::collision::solver::Softness`]); a relax pass
//! λ = −K⁻¹ Ċ.

use glam::{Mat3A, Quat, Vec3, Vec3A};

use crate::collision::solver::Softness;

/// One side of a joint during a pass.
#[derive(Debug, Clone, Copy)]
pub(super) struct Side {
    pub x: Vec3A,
    pub q: Quat,
    pub v: Vec3A,
    pub w: Vec3A,
    /// Inverse mass per world axis (zero along a locked one, see
    /// [`crate::rigid::LockedAxes`]).
    pub inv_m: Vec3A,
    pub inv_i: Mat3A,
    /// The angular impulse the pass gave it (N·m·s): L += this.
    pub dl: Vec3A,
    /// It takes impulses (a dynamic body awake).
    pub moves: bool,
    /// When the pass turns it with a stiffened inertia (see [`stiffen`]): the map from the
    /// angular impulse the pass gave it to the change of its angular momentum, I I_s⁻¹.
    pub momentum: Option<Mat3A>,
}

impl Side {
    /// The world, or a body that takes no impulse: unmoved, immovable.
    pub const WORLD: Self = Self {
        x: Vec3A::ZERO,
        q: Quat::IDENTITY,
        v: Vec3A::ZERO,
        w: Vec3A::ZERO,
        inv_m: Vec3A::ZERO,
        inv_i: Mat3A::ZERO,
        dl: Vec3A::ZERO,
        moves: false,
        momentum: None,
    };

    /// Takes the linear impulse `p` at lever arm `r` and the angular impulse `l`.
    #[inline]
    pub fn push(&mut self, p: Vec3A, r: Vec3A, l: Vec3A) {
        if !self.moves {
            return;
        }
        let dl = r.cross(p) + l;
        self.v += self.inv_m * p;
        self.w += self.inv_i * dl;
        self.dl += dl;
    }
}

/// What a joint holds besides its anchors.
#[derive(Debug, Clone, Copy)]
pub(super) enum Angular {
    /// Nothing: a ball joint.
    Free,
    /// The hinge axes (each side's shape frame) aligned.
    Hinge { axis_a: Vec3, axis_b: Vec3 },
    /// q_b = q_a · relative.
    Weld { relative: Quat },
}

impl Angular {
    /// Its angular rows: none, two or three.
    pub fn rows(&self) -> usize {
        match self {
            Angular::Free => 0,
            Angular::Hinge { .. } => 2,
            Angular::Weld { .. } => 3,
        }
    }
}

/// Which free axis.
#[derive(Debug, Clone, Copy)]
pub(super) enum Axis {
    /// The turn of `b` relative to `a` about the hinge axis (rad).
    Turn { axis_a: Vec3, axis_b: Vec3 },
    /// The offset of `b`'s anchor from `a`'s along `a`'s axis (m).
    Slide { axis_a: Vec3 },
    /// The distance between the anchors (m).
    Length,
    /// A ball joint's twist: `b`'s turn about its axis once that axis is brought back onto
    /// `a`'s by the shortest arc (rad; the twist of the swing–twist split).
    Twist { axis_a: Vec3, axis_b: Vec3 },
}

/// A ball joint's cone: the angle between the sides' axes (each side's shape frame) kept
/// at most `max` (rad).
#[derive(Debug, Clone, Copy)]
pub(super) struct Swing {
    pub axis_a: Vec3,
    pub axis_b: Vec3,
    pub max: f32,
}

/// A motor spring's target (rad or m), stiffness and damping.
pub(super) type Spring = (f32, f32, f32);

/// A joint's free axis with its limits and motor, if it has one.
#[derive(Debug, Clone, Copy)]
pub(super) struct Axial {
    pub axis: Option<Axis>,
    /// `min ≤ value ≤ max`.
    pub limits: Option<(f32, f32)>,
    /// Target rate (rad/s or m/s), largest force or torque (N or N·m), and a spring's
    /// target, stiffness and damping.
    pub motor: Option<(f32, f32, Option<Spring>)>,
    /// A ball joint's cone limit, if any.
    pub swing: Option<Swing>,
    /// A ball joint's friction: the largest torque resisting any relative turn (N·m).
    pub friction: Option<f32>,
}

impl Axial {
    /// No free axis with rows of its own (a ball joint, a weld).
    pub const NONE: Self = Self {
        axis: None,
        limits: None,
        motor: None,
        swing: None,
        friction: None,
    };

    /// Whether it has any row to solve.
    pub fn active(&self) -> bool {
        self.swing.is_some()
            || self.friction.is_some()
            || (self.axis.is_some() && (self.limits.is_some() || self.motor.is_some()))
    }
}

/// What a joint holds of its anchors' separation.
#[derive(Debug, Clone, Copy)]
pub(super) enum Linear {
    /// All three components: the anchors together.
    Point,
    /// The two perpendicular to `a`'s axis (its shape frame): a slider.
    Slide { axis_a: Vec3 },
    /// None (a distance joint holds its length with its axial rows alone).
    Free,
}

impl Linear {
    /// Its rows: three, two or none.
    pub fn rows(&self) -> usize {
        match self {
            Linear::Point => 3,
            Linear::Slide { .. } => 2,
            Linear::Free => 0,
        }
    }
}

/// A joint's geometry for one pass: lever arms in the world frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rows {
    /// Anchor minus centre of mass, each side's shape frame (a world point for the world).
    pub local_a: Vec3A,
    pub local_b: Vec3A,
    pub angular: Angular,
    pub linear: Linear,
    /// The free axis's limits and motor.
    pub axial: Axial,
}

impl Rows {
    /// A ball joint's rows between the anchors `local_a` and `local_b`.
    pub fn ball(local_a: Vec3A, local_b: Vec3A) -> Self {
        Self {
            local_a,
            local_b,
            angular: Angular::Free,
            linear: Linear::Point,
            axial: Axial::NONE,
        }
    }

    /// The rows solved together with other joints' (all but the axial ones).
    pub fn count(&self) -> usize {
        self.angular.rows() + self.linear.rows()
    }
}

/// The accumulated impulses applied to `b` (and their opposite to `a`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Accumulated {
    pub linear: Vec3A,
    pub angular: Vec3A,
    /// The motor's impulse along the free axis (N·s or N·m·s).
    pub motor: f32,
    /// The lower and upper limits' impulses along the free axis (each ≥ 0, pushing away
    /// from its limit).
    pub lower: f32,
    pub upper: f32,
    /// A ball joint's cone limit's impulse (≥ 0, closing the cone).
    pub swing: f32,
    /// A ball joint's friction's angular impulse (world frame).
    pub friction: Vec3A,
}

/// [`Softness`] for a biased pass, or the rigid solve of a relax pass.
#[derive(Debug, Clone, Copy)]
pub(super) struct Mode {
    pub bias_rate: f32,
    pub mass_scale: f32,
    pub impulse_scale: f32,
}

impl Mode {
    pub const RIGID: Self = Self {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    pub fn soft(s: Softness) -> Self {
        Self {
            bias_rate: s.bias_rate,
            mass_scale: s.mass_scale,
            impulse_scale: s.impulse_scale,
        }
    }

    /// The mode for rows solved exactly together: the soft step's bias rate with the full
    /// effective mass and nothing of the held impulse let go.
    ///
    /// The soft step's two scales make a joint a stiff spring, which a pass one joint after
    /// another needs to converge; they also let a load stretch it, C = a / ω² for the
    /// acceleration a its bodies carry, which the relax pass does not take back (a light
    /// forearm under a pile of ragdolls parted by 7.7 mm at 60 Hz). A group solved as one
    /// system converges in one pass, so it holds the whole load and closes C at the bias
    /// rate; the relax pass then takes away the velocity the bias left, so the correction
    /// moves positions without adding energy (Box2D's relax, as for the soft step).
    #[must_use]
    pub fn exact(self) -> Self {
        Self {
            mass_scale: 1.0,
            impulse_scale: 0.0,
            ..self
        }
    }
}

/// The arms r_a, r_b (world frame) and the anchors' separation p_b − p_a.
#[inline]
fn arms(rows: &Rows, a: &Side, b: &Side) -> (Vec3A, Vec3A, Vec3A) {
    let r_a = a.q * rows.local_a;
    let r_b = b.q * rows.local_b;
    (r_a, r_b, (b.x + r_b) - (a.x + r_a))
}

/// The lever arm of the linear rows on `a`: to its anchor, or for a slider to `b`'s anchor
/// (where the slider's rows act on the rail).
#[inline]
pub(super) fn lever_a(rows: &Rows, r_a: Vec3A, gap: Vec3A) -> Vec3A {
    match rows.linear {
        Linear::Slide { .. } => r_a + gap,
        _ => r_a,
    }
}

/// Applies the accumulated impulses again (the warm start of a substep). A hinge's angular
/// impulse is first projected off its axis as it now stands: it was found perpendicular to
/// the axis of the last substep, and the part of it along the turned axis would spin the
/// hinge, which its rows leave free (a spinning wheel on a swinging arm gained speed that
/// way, past what its motor could hold).
pub(super) fn warm_start(rows: &Rows, acc: &mut Accumulated, a: &mut Side, b: &mut Side) {
    let (r_a, r_b, gap) = arms(rows, a, b);
    if let Angular::Hinge { axis_a, .. } = rows.angular {
        let axis = a.q * Vec3A::from(axis_a);
        acc.angular -= axis * axis.dot(acc.angular);
    }
    a.push(-acc.linear, lever_a(rows, r_a, gap), -acc.angular);
    b.push(acc.linear, r_b, acc.angular);
}

/// Solves a ball joint's three rows on their own: K λ = −S_m (Ċ + β C) − S_i λ_acc with
/// K = Σ (m⁻¹ 1 − [r]× I⁻¹ [r]×) over the moving sides (the same answer as
/// [`super::block::solve`] on its rows, without assembling them).
pub(super) fn solve_ball(
    rows: &Rows,
    a: &mut Side,
    b: &mut Side,
    acc: &mut Accumulated,
    mode: Mode,
) {
    let (r_a, r_b, gap) = arms(rows, a, b);
    let mut k = Mat3A::ZERO;
    for (side, r) in [(&*a, r_a), (&*b, r_b)] {
        if side.moves {
            let skew = Mat3A::from_cols(
                Vec3A::new(0.0, r.z, -r.y),
                Vec3A::new(-r.z, 0.0, r.x),
                Vec3A::new(r.y, -r.x, 0.0),
            );
            k += Mat3A::from_diagonal(side.inv_m.into()) - skew * side.inv_i * skew;
        }
    }
    let k = free_of_locks(k);
    let det = k.determinant();
    if !(det.is_finite() && det > 0.0) {
        return;
    }
    let cdot = (b.v + b.w.cross(r_b)) - (a.v + a.w.cross(r_a));
    let lambda = k.inverse() * (-mode.mass_scale * (cdot + mode.bias_rate * gap))
        - mode.impulse_scale * acc.linear;
    if !lambda.is_finite() {
        return;
    }
    a.push(-lambda, r_a, Vec3A::ZERO);
    b.push(lambda, r_b, Vec3A::ZERO);
    acc.linear += lambda;
}

/// Adds the geometric stiffness of the joints pulling on a body to its inertia for the pass:
/// I_s = I + h² K, with K = Σ |F| |r| (1 − r̂ r̂ᵀ) over the forces F (last substep's) acting
/// at lever arms r.
///
/// Why: a light body pulled hard at its anchors, a link of a chain under a heavy load, has a
/// stiff mode, its turning back into line with the pull, of ω² = K / I. At 1:1000 that mode
/// runs near 900 rad/s, past what a substep of 1/240 s can follow (ω h < 2), and the pass,
/// which sees the pull only through lever arms fixed for the substep, feeds it until the
/// chain tears. Turned with I + h² K, the mode's ω h stays below 1 (the implicit step's
/// answer for the pull's change with the turn, as in Andrews, Teichmann and Kry,
/// "Geometric stiffness for real-time constrained multibody dynamics", 2017); a body whose
/// own inertia dwarfs h² K (a pendulum rod: 1e-4 of I) turns as before.
///
/// `stiffness` is K; returns false (and leaves the side alone) when there is nothing to add.
pub(super) fn stiffen(side: &mut Side, stiffness: Mat3A, h: f32) -> bool {
    let Some(inertia) = invert(side.inv_i) else {
        return false;
    };
    let Some(inv_stiffened) = invert(inertia + stiffness * (h * h)) else {
        return false;
    };
    side.momentum = Some(inertia * inv_stiffened);
    side.inv_i = inv_stiffened;
    true
}

/// The geometric stiffness K of a force `f` acting at lever arm `r`: |F| |r| (1 − r̂ r̂ᵀ).
#[must_use]
pub(super) fn geometric_stiffness(f: Vec3A, r: Vec3A) -> Mat3A {
    let (r_len, f_len) = (r.length(), f.length());
    if !(r_len > 0.0 && f_len.is_finite() && f_len > 0.0) {
        return Mat3A::ZERO;
    }
    let k = f_len / r_len;
    // |F| |r| (1 − r rᵀ / |r|²) = (|F| / |r|) (|r|² 1 − r rᵀ).
    (Mat3A::from_diagonal(Vec3::splat(r_len * r_len)) - outer(r, r)) * k
}

fn outer(a: Vec3A, b: Vec3A) -> Mat3A {
    Mat3A::from_cols(a * b.x, a * b.y, a * b.z)
}

/// `k` with 1 on the diagonal of each row and column that is exactly zero: a world axis
/// that [`crate::rigid::LockedAxes`] keeps both sides from moving along. Its λ then moves
/// nothing, and the other axes are solved as if it were not there (otherwise the singular
/// `k` would leave the whole joint unsolved).
#[must_use]
pub(super) fn free_of_locks(mut k: Mat3A) -> Mat3A {
    if k == Mat3A::ZERO {
        return k;
    }
    for i in 0..3 {
        let row = Vec3A::new(k.x_axis[i], k.y_axis[i], k.z_axis[i]);
        if row == Vec3A::ZERO && k.col(i) == Vec3A::ZERO {
            k.col_mut(i)[i] = 1.0;
        }
    }
    k
}

/// The inverse of a symmetric positive definite 3 × 3, or None when it is not invertible.
fn invert(m: Mat3A) -> Option<Mat3A> {
    let det = m.determinant();
    (det.is_finite() && det > 0.0).then(|| m.inverse())
}
