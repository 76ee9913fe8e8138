//! Four contact manifolds at a time: 3-vectors, 3×3 matrices and quaternions whose
//! components are `f32x4` lanes (one lane per manifold). Every operation is the lane-wise
//! IEEE operation of the scalar formula, so results are the same on every run.

use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use glam::{Mat3A, Quat, Vec3A};
use wide::f32x4;

/// Four scalars, one per lane.
pub(crate) type F4 = f32x4;

/// Four 3-vectors in structure-of-arrays form.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct V3 {
    pub x: F4,
    pub y: F4,
    pub z: F4,
}

impl V3 {
    /// Lane `i` holds `v[i]`.
    #[inline]
    #[must_use]
    pub fn from_lanes(v: [Vec3A; 4]) -> Self {
        // A 4×4 register transpose (the fourth component is padding).
        let [x, y, z, _] = F4::transpose(v.map(|v| F4::new(v.extend(0.0).to_array())));
        Self { x, y, z }
    }

    /// The four vectors, lane by lane.
    #[inline]
    #[must_use]
    pub fn lanes(self) -> [Vec3A; 4] {
        let t = F4::transpose([self.x, self.y, self.z, F4::ZERO]);
        t.map(|l| Vec3A::from_vec4(glam::Vec4::from_array(l.to_array())))
    }

    #[inline]
    #[must_use]
    pub fn dot(self, o: Self) -> F4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Component by component: (x₁x₂, y₁y₂, z₁z₂).
    #[inline]
    #[must_use]
    pub fn scale(self, o: Self) -> Self {
        Self {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    #[inline]
    #[must_use]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

impl Add for V3 {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3 {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for V3 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl AddAssign for V3 {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl SubAssign for V3 {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

/// Lane-wise scaling.
impl Mul<V3> for F4 {
    type Output = V3;
    #[inline]
    fn mul(self, v: V3) -> V3 {
        V3 {
            x: self * v.x,
            y: self * v.y,
            z: self * v.z,
        }
    }
}

/// Four 3×3 matrices, by columns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct M3 {
    pub cols: [V3; 3],
}

impl M3 {
    /// Lane `i` holds `m[i]`.
    #[inline]
    #[must_use]
    pub fn from_lanes(m: [&Mat3A; 4]) -> Self {
        let col = |c: usize| V3::from_lanes(std::array::from_fn(|i| m[i].col(c)));
        Self {
            cols: [col(0), col(1), col(2)],
        }
    }

    /// M v, lane by lane (the same sums in the same order as glam's `Mat3A * Vec3`).
    #[inline]
    #[must_use]
    pub fn mul_vec(&self, v: V3) -> V3 {
        v.x * self.cols[0] + v.y * self.cols[1] + v.z * self.cols[2]
    }
}

/// Four unit quaternions: vector part and scalar part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Q4 {
    pub v: V3,
    pub w: F4,
}

impl Q4 {
    /// Lane `i` holds `q[i]`.
    #[inline]
    #[must_use]
    pub fn from_lanes(q: [Quat; 4]) -> Self {
        let [x, y, z, w] = F4::transpose(q.map(|q| F4::new(q.to_array())));
        Self {
            v: V3 { x, y, z },
            w,
        }
    }

    /// Rᵀ v, lane by lane, for the rotation R of each (unit) quaternion: with t = 2 u × v,
    /// Rᵀ v = v − w t + u × t (u the vector part; R v has + w t).
    #[inline]
    #[must_use]
    pub fn inverse_rotate(&self, v: V3) -> V3 {
        let u = self.v;
        let t = F4::splat(2.0) * u.cross(v);
        v - self.w * t + u.cross(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes_of(v: [Vec3A; 4]) -> V3 {
        V3::from_lanes(v)
    }

    #[test]
    fn lane_operations_match_the_scalar_formulas() {
        let a = [
            Vec3A::new(1.0, 2.0, 3.0),
            Vec3A::new(-1.0, 0.5, 2.0),
            Vec3A::new(0.0, 0.0, 1.0),
            Vec3A::new(4.0, -3.0, 0.25),
        ];
        let b = [Vec3A::X, Vec3A::new(0.3, 0.7, -0.2), Vec3A::Y, Vec3A::ONE];
        let (va, vb) = (lanes_of(a), lanes_of(b));
        let dots = va.dot(vb).to_array();
        let crosses = va.cross(vb).lanes();
        let sums = (va + vb).lanes();
        let m = [
            Mat3A::from_cols_array(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]),
            Mat3A::IDENTITY,
            Mat3A::from_diagonal(glam::Vec3::new(2.0, 3.0, 4.0)),
            Mat3A::from_quat(glam::Quat::from_rotation_y(0.7)),
        ];
        let mv = M3::from_lanes([&m[0], &m[1], &m[2], &m[3]])
            .mul_vec(va)
            .lanes();
        for i in 0..4 {
            assert_eq!(dots[i], a[i].dot(b[i]));
            assert_eq!(crosses[i], a[i].cross(b[i]));
            assert_eq!(sums[i], a[i] + b[i]);
            let want = m[i] * a[i];
            assert!((want - mv[i]).length() < 1e-6, "lane {i}");
        }
    }

    #[test]
    fn a_quaternion_lane_turns_a_vector_back_as_the_transposed_matrix_does() {
        let q = [
            Quat::IDENTITY,
            Quat::from_rotation_y(0.7),
            Quat::from_axis_angle(glam::Vec3::new(1.0, -2.0, 0.5).normalize(), 2.9),
            Quat::from_rotation_x(-1.3) * Quat::from_rotation_z(0.4),
        ];
        let v = [Vec3A::X, Vec3A::new(0.3, 0.7, -0.2), Vec3A::Y, Vec3A::ONE];
        let turned = Q4::from_lanes(q).inverse_rotate(lanes_of(v)).lanes();
        for i in 0..4 {
            let want = Mat3A::from_quat(q[i]).transpose() * v[i];
            assert!(
                (want - turned[i]).length() < 1e-6,
                "lane {i}: {want} {}",
                turned[i]
            );
            // Not the forward turn (except for the identity).
            if i > 0 {
                assert!((Mat3A::from_quat(q[i]) * v[i] - turned[i]).length() > 1e-3);
            }
        }
    }
}
