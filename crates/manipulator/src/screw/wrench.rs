//! Wrenches (eqs. 14–20) and the screw bases used for them (eqs. 17, 87).
//!
//! A wrench is `[f; n]`: a force through the reference point and a moment about it. Written
//! as `L ρ` with an orthogonal screw basis `L` (eq. 15), the columns of `L` are screws, so the
//! whole basis transforms with the screw transformations (eq. 20).

use nalgebra::{Matrix6, Matrix6x2, Vector3};

use super::{line_x, line_y, Screw};

/// The wrench `[f; n]` (eq. 14).
#[must_use]
pub fn wrench(f: Vector3<f64>, n: Vector3<f64>) -> Screw {
    Screw::new(f.x, f.y, f.z, n.x, n.y, n.z)
}

/// The orthogonal screw basis `L_{j/j}^j = [L_x L_y L_z N_x N_y N_z]` (eq. 17): the identity.
#[must_use]
pub fn screw_basis() -> Matrix6<f64> {
    Matrix6::identity()
}

/// The basis of the reaction wrench of a planar revolute joint `[L_x L_y]` (eq. 87): the
/// wrench `[ρ_x ρ_y 0 0 0 0]ᵀ` of eq. 85 is `L ρ`.
#[must_use]
pub fn reaction_basis() -> Matrix6x2<f64> {
    Matrix6x2::from_columns(&[line_x(), line_y()])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn reaction_basis_spans_the_in_plane_forces() {
        let w = reaction_basis() * Vector2::new(3.0, -4.0);
        assert_eq!(w, wrench(Vector3::new(3.0, -4.0, 0.0), Vector3::zeros()));
        assert_eq!(screw_basis() * w, w);
    }
}
