//! The two scalar types of the iteration matrices, f64 for (γ/h)I − J and c64 for
//! ((α + iβ)/h)I − J, with the arithmetic the factors need. Moduli and reciprocals are
//! faer's own functions, so that the refactorisation gives faer's bits.

use std::ops::{Add, AddAssign, Mul, Sub, SubAssign};

use faer::c64;
use faer::traits::math_utils::{abs, recip};
use faer::traits::ComplexField;
use nalgebra::Complex;

pub(crate) trait Scalar:
    ComplexField
    + Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + AddAssign
    + SubAssign
{
    /// v + 0i.
    fn real(v: f64) -> Self;
    /// 1/v (faer's: scaled against overflow for c64).
    fn inv(self) -> Self {
        recip(&self)
    }
    /// Whether |self| > |pivot| (faer's moduli), the test partial pivoting chooses by.
    fn exceeds(self, pivot: Self) -> bool;
    /// Whether both parts are finite.
    fn finite(self) -> bool;
}

impl Scalar for f64 {
    fn real(v: f64) -> Self {
        v
    }
    fn exceeds(self, pivot: Self) -> bool {
        self.abs() > pivot.abs()
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for c64 {
    fn real(v: f64) -> Self {
        Complex::new(v, 0.0)
    }
    fn exceeds(self, pivot: Self) -> bool {
        // |z|² decides unless the two are within round-off of each other; then faer's
        // (scaled) modulus decides, as its pivot search does.
        let (a, b) = (self.norm_sqr(), pivot.norm_sqr());
        if !(a.is_normal() && b.is_normal()) {
            abs(&self) > abs(&pivot)
        } else if a < 0.999_999 * b {
            false
        } else if a > 1.000_001 * b {
            true
        } else {
            abs(&self) > abs(&pivot)
        }
    }
    fn finite(self) -> bool {
        self.re.is_finite() && self.im.is_finite()
    }
}
