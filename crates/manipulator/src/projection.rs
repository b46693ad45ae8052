//! Projection matrices (eqs. 24, 38, 73): the twist of a point of the arm is `t = P u`.
//!
//! For the cross-section i_e of link i at distance x (eq. 38):
//!
//! ```text
//! P_{0i_e/i_e}^i = [ L_{1/i_e}^i … L_{i/i_e}^i  0 …  0 …  S_{i_e/i_e}^i  0 … ]
//! L_{j/i_e}^i   = V_{i_e,j}^{i,j} L_{j/j}^j                                  (eq. 35)
//! S_{i_e/i_e}^i = [ L_z θ_k(x) + N_y ψ_k(x) ]_k                              (eq. 36)
//! ```
//!
//! The reference point is the *deformed* position `(x, w(x))` (docs/knuckle-boom.md): `p_{i_e,j}^j`
//! in `V` runs from there to joint j. Expressed in frame 0 instead (`R̄_i^0 P`, eq. 73), the
//! rows `N_c = [0 I₂ 0]` (eq. 72) of the projection are the velocity Jacobian of the point,
//! which gives `J_c` (eq. 71) and the pin velocities of the actuators.
//!
//! A projection is stored by its non-zero columns: joints 1..i and link i's modes.

use nalgebra::{DMatrix, Vector2, Vector3};

use crate::arm::{Pose, Station};
use crate::screw::{joint_line, line_z, rot_z_cs, screw_n_y, Screw, ScrewTransform};

/// The projection matrix of one station, by its non-zero columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Projection {
    n: usize,
    link: usize,
    /// (index in u, column): joints 0..=link first, then the link's modes.
    pub(crate) cols: Vec<(usize, [f64; 6])>,
    /// Moment arms `d_j = R_0^i (r − o_j)` of the station about joints j = 0..=link, in the
    /// coordinates of the link's frame (used for ∂P/∂q).
    arms: Vec<Vector2<f64>>,
}

impl Projection {
    /// `P_{0i_e/i_e}^i` of eq. 38 at a station, in the coordinates of its link's frame.
    #[must_use]
    pub fn at(pose: &Pose<'_>, s: &Station) -> Self {
        let arm = pose.arm();
        let i = s.link;
        let r = pose.position(s);
        let mut columns = Vec::with_capacity(i + 1 + s.psi.len());
        let mut arms = Vec::with_capacity(i + 1);
        let line = joint_line();
        for j in 0..=i {
            // p_{i_e,j}^j: from the station to joint j, in the coordinates of j.
            let pj = pose.to_frame(j, &(pose.origin(j) - r));
            let (c, sn) = pose.relative_rotation(j, i);
            let v = ScrewTransform::new(rot_z_cs(c, sn), Vector3::new(pj.x, pj.y, 0.0));
            columns.push((j, v.apply(&line).into()));
            arms.push(pose.to_frame(i, &(r - pose.origin(j))));
        }
        let o = arm.modal_offset(i);
        for (k, (psi, theta)) in s.psi.iter().zip(&s.theta).enumerate() {
            columns.push((o + k, (line_z() * *theta + screw_n_y() * *psi).into()));
        }
        Self {
            n: arm.n(),
            link: i,
            cols: columns,
            arms,
        }
    }

    /// `P_{0,h/h}^0 = R̄_i^0 P_{0h/h}^i` of eq. 73: the same projection in frame 0.
    #[must_use]
    pub fn in_base_frame(&self, pose: &Pose<'_>) -> Self {
        let rb = pose.screw_to_base(self.link);
        Self {
            cols: self
                .cols
                .iter()
                .map(|(k, c)| (*k, rb.apply(&Screw::from(*c)).into()))
                .collect(),
            ..self.clone()
        }
    }

    /// The link the station is on.
    #[must_use]
    pub fn link(&self) -> usize {
        self.link
    }
    /// Non-zero columns with their index in u.
    pub fn columns(&self) -> impl Iterator<Item = (usize, Screw)> + '_ {
        self.cols.iter().map(|(k, c)| (*k, Screw::from(*c)))
    }
    /// The moment arms `d_j` (frame of the link) about joints 0..=link.
    #[must_use]
    pub fn arms(&self) -> &[Vector2<f64>] {
        &self.arms
    }
    /// The twist `t = P u`.
    #[must_use]
    pub fn twist(&self, u: &[f64]) -> Screw {
        let mut t = [0.0; 6];
        for (k, c) in &self.cols {
            let uk = u[*k];
            t[0] += c[0] * uk;
            t[1] += c[1] * uk;
            t[2] += c[2] * uk;
            t[3] += c[3] * uk;
            t[4] += c[4] * uk;
            t[5] += c[5] * uk;
        }
        Screw::from(t)
    }
    /// `out += Pᵀ w`.
    pub fn add_transpose_times(&self, w: &Screw, out: &mut [f64]) {
        for (k, c) in &self.cols {
            out[*k] +=
                c[0] * w[0] + c[1] * w[1] + c[2] * w[2] + c[3] * w[3] + c[4] * w[4] + c[5] * w[5];
        }
    }
    /// The dense 6×n matrix.
    #[must_use]
    pub fn matrix(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(6, self.n);
        for (k, c) in self.columns() {
            m.column_mut(k).copy_from(&c);
        }
        m
    }
    /// Rows `N_c` (eq. 72) of a frame-0 projection: the 2×n velocity Jacobian of the point.
    #[must_use]
    pub fn velocity_jacobian(&self) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(2, self.n);
        for (k, c) in &self.cols {
            j[(0, *k)] = c[3];
            j[(1, *k)] = c[4];
        }
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Link, PlanarArm};

    fn arm() -> PlanarArm {
        let l1 = Link::beam(10.0, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(3)
            .unwrap();
        let l2 = Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(2)
            .unwrap();
        PlanarArm::new(vec![l1, l2, Link::pendulum(6.0, 5000.0).unwrap()], 9.81).unwrap()
    }

    #[test]
    fn velocity_jacobian_matches_finite_differences_of_the_position() {
        let arm = arm();
        let q = [0.3, -1.9, 0.7, 0.05, -0.02, 0.01, 0.04, -0.03];
        let s = arm.station(1, 3.3).unwrap();
        let pose = arm.pose(&q);
        let j = Projection::at(&pose, &s)
            .in_base_frame(&pose)
            .velocity_jacobian();
        for k in 0..arm.n() {
            let h = 1e-6;
            let (mut qp, mut qm) = (q, q);
            qp[k] += h;
            qm[k] -= h;
            let d = (arm.pose(&qp).position(&s) - arm.pose(&qm).position(&s)) / (2.0 * h);
            assert!(
                (d.x - j[(0, k)]).abs() < 1e-7 && (d.y - j[(1, k)]).abs() < 1e-7,
                "column {k}"
            );
        }
        // the pendulum's columns are zero for a point on link 2
        assert!(j.column(2).norm() == 0.0);
    }

    #[test]
    fn rigid_columns_are_rotations_about_the_joints() {
        let arm = arm();
        let q = [0.3, -1.9, 0.7, 0.05, -0.02, 0.01, 0.04, -0.03];
        let pose = arm.pose(&q);
        let s = arm.station(1, 5.0).unwrap();
        let p = Projection::at(&pose, &s);
        for (j, d) in p.arms().iter().enumerate() {
            let c = p.cols[j].1;
            assert!((c[2] - 1.0).abs() < 1e-15);
            assert!((c[3] + d.y).abs() < 1e-12 && (c[4] - d.x).abs() < 1e-12);
        }
        assert_eq!(p.matrix().ncols(), arm.n());
    }
}
