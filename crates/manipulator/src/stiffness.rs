//! The stiffness matrix K (eq. 51) and the strain energy (eq. 50).
//!
//! `U_i = ½ E_i I_i ∫ (∂θ_i/∂x)² dx` with `θ_i' = w_i'' = Σ_k ψ_k'' q_k^b`, so
//! `K = Σ_i E_i I_i ∫ Θ_i'ᵀ Θ_i' dx` is block diagonal over the links' modal coordinates and
//! zero on the joint angles. For sine modes `K_kk = EI (kπ/L)⁴ L/2` and the modes decouple.

use nalgebra::DMatrix;

use crate::arm::PlanarArm;

impl PlanarArm {
    /// K of eq. 51 (n×n, constant).
    #[must_use]
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.n();
        let mut k = DMatrix::zeros(n, n);
        for (i, link) in self.links().iter().enumerate() {
            let o = self.modal_offset(i);
            let modes = link.modes();
            for (x, w) in self.quadrature().on(link.length()) {
                let c: Vec<f64> = modes.iter().map(|m| m.curvature(x)).collect();
                for a in 0..modes.len() {
                    for b in 0..modes.len() {
                        k[(o + a, o + b)] += link.bending_stiffness() * w * c[a] * c[b];
                    }
                }
            }
        }
        k
    }

    /// Strain energy `½ qᵀ K q` (eq. 50) given K.
    #[must_use]
    pub fn strain_energy(k: &DMatrix<f64>, q: &[f64]) -> f64 {
        let q = nalgebra::DVector::from_column_slice(q);
        0.5 * q.dot(&(k * &q))
    }
}
