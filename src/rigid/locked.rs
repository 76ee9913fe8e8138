//! Locked axes: a body held from moving along, or turning about, chosen world axes (a 2.5D
//! game's bodies in the xy-plane, an upright character).
//!
//! A lock is an ideal constraint, and the motion it leaves is the exact constrained motion:
//!
//! - Translation: the reaction cancels every force and impulse along a locked axis, so the
//!   inverse mass becomes m⁻¹ P with P the projection onto the free axes, and the velocity
//!   along a locked axis stays zero.
//! - Rotation: the reaction torques lie along the locked axes, so ω stays in the free
//!   subspace S and P I ω̇ = P τ there. The response to a torque is (P I P)⁺, the inverse of
//!   I restricted to S, not the projected inverse P I⁻¹ P that rapier and avian use: the two
//!   agree only when the free axes are principal axes of the world tensor. A body whose
//!   principal axes are tilted about a free axis still turns at τ / (e·I e) about it.
//!
//! The rotation locks are copied into [`Inertia`] by hooks, so that every ω = I⁻¹ L in the
//! crate (integrators, contacts, joints, queries of ω) sees them without asking.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Mat3A, Quat, Vec3A};

use super::Inertia;
use crate::core::rest::Simulated;
use crate::particles::{Force, LinearVelocity};

/// World axes a body may not move along or turn about (avian's and rapier's `LockedAxes`).
/// A locked axis takes no force, impulse or contact: the velocity along it stays zero, and
/// a velocity written along it is dropped at the next substep.
///
/// ```
/// use hooke::prelude::*;
/// // A 2.5D game: bodies move in the xy-plane and turn only about z.
/// let planar = LockedAxes::XY_PLANE;
/// assert!(planar.is_translation_locked(2) && planar.is_rotation_locked(0));
/// // An upright character: it never tips over.
/// let upright = LockedAxes::new().lock_rotation_x().lock_rotation_z();
/// assert!(!upright.is_rotation_locked(1));
/// ```
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = locks_inserted, on_remove = locks_removed)]
pub struct LockedAxes(u8);

impl LockedAxes {
    /// Nothing locked.
    pub const NONE: Self = Self(0);
    /// All three translations locked: the body can only turn in place.
    pub const TRANSLATION_LOCKED: Self = Self(0b000_111);
    /// All three rotations locked: the body never turns.
    pub const ROTATION_LOCKED: Self = Self(0b111_000);
    /// Everything locked: contacts, forces and impulses leave the body where it is.
    pub const ALL_LOCKED: Self = Self(0b111_111);
    /// Planar motion in the xy-plane: translation along z and rotation about x and y locked.
    pub const XY_PLANE: Self = Self(0b011_100);

    /// Nothing locked (as [`LockedAxes::NONE`]), to chain `lock_*` calls on.
    #[must_use]
    pub const fn new() -> Self {
        Self::NONE
    }

    /// Also locks translation along world axis `axis` (0 = x, 1 = y, 2 = z; others are
    /// ignored).
    #[must_use]
    pub const fn lock_translation(self, axis: usize) -> Self {
        if axis < 3 {
            Self(self.0 | 1 << axis)
        } else {
            self
        }
    }

    /// Also locks rotation about world axis `axis` (0 = x, 1 = y, 2 = z; others are
    /// ignored).
    #[must_use]
    pub const fn lock_rotation(self, axis: usize) -> Self {
        if axis < 3 {
            Self(self.0 | 8 << axis)
        } else {
            self
        }
    }

    /// Frees translation along world axis `axis`.
    #[must_use]
    pub const fn unlock_translation(self, axis: usize) -> Self {
        if axis < 3 {
            Self(self.0 & !(1 << axis))
        } else {
            self
        }
    }

    /// Frees rotation about world axis `axis`.
    #[must_use]
    pub const fn unlock_rotation(self, axis: usize) -> Self {
        if axis < 3 {
            Self(self.0 & !(8 << axis))
        } else {
            self
        }
    }

    /// Locks translation along x.
    #[must_use]
    pub const fn lock_translation_x(self) -> Self {
        self.lock_translation(0)
    }

    /// Locks translation along y.
    #[must_use]
    pub const fn lock_translation_y(self) -> Self {
        self.lock_translation(1)
    }

    /// Locks translation along z.
    #[must_use]
    pub const fn lock_translation_z(self) -> Self {
        self.lock_translation(2)
    }

    /// Locks rotation about x.
    #[must_use]
    pub const fn lock_rotation_x(self) -> Self {
        self.lock_rotation(0)
    }

    /// Locks rotation about y.
    #[must_use]
    pub const fn lock_rotation_y(self) -> Self {
        self.lock_rotation(1)
    }

    /// Locks rotation about z.
    #[must_use]
    pub const fn lock_rotation_z(self) -> Self {
        self.lock_rotation(2)
    }

    /// Whether translation along world axis `axis` (0–2) is locked.
    #[must_use]
    pub const fn is_translation_locked(self, axis: usize) -> bool {
        axis < 3 && self.0 & (1 << axis) != 0
    }

