//! Generalized gravity forces G (eqs. 45–48) and the gravitational potential, contracted from
//! the links' shape integrals.
//!
//! Each mass point carries the gravity wrench `[0 −m g 0 0 0 0]ᵀ` (eq. 48) at its deformed
//! position `r = o_i + R_i (x, w)`, and `G = Σ Pᵀ Π w^{i(g)}` (eq. 45) is the generalized force
//! of these weights: `G_k = −g Σ m ∂y/∂q_k`. With `∂r/∂q_j = ẑ × (r − o_j)` (j ≤ i) and
//! `∂r/∂q^b_k = ψ_k R_i ŷ`, link i (chord angle φ_i, `(c, s) = (cos φ_i, sin φ_i)`) adds
//!
//! ```text
//! V_g += g (m o_iy + s s₁ + c ∫ρA w)
//! G_j += −g (m (o_ix − o_jx) + c s₁ − s ∫ρA w)       joints j ≤ i
//! G_k += −g c a_k                                     modes k
//! ```
//!
//! with `m = ∫ρA`, `s₁ = ∫ρA x`, `a = ∫ρA ψ` (point masses included), so `G = −∂V_g/∂q`.

use nalgebra::DVector;

use crate::kinematics::ArmKinematics;

impl ArmKinematics<'_> {
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

    /// (G, V_g) in one pass (V_g is as cheap as G, so `potential` only keeps the signature).
    #[must_use]
    pub fn gravity_terms(&self, potential: bool) -> (DVector<f64>, f64) {
        let mut g = DVector::zeros(self.arm().n());
        let v = self.gravity_into(g.as_mut_slice());
        (g, if potential { v } else { 0.0 })
    }

    /// G into `forces` (length n), without allocating; returns V_g.
    pub fn gravity_into(&self, forces: &mut [f64]) -> f64 {
        let arm = self.arm();
        let g = arm.gravity();
        forces.fill(0.0);
        let mut v = 0.0;
        for i in 0..arm.n_links() {
            let si = arm.shape_integrals(i);
            let o = arm.modal_offset(i);
            let qb = self.pose.modal(i);
            let w: f64 = (0..qb.len()).map(|k| si.mode_mass(k) * qb[k]).sum();
            let (c, s) = self.pose.cos_sin(i);
            let (mass, s1) = (si.mass(), si.first_moment());
            let oi = self.pose.origin(i);
            v += g * (mass * oi.y + s * s1 + c * w);
            let arm_x = c * s1 - s * w;
            for (j, fj) in forces.iter_mut().enumerate().take(i + 1) {
                *fj -= g * (mass * (oi.x - self.pose.origin(j).x) + arm_x);
            }
            for k in 0..qb.len() {
                forces[o + k] -= g * c * si.mode_mass(k);
            }
        }
        if arm.has_geometric_stiffening() {
            v += self.add_stiffening_gravity(forces);
        }
        v
    }
}
