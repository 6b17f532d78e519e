//! 3-vectors and 3x3 matrices of four `f64` lanes ([`wide::f64x4`]): the force kernel evaluates
//! four tetrahedra at once, one per lane, with the same formulas as the scalar `glam` code.

use rapier3d::glamx::{DMat3, DVec3};
use std::ops::{Add, AddAssign, Mul, Neg, Sub};
pub use wide::f64x4;

/// Number of lanes.
pub const LANES: usize = 4;

/// A 3-vector of four lanes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3x4 {
    /// x components.
    pub x: f64x4,
    /// y components.
    pub y: f64x4,
    /// z components.
    pub z: f64x4,
}

/// A 3x3 matrix of four lanes, stored by columns like `glam::DMat3`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mat3x4 {
    /// The three columns.
    pub cols: [Vec3x4; 3],
}

impl Vec3x4 {
    /// All lanes zero.
    pub const ZERO: Self = Self::splat(DVec3::ZERO);

    /// The same vector in every lane.
    pub const fn splat(v: DVec3) -> Self {
        Self {
            x: f64x4::splat(v.x),
            y: f64x4::splat(v.y),
            z: f64x4::splat(v.z),
        }
    }

    /// Lane `i` of each component comes from `values[i]`.
    #[inline(always)]
    pub fn from_lanes(values: [DVec3; LANES]) -> Self {
        Self {
            x: f64x4::new(values.map(|v| v.x)),
            y: f64x4::new(values.map(|v| v.y)),
            z: f64x4::new(values.map(|v| v.z)),
        }
    }

    /// The vector of each lane.
    #[inline(always)]
    pub fn to_lanes(self) -> [DVec3; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|i| DVec3::new(x[i], y[i], z[i]))
    }

    /// Lane-wise dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> f64x4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Lane-wise cross product.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

impl Add for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl Mul<f64x4> for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: f64x4) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Mat3x4 {
    /// The identity in every lane.
    pub const IDENTITY: Self = Self::splat(DMat3::IDENTITY);

    /// The same matrix in every lane.
    pub const fn splat(m: DMat3) -> Self {
        Self {
            cols: [
                Vec3x4::splat(m.x_axis),
                Vec3x4::splat(m.y_axis),
                Vec3x4::splat(m.z_axis),
            ],
        }
    }

    /// A matrix from its columns.
    #[inline(always)]
    pub fn from_cols(a: Vec3x4, b: Vec3x4, c: Vec3x4) -> Self {
        Self { cols: [a, b, c] }
    }

    /// Lane `i` comes from `values[i]`.
    #[inline(always)]
    pub fn from_lanes(values: [DMat3; LANES]) -> Self {
        Self::from_cols(
            Vec3x4::from_lanes(values.map(|m| m.x_axis)),
            Vec3x4::from_lanes(values.map(|m| m.y_axis)),
            Vec3x4::from_lanes(values.map(|m| m.z_axis)),
        )
    }

    /// The matrix of each lane.
    #[inline(always)]
    pub fn to_lanes(self) -> [DMat3; LANES] {
        let [a, b, c] = self.cols.map(Vec3x4::to_lanes);
        std::array::from_fn(|i| DMat3::from_cols(a[i], b[i], c[i]))
    }

    /// The matrix of lane `lane` alone.
    #[inline(always)]
    pub fn lane(&self, lane: usize) -> DMat3 {
        let column = |c: &Vec3x4| {
            DVec3::new(
                c.x.as_array()[lane],
                c.y.as_array()[lane],
                c.z.as_array()[lane],
            )
        };
        DMat3::from_cols(
            column(&self.cols[0]),
            column(&self.cols[1]),
            column(&self.cols[2]),
        )
    }

    /// Lane-wise transpose.
    #[inline(always)]
    pub fn transpose(&self) -> Self {
        let [a, b, c] = self.cols;
        Self::from_cols(
            Vec3x4 {
                x: a.x,
                y: b.x,
                z: c.x,
            },
            Vec3x4 {
                x: a.y,
                y: b.y,
                z: c.y,
            },
            Vec3x4 {
                x: a.z,
                y: b.z,
                z: c.z,
            },
        )
    }

    /// Lane-wise matrix times vector.
    #[inline(always)]
    pub fn mul_vec(&self, v: Vec3x4) -> Vec3x4 {
        self.cols[0] * v.x + self.cols[1] * v.y + self.cols[2] * v.z
    }

    /// Lane-wise trace.
    #[inline(always)]
    pub fn trace(&self) -> f64x4 {
        self.cols[0].x + self.cols[1].y + self.cols[2].z
    }

    /// Lane-wise determinant.
    #[inline(always)]
    pub fn determinant(&self) -> f64x4 {
        self.cols[2].dot(self.cols[0].cross(self.cols[1]))
    }

    /// Lane-wise `(M + Mᵀ)/2`.
    #[inline(always)]
    pub fn symmetric_part(&self) -> Self {
        (*self + self.transpose()) * f64x4::splat(0.5)
    }

    /// Lane-wise `Mᵀ N`: entry `(i, j)` is column `i` of `M` dotted with column `j` of `N`,
    /// cheaper than forming the transpose.
    #[inline(always)]
    pub fn transpose_mul(&self, n: &Self) -> Self {
        let m = &self.cols;
        let column = |c: Vec3x4| Vec3x4 {
            x: m[0].dot(c),
            y: m[1].dot(c),
            z: m[2].dot(c),
        };
        Self::from_cols(column(n.cols[0]), column(n.cols[1]), column(n.cols[2]))
    }

    /// Lane-wise `I * s + self`, adding `s` on the diagonal.
    #[inline(always)]
    pub fn add_diagonal(mut self, s: f64x4) -> Self {
        self.cols[0].x += s;
        self.cols[1].y += s;
        self.cols[2].z += s;
        self
    }

    /// Lane-wise cofactor matrix `det(M) M⁻ᵀ`.
    #[inline(always)]
    pub fn cofactor(&self) -> Self {
        let [a, b, c] = self.cols;
        Self::from_cols(b.cross(c), c.cross(a), a.cross(b))
    }
}

impl AddAssign for Vec3x4 {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl Add for Mat3x4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::from_cols(
            self.cols[0] + o.cols[0],
            self.cols[1] + o.cols[1],
            self.cols[2] + o.cols[2],
        )
    }
}

impl Sub for Mat3x4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::from_cols(
            self.cols[0] - o.cols[0],
            self.cols[1] - o.cols[1],
            self.cols[2] - o.cols[2],
        )
    }
}

impl Mul<f64x4> for Mat3x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: f64x4) -> Self {
        Self::from_cols(self.cols[0] * s, self.cols[1] * s, self.cols[2] * s)
    }
}

impl Mul for Mat3x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::from_cols(
            self.mul_vec(o.cols[0]),
            self.mul_vec(o.cols[1]),
            self.mul_vec(o.cols[2]),
        )
    }
}