    /// Whether rotation about world axis `axis` (0–2) is locked.
    #[must_use]
    pub const fn is_rotation_locked(self, axis: usize) -> bool {
        axis < 3 && self.0 & (8 << axis) != 0
    }

    /// Whether some translation is locked.
    #[must_use]
    pub const fn locks_translation(self) -> bool {
        self.0 & 0b111 != 0
    }

    /// The free translations as a mask: 1 along a free axis, 0 along a locked one.
    #[must_use]
    pub fn translation_mask(self) -> Vec3A {
        free_mask(self.0 & 0b111)
    }

    /// The inverse mass per world axis for a body of inverse mass `inverse` (1/kg): zero
    /// along a locked axis.
    #[must_use]
    pub fn inverse_mass(self, inverse: f32) -> Vec3A {
        self.translation_mask() * inverse
    }

    /// [`Self::inverse_mass`] of a body that may have no locks: `inverse` along every axis
    /// then.
    #[must_use]
    pub fn inverse_mass_of(locks: Option<&Self>, inverse: f32) -> Vec3A {
        locks.map_or(Vec3A::splat(inverse), |l| l.inverse_mass(inverse))
    }

    /// The translation bits (0–2: x, y, z).
    #[must_use]
    pub(crate) const fn translation_bits(self) -> u8 {
        self.0 & 0b111
    }

    /// The rotation bits, as [`Inertia`] keeps them.
    const fn rotation_bits(self) -> u8 {
        self.0 >> 3 & 0b111
    }
}

/// 1 for each axis whose bit in `locked` is clear, 0 for a set one.
#[must_use]
pub(crate) fn free_mask(locked: u8) -> Vec3A {
    Vec3A::from_array(std::array::from_fn(|k| {
        f32::from(u8::from(locked & (1 << k) == 0))
    }))
}

/// The inverse of the world tensor `tensor` restricted to the free axes of `locked`
/// (bits 0–2: x, y, z): (P I P)⁺, zero in every locked row and column.
#[must_use]
pub(crate) fn restricted_inverse(tensor: Mat3A, locked: u8) -> Mat3A {
    let (mut free, mut n) = ([0usize; 3], 0);
    for k in 0..3 {
        if locked & (1 << k) == 0 {
            free[n] = k;
            n += 1;
        }
    }
    let at = |r: usize, c: usize| tensor.col(c)[r];
    let mut cols = [Vec3A::ZERO; 3];
    match free[..n] {
        [k] => cols[k][k] = 1.0 / at(k, k),
        [j, k] => {
            let (a, b, d) = (at(j, j), at(j, k), at(k, k));
            let inv_det = 1.0 / (a * d - b * b);
            cols[j][j] = d * inv_det;
            cols[k][k] = a * inv_det;
            cols[k][j] = -b * inv_det;
            cols[j][k] = -b * inv_det;
        }
        [_, _, _] => return tensor.inverse(),
        _ => {}
    }
    if !cols.iter().all(|c| c.is_finite()) {
        return Mat3A::ZERO;
    }
    Mat3A::from_cols(cols[0], cols[1], cols[2])
}

impl Inertia {
    /// ω = (P I P)⁺ L without forming I: the restricted tensor's entries are
    /// Σᵢ pᵢ (bⱼ)ᵢ (bₖ)ᵢ with bⱼ the free world axes in the principal frame. Per body and
    /// substep this is what a locked body's ω costs: forming R I₀ Rᵀ and inverting it took a
    /// planar pyramid's step a quarter more instructions than the unlocked one's.
    pub(super) fn locked_angular_velocity(&self, q: Quat, l: Vec3A) -> Vec3A {
        let p = self.principal;
        if p.x == p.y && p.y == p.z {
            return free_mask(self.locked) * l * self.inverse.x;
        }
        let to_body = (super::unit(q) * self.frame).inverse();
        let axis = |k: usize| to_body * Vec3A::AXES[k];
        let entry = |a: Vec3A, b: Vec3A| (p * a * b).element_sum();
        match self.locked {
            0b011 | 0b101 | 0b110 => {
                let k = (!self.locked & 0b111).trailing_zeros() as usize;
                let b = axis(k);
                let mut w = Vec3A::ZERO;
                w[k] = l[k] / entry(b, b);
                if w.is_finite() { w } else { Vec3A::ZERO }
            }
            0b001 | 0b010 | 0b100 => {
                let (j, k) = match self.locked {
                    0b001 => (1, 2),
                    0b010 => (0, 2),
                    _ => (0, 1),
                };
                let (bj, bk) = (axis(j), axis(k));
                let (a, c, d) = (entry(bj, bj), entry(bj, bk), entry(bk, bk));
                let inv_det = 1.0 / (a * d - c * c);
                let mut w = Vec3A::ZERO;
                w[j] = (d * l[j] - c * l[k]) * inv_det;
                w[k] = (a * l[k] - c * l[j]) * inv_det;
                if w.is_finite() { w } else { Vec3A::ZERO }
            }
            _ => Vec3A::ZERO,
        }
    }

