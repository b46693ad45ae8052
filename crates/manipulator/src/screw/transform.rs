//! Screw transformations: reference `U` (eq. 9), coordinates `R̄` (eq. 11), both `V` (eq. 12).
//!
//! Notation as in the paper: `U_{k,j}^j` moves the reference point of a screw given in the
//! coordinates of frame j from the origin of j to the origin of k, with `p = p_{k,j}^j` the
//! vector *from k to j* in the coordinates of j; `R̄_j^k` re-expresses a screw from the
//! coordinates of j in those of k; `V_{k,j}^{k,j} = R̄_j^k U_{k,j}^j` does both. For a twist
//! `[ω; v]`, `U` gives the velocity of the new reference point, `v_k = v_j + p × ω`; for a
//! wrench `[f; n]`, the moment about it, `n_k = n_j + p × f`.

use nalgebra::{Matrix3, Matrix6, Vector3};

use super::Screw;

/// Rotation about z by `angle` (rad): the rotation matrix of a planar frame.
#[must_use]
pub fn rot_z(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    rot_z_cs(c, s)
}

/// `p × a + m`, written out (the hot path of every projection).
fn cross_add(p: &Vector3<f64>, a: [f64; 3], m: [f64; 3]) -> [f64; 3] {
    [
        p.y * a[2] - p.z * a[1] + m[0],
        p.z * a[0] - p.x * a[2] + m[1],
        p.x * a[1] - p.y * a[0] + m[2],
    ]
}

/// `R v`, written out.
fn rotate3(r: &Matrix3<f64>, v: [f64; 3]) -> [f64; 3] {
    [
        r.m11 * v[0] + r.m12 * v[1] + r.m13 * v[2],
        r.m21 * v[0] + r.m22 * v[1] + r.m23 * v[2],
        r.m31 * v[0] + r.m32 * v[1] + r.m33 * v[2],
    ]
}

/// The rotation about z with cosine `c` and sine `s`.
#[must_use]
pub fn rot_z_cs(c: f64, s: f64) -> Matrix3<f64> {
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `U_{k,j}^j` (eq. 9): change of reference point by `p = p_{k,j}^j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceTransform {
    p: Vector3<f64>,
}

impl ReferenceTransform {
    /// `U` for the vector `p` from the new reference point k to the old one j (coordinates of j).
    #[must_use]
    pub fn new(p: Vector3<f64>) -> Self {
        Self { p }
    }
    /// `[a; m] ↦ [a; p × a + m]`.
    #[must_use]
    pub fn apply(&self, s: &Screw) -> Screw {
        let m = cross_add(&self.p, [s[0], s[1], s[2]], [s[3], s[4], s[5]]);
        Screw::new(s[0], s[1], s[2], m[0], m[1], m[2])
    }
    /// The 6×6 matrix `[I 0; p̂ I]`.
    #[must_use]
    pub fn matrix(&self) -> Matrix6<f64> {
        let mut u = Matrix6::identity();
        u.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&self.p.cross_matrix());
        u
    }
    /// `U_{j,k}^j = (U_{k,j}^j)⁻¹`: the reference point moved back.
    #[must_use]
    pub fn inverse(&self) -> Self {
        Self { p: -self.p }
    }
}

/// `R̄_j^k` (eq. 11): change of coordinates by the rotation `R = R_j^k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoordinateTransform {
    r: Matrix3<f64>,
}

impl CoordinateTransform {
    /// `R̄` for the rotation matrix `R_j^k` (coordinates of j to coordinates of k).
    #[must_use]
    pub fn new(r: Matrix3<f64>) -> Self {
        Self { r }
    }
    /// A planar rotation by `angle` about z.
    #[must_use]
    pub fn planar(angle: f64) -> Self {
        Self { r: rot_z(angle) }
    }
    /// `[a; m] ↦ [R a; R m]`.
    #[must_use]
    pub fn apply(&self, s: &Screw) -> Screw {
        let a = rotate3(&self.r, [s[0], s[1], s[2]]);
        let m = rotate3(&self.r, [s[3], s[4], s[5]]);
        Screw::new(a[0], a[1], a[2], m[0], m[1], m[2])
    }
    /// The 6×6 matrix `diag(R, R)`.
    #[must_use]
    pub fn matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.r);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.r);
        m
    }
    /// `R̄_k^j = (R̄_j^k)ᵀ`.
    #[must_use]
    pub fn inverse(&self) -> Self {
        Self {
            r: self.r.transpose(),
        }
    }
}

/// `V_{k,j}^{k,j} = R̄_j^k U_{k,j}^j` (eq. 12): the adjoint map of SE(3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScrewTransform {
    r: Matrix3<f64>,
    p: Vector3<f64>,
}

