//! Revolute joints of a planar serial chain, with chord-to-chord joint angles (docs/knuckle-boom.md).
//!
//! Joint 1 sits at the origin of frame 0; joint i+1 sits at the end of link i's chord, so
//! bending of link i never moves link i+1. Joint i turns about z_i: its twist is `u_i L_{i/i}`
//! with the line `L_{i/i}^i = L_z` (eqs. 6–7), and it carries the in-plane reaction wrench
//! `L ρ_i` with the basis `L = [L_x L_y]` (eqs. 85–87). The generalized coordinate `q_i` is
//! the angle of link i's chord relative to link i−1's chord (relative to x₀ for i = 1).

use nalgebra::Matrix6x2;

use crate::screw::{joint_line, reaction_basis, Screw};

/// A planar revolute joint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RevoluteJoint;

impl RevoluteJoint {
    /// The joint line `L_{j/j}^j` (eq. 7).
    #[must_use]
    pub fn line(&self) -> Screw {
        joint_line()
    }
    /// The basis of its reaction wrench (eq. 87).
    #[must_use]
    pub fn reaction_basis(&self) -> Matrix6x2<f64> {
        reaction_basis()
    }
}