    /// `omega` without its components about locked axes.
    #[must_use]
    pub(crate) fn drop_locked_spin(&self, omega: Vec3A) -> Vec3A {
        omega * free_mask(self.locked)
    }

    /// [`Inertia::world_tensors`] for a body with locked rotations: the full world tensor
    /// (an impulse pass's change of ω times it still gives the free components of the
    /// angular impulse) and the restricted inverse.
    pub(super) fn locked_world_tensors(&self, q: Quat) -> (Mat3A, Mat3A) {
        let free = Self { locked: 0, ..*self };
        let (tensor, inverse) = free.world_tensors(q);
        if self.is_infinite() {
            return (tensor, inverse);
        }
        (tensor, restricted_inverse(tensor, self.locked))
    }
}

/// Keeps [`Inertia`]'s copy of the rotation locks: on a new [`LockedAxes`]...
///
/// A sleeping body wakes when its locks change: what held it may have let go.
fn locks_inserted(mut world: DeferredWorld, ctx: HookContext) {
    copy_locks(&mut world, ctx.entity);
    crate::core::rest::wake(&mut world, ctx.entity);
}

/// ...when it goes...
fn locks_removed(mut world: DeferredWorld, ctx: HookContext) {
    set_inertia_locks(&mut world, ctx.entity, 0);
    crate::core::rest::wake(&mut world, ctx.entity);
}

/// ...and on a new [`Inertia`] (a kind change, a new collider's mass, a user's value).
pub(super) fn lock_inserted_inertia(mut world: DeferredWorld, ctx: HookContext) {
    copy_locks(&mut world, ctx.entity);
}

/// Copies `entity`'s rotation locks (none without a [`LockedAxes`]) into its [`Inertia`].
fn copy_locks(world: &mut DeferredWorld, entity: Entity) {
    let bits = world
        .get::<LockedAxes>(entity)
        .map_or(0, |l| l.rotation_bits());
    set_inertia_locks(world, entity, bits);
}

fn set_inertia_locks(world: &mut DeferredWorld, entity: Entity, bits: u8) {
    if world
        .get::<Inertia>(entity)
        .is_some_and(|i| i.locked != bits)
        && let Some(mut inertia) = world.get_mut::<Inertia>(entity)
    {
        inertia.locked = bits;
    }
}

/// Drops the force and velocity along locked translation axes, after every force is in
/// (so in the stage re-evaluations too) and before the integrators read them.
pub(crate) fn hold_locked_translations(
    mut bodies: Query<(&mut Force, &mut LinearVelocity, &LockedAxes), Simulated>,
) {
    for (mut f, mut v, locks) in &mut bodies {
        if locks.locks_translation() {
            let mask = locks.translation_mask();
            f.bypass_change_detection().0 *= mask;
            if (v.0 * (Vec3A::ONE - mask)) != Vec3A::ZERO {
                v.0 *= mask;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restricted_inverse_is_the_inverse_on_the_free_axes() {
        let q = Quat::from_rotation_y(0.4) * Quat::from_rotation_x(0.7);
        let inertia = Inertia::diagonal(1.0, 2.0, 3.0).unwrap();
        let (tensor, _) = inertia.world_tensors(q);
        for locked in 1..8u8 {
            let inv = restricted_inverse(tensor, locked);
            let p = Mat3A::from_diagonal(free_mask(locked).into());
            // (P I P) (P I P)⁺ = P, and the locked rows and columns are zero.
            let product = p * tensor * p * inv;
            assert!(
                (product - p).abs_diff_eq(Mat3A::ZERO, 1e-5),
                "{locked}: {product}"
            );
            assert_eq!(p * inv * p, inv);
        }
        assert_eq!(restricted_inverse(tensor, 0), tensor.inverse());
    }

    #[test]
    fn the_cheap_angular_velocity_is_the_restricted_inverse_times_l() {
        let q = Quat::from_rotation_z(-0.3) * Quat::from_rotation_x(1.1);
        let frame = Quat::from_rotation_y(0.5);
        let l = Vec3A::new(0.7, -1.3, 2.1);
        for inertia in [
            Inertia::new(glam::Vec3::new(1.0, 2.0, 3.0), frame).unwrap(),
            Inertia::diagonal(2.0, 2.0, 2.0).unwrap(),
        ] {
            for locked in 1..8u8 {
                let body = Inertia { locked, ..inertia };
                let (tensor, _) = inertia.world_tensors(q);
                let want = restricted_inverse(tensor, locked) * l;
                let got = body.angular_velocity(q, l);
                assert!(got.abs_diff_eq(want, 1e-5), "{locked}: {got} vs {want}");
                for k in 0..3 {
                    if locked & (1 << k) != 0 {
                        assert_eq!(got[k], 0.0, "{locked}: locked axis {k}");
                    }
                }
            }
        }
    }
}
