//! One side of four manifolds during a pass, and its inverse mass.
//!
//! A side's inverse mass is one scalar per lane, except in a batch where some body has a
//! locked translation ([`crate::rigid::LockedAxes`]): there it is a 3-vector per lane, zero
//! along the locked axes ([`LinearMass`] covers both).

use super::{Axis, F4, V3};

/// The inverse mass of one side of four manifolds: [`F4`] (the same along every axis) or
/// [`V3`] (per world axis, for locked translations).
pub(super) trait LinearMass: Copy {
    /// Whether a direction can be vacuous: one that a lock keeps both sides from moving
    /// along, whose effective mass is zero.
    const LOCKS: bool;
    /// The velocity change m⁻¹ (λ d) of an impulse λ along unit directions `d`.
    fn response(self, lambda: F4, d: V3) -> V3;
    /// d·(m⁻¹ d): the side's linear share of the effective mass along `d`.
    fn along(self, d: V3) -> F4;
    /// d·(m⁻¹ e) for d ⊥ e: zero unless a translation is locked.
    fn across(self, d: V3, e: V3) -> F4;
    /// The largest inverse mass over the axes (the body's own 1/m unless all are locked).
    fn largest(self) -> F4;
}

impl LinearMass for F4 {
    const LOCKS: bool = false;

    #[inline(always)]
    fn response(self, lambda: F4, d: V3) -> V3 {
        (self * lambda) * d
    }

    #[inline(always)]
    fn along(self, _: V3) -> F4 {
        self
    }

    #[inline(always)]
    fn across(self, _: V3, _: V3) -> F4 {
        F4::ZERO
    }

    #[inline(always)]
    fn largest(self) -> F4 {
        self
    }
}

impl LinearMass for V3 {
    const LOCKS: bool = true;

    #[inline(always)]
    fn response(self, lambda: F4, d: V3) -> V3 {
        lambda * self.scale(d)
    }

    #[inline(always)]
    fn along(self, d: V3) -> F4 {
        self.scale(d).dot(d)
    }

    #[inline(always)]
    fn across(self, d: V3, e: V3) -> F4 {
        self.scale(d).dot(e)
    }

    #[inline(always)]
    fn largest(self) -> F4 {
        self.x.fast_max(self.y).fast_max(self.z)
    }
}

/// One side of four manifolds during a pass.
#[derive(Clone, Copy)]
pub(super) struct Side<M> {
    pub v: V3,
    pub w: V3,
    pub inv_m: M,
}

impl<M: LinearMass> Side<M> {
    /// Velocity of b's material point against a's at the contact points (lever arms `r_a`,
    /// `r_b`). Its component along a direction d equals d·(v_b − v_a) + ω_b·(r_b × d) −
    /// ω_a·(r_a × d), so the lever products need not be stored.
    #[inline]
    pub fn relative(a: &Self, b: &Self, r_a: V3, r_b: V3) -> V3 {
        (b.v + b.w.cross(r_b)) - (a.v + a.w.cross(r_a))
    }

    /// Applies impulse λ along `d`: −λ to a, +λ to b.
    #[inline]
    pub fn push(a: &mut Self, b: &mut Self, d: V3, axis: &Axis, lambda: F4) {
        a.v -= a.inv_m.response(lambda, d);
        a.w -= lambda * axis.ird_a;
        b.v += b.inv_m.response(lambda, d);
        b.w += lambda * axis.ird_b;
    }
}
