//! Twists (eqs. 3–7, 13) and the lines and screws of the orthogonal basis (eq. 18).
//!
//! The twist of a revolute joint is `u_j · L_{j/j}` (eq. 6): the joint's speed times its line.
//! A revolute joint of a planar manipulator turns about its frame's z axis, so its line is
//! `L_{z/j} = [0 0 1 0 0 0]ᵀ` ([`joint_line`]).

use nalgebra::Vector3;

use super::Screw;

/// The twist `[ω; v]` (eq. 4).
#[must_use]
pub fn twist(omega: Vector3<f64>, v: Vector3<f64>) -> Screw {
    Screw::new(omega.x, omega.y, omega.z, v.x, v.y, v.z)
}

/// `L_x` of eq. 18: the line along the x axis through the origin.
#[must_use]
pub fn line_x() -> Screw {
    Screw::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
}

/// `L_y` of eq. 18.
#[must_use]
pub fn line_y() -> Screw {
    Screw::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
}

/// `L_z` of eq. 18.
#[must_use]
pub fn line_z() -> Screw {
    Screw::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
}

/// `N_x` of eq. 18: the screw of infinite pitch along x (a translation along x as a twist).
#[must_use]
pub fn screw_n_x() -> Screw {
    Screw::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
}

/// `N_y` of eq. 18.
#[must_use]
pub fn screw_n_y() -> Screw {
    Screw::new(0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
}

/// `N_z` of eq. 18.
#[must_use]
pub fn screw_n_z() -> Screw {
    Screw::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}

/// The line `L_{j/j}^j` of a planar revolute joint (eq. 7): its axis is z_j through the
/// origin of frame j, so its moment is zero.
#[must_use]
pub fn joint_line() -> Screw {
    line_z()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::screw::ReferenceTransform;

    #[test]
    fn joint_line_referenced_elsewhere_gives_the_velocity_of_that_point() {
        // A unit rotation about z through the origin: the point r = (2, 1, 0) moves with
        // v = ẑ × r = (−1, 2, 0). U takes p from the new reference point to the old one.
        let r = Vector3::new(2.0, 1.0, 0.0);
        let l = ReferenceTransform::new(-r).apply(&joint_line());
        assert_eq!(l, twist(Vector3::z(), Vector3::new(-1.0, 2.0, 0.0)));
    }
}