impl ScrewTransform {
    /// `V` for `R = R_j^k` and `p = p_{k,j}^j`.
    #[must_use]
    pub fn new(r: Matrix3<f64>, p: Vector3<f64>) -> Self {
        Self { r, p }
    }
    /// `R̄ U` applied: `[a; m] ↦ [R a; R (p × a + m)]`.
    #[must_use]
    pub fn apply(&self, s: &Screw) -> Screw {
        let a0 = [s[0], s[1], s[2]];
        let a = rotate3(&self.r, a0);
        let m = rotate3(&self.r, cross_add(&self.p, a0, [s[3], s[4], s[5]]));
        Screw::new(a[0], a[1], a[2], m[0], m[1], m[2])
    }
    /// The 6×6 matrix `R̄ U`.
    #[must_use]
    pub fn matrix(&self) -> Matrix6<f64> {
        CoordinateTransform::new(self.r).matrix() * ReferenceTransform::new(self.p).matrix()
    }
    /// `V_{j,k}^{j,k} = (V_{k,j}^{k,j})⁻¹ = U_{j,k}^j R̄_k^j`.
    #[must_use]
    pub fn inverse(&self) -> Self {
        Self {
            r: self.r.transpose(),
            p: -(self.r * self.p),
        }
    }
    /// The composition `self ∘ other` (apply `other` first).
    #[must_use]
    pub fn then_after(&self, other: &Self) -> Self {
        // R1 (p1 × (R2 (p2 × a + m)) + R2 (p2 × a + m)) with a' = R2 a:
        // = R1 R2 ((R2ᵀ p1 + p2) × a + m)
        Self {
            r: self.r * other.r,
            p: other.r.transpose() * self.p + other.p,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::screw::{interchange, power};
    use proptest::prelude::*;

    fn screw(v: [f64; 6]) -> Screw {
        Screw::from_column_slice(&v)
    }

    proptest! {
        #[test]
        fn a_transform_then_its_inverse_is_the_identity(
            angle in -4.0..4.0f64, px in -5.0..5.0f64, py in -5.0..5.0f64,
            s in proptest::array::uniform6(-3.0..3.0f64),
        ) {
            let s = screw(s);
            let p = Vector3::new(px, py, 0.3);
            let u = ReferenceTransform::new(p);
            let rb = CoordinateTransform::planar(angle);
            let v = ScrewTransform::new(rot_z(angle), p);
            for back in [u.inverse().apply(&u.apply(&s)), rb.inverse().apply(&rb.apply(&s)),
                         v.inverse().apply(&v.apply(&s))] {
                prop_assert!((back - s).norm() < 1e-12);
            }
            prop_assert!((v.matrix() * v.inverse().matrix() - Matrix6::identity()).norm() < 1e-12);
        }

        #[test]
        fn matrices_and_apply_agree_and_v_is_r_bar_u(
            angle in -4.0..4.0f64, p in proptest::array::uniform3(-5.0..5.0f64),
            s in proptest::array::uniform6(-3.0..3.0f64),
        ) {
            let s = screw(s);
            let p = Vector3::from(p);
            let v = ScrewTransform::new(rot_z(angle), p);
            prop_assert!((v.matrix() * s - v.apply(&s)).norm() < 1e-12);
            let rbu = CoordinateTransform::planar(angle).matrix() * ReferenceTransform::new(p).matrix();
            prop_assert!((v.matrix() - rbu).norm() < 1e-12);
        }

        #[test]
        fn power_is_invariant_under_a_common_screw_transformation(
            angle in -4.0..4.0f64, p in proptest::array::uniform3(-5.0..5.0f64),
            t in proptest::array::uniform6(-3.0..3.0f64), w in proptest::array::uniform6(-3.0..3.0f64),
        ) {
            let (t, w) = (screw(t), screw(w));
            let v = ScrewTransform::new(rot_z(angle), Vector3::from(p));
            // Twists and wrenches of the same body and point move together: tᵀΠw is invariant.
            let before = power(&t, &w);
            let after = (v.apply(&t).transpose() * interchange() * v.apply(&w))[0];
            prop_assert!((before - after).abs() < 1e-10 * (1.0 + before.abs()));
        }

        #[test]
        fn composition_is_the_product_of_matrices(
            a1 in -4.0..4.0f64, a2 in -4.0..4.0f64,
            p1 in proptest::array::uniform3(-5.0..5.0f64), p2 in proptest::array::uniform3(-5.0..5.0f64),
        ) {
            let v1 = ScrewTransform::new(rot_z(a1), Vector3::from(p1));
            let v2 = ScrewTransform::new(rot_z(a2), Vector3::from(p2));
            prop_assert!((v1.then_after(&v2).matrix() - v1.matrix() * v2.matrix()).norm() < 1e-10);
        }
    }

    #[test]
    fn reference_change_moves_the_moment_of_a_force() {
        // A force f = (0, −10, 0) at j; about k, 2 m to the left of j (p from k to j = +2 x̂),
        // the moment is p × f = (0, 0, −20).
        let w = Screw::new(0.0, -10.0, 0.0, 0.0, 0.0, 0.0);
        let m = ReferenceTransform::new(Vector3::new(2.0, 0.0, 0.0)).apply(&w);
        assert_eq!(m, Screw::new(0.0, -10.0, 0.0, 0.0, 0.0, -20.0));
    }
}
