//! The interchange operator `Π` (eq. 46) and the power of a wrench on a twist.
//!
//! `Π = [0 I; I 0]` swaps the two halves of a screw: `Π [f; n] = [n; f]`, so that
//! `tᵀ Π w = ω·n + v·f` is the power of the wrench `w` on the twist `t` when both are
//! referenced to the same point and expressed in the same coordinates. This is how the
//! generalized forces `Pᵀ Π w` of eqs. 45, 49, 67 and 68 arise.

use nalgebra::Matrix6;

use super::Screw;

/// `Π` of eq. 46.
#[must_use]
pub fn interchange() -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    for k in 0..3 {
        m[(k, k + 3)] = 1.0;
        m[(k + 3, k)] = 1.0;
    }
    m
}

/// `Π s`: the halves of a screw swapped, `[f; n] ↦ [n; f]`.
#[must_use]
pub fn swap(s: &Screw) -> Screw {
    Screw::new(s[3], s[4], s[5], s[0], s[1], s[2])
}

/// The power `tᵀ Π w` of wrench `w` on twist `t`.
#[must_use]
pub fn power(t: &Screw, w: &Screw) -> f64 {
    t.fixed_rows::<3>(0).dot(&w.fixed_rows::<3>(3))
        + t.fixed_rows::<3>(3).dot(&w.fixed_rows::<3>(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interchange_is_its_own_inverse_and_gives_the_power() {
        let pi = interchange();
        assert_eq!(pi * pi, Matrix6::identity());
        let s = Screw::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        assert_eq!(swap(&s), pi * s);
        let t = Screw::new(0.0, 0.0, 2.0, 1.0, -3.0, 0.0);
        let w = Screw::new(4.0, 5.0, 0.0, 0.0, 0.0, 7.0);
        // ω_z n_z + v·f = 14 + 4 − 15
        assert!((power(&t, &w) - 3.0).abs() < 1e-15);
        assert!(((t.transpose() * pi * w)[0] - 3.0).abs() < 1e-15);
    }
}
