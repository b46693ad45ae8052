//! Generalized gravity forces G (eqs. 45–48) and the gravitational potential.
//!
//! Each mass point carries the gravity wrench `w^{0(g)} = [0 −m g 0 0 0 0]ᵀ` (eq. 48, for a
//! quadrature point `m = w ρA`) at its deformed position, re-expressed in its link's frame,
//! `w^{i(g)} = R̄_0^i w^{0(g)}` (eq. 47), and projected: `G = Σ Pᵀ Π w^{i(g)}` (eq. 45, `Π` applied as [`swap`]). Then
//! `G = −∂V_g/∂q` with `V_g = Σ m g y`.

use nalgebra::{DVector, Vector3};

use super::StationKinematics;
use crate::screw::{swap, wrench};

impl StationKinematics<'_> {
    /// G(q) of eq. 45.
    #[must_use]
    pub fn gravity_forces(&self) -> DVector<f64> {
        self.gravity_terms(false).0
    }

    /// Gravitational potential `V_g = Σ m g y` (J), zero at y = 0.
    #[must_use]
    pub fn gravity_potential(&self) -> f64 {
        self.gravity_terms(true).1
    }

    /// (G, V_g) in one pass (V_g only if `potential`, else 0).
    #[must_use]
    pub fn gravity_terms(&self, potential: bool) -> (DVector<f64>, f64) {
        let arm = self.arm();
        let g = arm.gravity();
        let mut forces = DVector::zeros(arm.n());
        let mut v = 0.0;
        for p in self.points() {
            let w0 = wrench(Vector3::new(0.0, -p.mass * g, 0.0), Vector3::zeros());
            let wi = self.pose.screw_to_frame(p.projection.link()).apply(&w0);
            p.projection
                .add_transpose_times(&swap(&wi), forces.as_mut_slice());
            if potential {
                v += p.mass * g * self.pose.position(p.station).y;
            }
        }
        (forces, v)
    }
}
