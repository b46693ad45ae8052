//! Reaction forces in the passive joints (section 5, eqs. 84–98), in the scene's
//! convention.
//!
//! The method of auxiliary generalized speeds: give joint j a fictitious translation along
//! x_j and y_j. It moves every point outboard of the joint with the twist columns of the
//! auxiliary projection (eqs. 88–89)
//!
//! ```text
//! L_{j/i_e}^i = V_{i_e,j}^{i,j} Π L_{j/j}^j,   L_{j/j}^j = [L_x L_y]   (pure translations)
//! ```
//!
//! and the reaction is what the motion of the outboard bodies requires beyond the applied
//! forces on them:
//!
//! ```text
//! ρ_j = Σ_{outboard} P_rᵀ D a  −  Σ_{outboard} P_rᵀ Π (w^{(g)} + w^{ext})
//! ```
//!
//! with `a` the inertial acceleration of each mass point (`P u̇ + Ṗ u` plus the transport
//! term `φ̇ ẑ × v` of its link frame: the full acceleration, velocity products included) —
//! eq. 97 with `M_r ϑ`, `G_r` and `τ_r F` written out per point. `ρ_{2j−1}, ρ_{2j}` is the
//! force that the inboard body exerts on link j through joint j, in the axes of frame j
//! (x along link j's chord; for the pendulum from the pivot to the payload). A pendulum at
//! rest gives `ρ = (−m g, 0)`. Internal forces — strain, modal damping, joint torques — do not
//! enter. External forces are the actuator forces on their pins and, when the lumped cylinder
//! masses hang on springs, the spring–damper forces on the pins; masses that move rigidly with
//! a pin (the paper's eqs. 91–94, or the "rigidly attached" scene) are point masses.

use nalgebra::{DVector, Vector2, Vector3};

use super::{MassPoint, StationKinematics};
use crate::arm::{z_cross, Station};
use crate::projection::Projection;
use crate::reactions::PointLoad;
use crate::screw::{line_x, line_y, rot_z_cs, swap, wrench, Screw, ScrewTransform};

impl MassPoint<'_> {
    /// Inertial acceleration `[0 0 α a_x a_y 0]` of the point, in its link's frame.
    pub(super) fn acceleration(&self, u: &[f64], u_dot: &[f64], modal_offset: usize) -> Screw {
        let pv = self.velocity(u, modal_offset);
        let pa = self.projection.twist(u_dot);
        let a = Vector2::new(pa[3], pa[4]) + pv.a_v + pv.phi_dot * z_cross(&pv.v);
        Screw::new(0.0, 0.0, pa[2], a.x, a.y, 0.0)
    }
}

impl StationKinematics<'_> {
    /// The auxiliary projection columns `V_{i_e,j}^{i,j} Π [L_x L_y]` (eq. 88) of joint j for
    /// a point of link i at `r` (frame 0).
    fn auxiliary_columns(&self, i: usize, j: usize, r: &Vector2<f64>) -> [Screw; 2] {
        let p = self.pose.to_frame(j, &(self.pose.origin(j) - r));
        let (c, s) = self.pose.relative_rotation(j, i);
        let v = ScrewTransform::new(rot_z_cs(c, s), Vector3::new(p.x, p.y, 0.0));
        [v.apply(&swap(&line_x())), v.apply(&swap(&line_y()))]
    }

    /// Inertial acceleration of a station in frame 0 at speeds `u` and accelerations `u_dot`.
    #[must_use]
    pub fn point_acceleration(&self, s: &Station, u: &[f64], u_dot: &[f64]) -> Vector2<f64> {
        let projection = Projection::at(&self.pose, s);
        let mp = MassPoint {
            projection: &projection,
            mass: 1.0,
            inertia: 0.0,
            station: s,
        };
        let a = mp.acceleration(u, u_dot, self.arm().modal_offset(s.link));
        self.pose.to_base(s.link, &Vector2::new(a[3], a[4]))
    }

    /// The reaction forces ρ (2 per joint, eq. 97) at speeds `u` and accelerations `u_dot`,
    /// with external `loads` and extra point masses `rigid_masses` moving with their stations.
    #[must_use]
    pub fn reactions(
        &self,
        u: &[f64],
        u_dot: &[f64],
        loads: &[PointLoad],
        rigid_masses: &[(Station, f64)],
    ) -> DVector<f64> {
        let arm = self.arm();
        let g = arm.gravity();
        let mut rho = DVector::zeros(2 * arm.n_links());
        let extra: Vec<Projection> = rigid_masses
            .iter()
            .map(|(s, _)| Projection::at(&self.pose, s))
            .collect();
        let extra = rigid_masses
            .iter()
            .zip(&extra)
            .map(|((s, m), projection)| MassPoint {
                projection,
                mass: *m,
                inertia: 0.0,
                station: s,
            });
        for p in self.points().chain(extra) {
            let i = p.projection.link();
            let r = self.pose.position(p.station);
            let a = p.acceleration(u, u_dot, arm.modal_offset(i));
            let d_a = super::mass_matrix::inertia_times(&p, &a);
            let gw = self.pose.screw_to_frame(i).apply(&wrench(
                Vector3::new(0.0, -p.mass * g, 0.0),
                Vector3::zeros(),
            ));
            let pi_gw = swap(&gw);
            for j in 0..=i {
                for (c, col) in self.auxiliary_columns(i, j, &r).iter().enumerate() {
                    rho[2 * j + c] += col.dot(&d_a) - col.dot(&pi_gw);
                }
            }
        }
        for load in loads {
            let i = load.station.link;
            let r = self.pose.position(&load.station);
            let w = self.pose.screw_to_frame(i).apply(&wrench(
                Vector3::new(load.force.x, load.force.y, 0.0),
                Vector3::zeros(),
            ));
            let pi_w = swap(&w);
            for j in 0..=i {
                for (c, col) in self.auxiliary_columns(i, j, &r).iter().enumerate() {
                    rho[2 * j + c] -= col.dot(&pi_w);
                }
            }
        }
        rho
    }
}
