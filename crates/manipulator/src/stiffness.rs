//! The stiffness matrix K (eq. 51) and the strain energy (eq. 50).
//!
//! `U_i = ½ E_i I_i ∫ (∂θ_i/∂x)² dx` with `θ_i' = w_i'' = Σ_k ψ_k'' q_k^b`, so
//! `K = Σ_i E_i I_i ∫ Θ_i'ᵀ Θ_i' dx` is block diagonal over the links' modal coordinates and
//! zero on the joint angles; the blocks are the links' [`ShapeIntegrals::bending`]. For sine
//! modes `K_kk = EI (kπ/L)⁴ L/2` and the modes decouple.
//!
//! [`ShapeIntegrals::bending`]: crate::ShapeIntegrals::bending

use nalgebra::DMatrix;

use crate::arm::PlanarArm;

impl PlanarArm {
    /// K of eq. 51 (n×n, constant).
    #[must_use]
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.n();
        let mut k = DMatrix::zeros(n, n);
        for i in 0..self.n_links() {
            let b = self.shape_integrals(i).bending();
            let o = self.modal_offset(i);
            k.view_mut((o, o), b.shape()).copy_from(b);
        }
        k
    }

    /// Strain energy `½ qᵀ K q` (eq. 50) given K.
    #[must_use]
    pub fn strain_energy(k: &DMatrix<f64>, q: &[f64]) -> f64 {
        let mut e = 0.0;
        for (a, qa) in q.iter().enumerate() {
            for (b, qb) in q.iter().enumerate() {
                e += qa * k[(a, b)] * qb;
            }
        }
        0.5 * e
    }
}
