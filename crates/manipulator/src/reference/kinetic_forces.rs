//! The kinetic forces `E = ∂T/∂q` at constant u (eq. 44), the velocity-product term `Ṁ u`,
//! and the accelerations `u̇ = M⁻¹(ṗ − Ṁ u)` of the momentum form (eq. 43).
//!
//! # ∂P/∂q, analytically
//! A rigid column of the projection of a station on link i is `L_{j/i_e}^i = [ẑ; ẑ × d_j]`
//! with the moment arm `d_j` of the station about joint j in frame i (see [`Projection`]);
//! the modal columns do not depend on q. In frame i, turning joint k (j < k ≤ i) turns the
//! inboard joints the other way about joint k, and a modal coordinate of link i moves the
//! station along y_i:
//!
//! ```text
//! ∂d_j/∂q_k   = ẑ × (d_k − d_j)   for j < k ≤ i, else 0
//! ∂d_j/∂q^b_k = ψ_k(x) ŷ           for every j ≤ i (modes of link i)
//! ```
//!
//! so with `v = Σ_j u_j ẑ × d_j + ẇ ŷ` the linear velocity of the station (frame i) and
//! `φ̇_i = Σ_{j≤i} u_j`:
//!
//! ```text
//! ∂v/∂q_k   = −Σ_{j<k} u_j (d_k − d_j)        ∂v/∂q^b_k = −φ̇_i ψ_k x̂
//! E_k       = Σ m v·∂v/∂q_k                  (the rotation ω does not depend on q)
//! Ṗ u       = Σ_k u_k ∂v/∂q_k =: a_v
//! Ṁ u       = Σ (Ṗᵀ D t + Pᵀ D Ṗ u),  (Ṗᵀ D t)_j = m (ẑ × ḋ_j)·v
//! ```
//!
//! The tests check E against central differences of T and Ṁu against differences of M.
//!
//! [`Projection`]: crate::Projection

use nalgebra::{DMatrix, DVector, Vector2};

use super::{MassPoint, StationKinematics};
use crate::arm::z_cross;

/// Velocity terms of one mass point at speeds u (frame of its link).
pub(super) struct PointVelocity {
    /// Linear velocity v.
    pub(super) v: Vector2<f64>,
    /// φ̇_i of the point's link.
    pub(super) phi_dot: f64,
    /// `a_v = Ṗ u` (linear part; the angular part is zero).
    pub(super) a_v: Vector2<f64>,
}

impl MassPoint<'_> {
    /// Velocity terms at speeds u; `on_partial(k, ∂v/∂q_k, v)` is called for every coordinate
    /// k the velocity depends on (joints 1..=i of the chain, then the link's modes).
    pub(super) fn velocity_with(
        &self,
        u: &[f64],
        modal_offset: usize,
        mut on_partial: impl FnMut(usize, Vector2<f64>, &Vector2<f64>),
    ) -> PointVelocity {
        let t = self.projection.twist(u);
        let v = Vector2::new(t[3], t[4]);
        let d = self.projection.arms();
        let i = d.len() - 1;
        let phi_dot: f64 = u[..=i].iter().sum();
        let mut a_v = Vector2::zeros();
        for k in 1..=i {
            let mut dv = Vector2::zeros();
            for j in 0..k {
                dv -= u[j] * (d[k] - d[j]);
            }
            a_v += u[k] * dv;
            on_partial(k, dv, &v);
        }
        for (k, psi) in self.station.psi.iter().enumerate() {
            let dv = Vector2::new(-phi_dot * psi, 0.0);
            a_v += u[modal_offset + k] * dv;
            on_partial(modal_offset + k, dv, &v);
        }
        PointVelocity { v, phi_dot, a_v }
    }

    pub(super) fn velocity(&self, u: &[f64], modal_offset: usize) -> PointVelocity {
        self.velocity_with(u, modal_offset, |_, _, _| ())
    }
}

impl StationKinematics<'_> {
    /// E = ∂T/∂q at constant u (eq. 44).
    #[must_use]
    pub fn kinetic_forces(&self, u: &[f64]) -> DVector<f64> {
        self.kinetic_terms(u).0
    }

    /// (E, Ṁ u) at speeds u.
    #[must_use]
    pub fn kinetic_terms(&self, u: &[f64]) -> (DVector<f64>, DVector<f64>) {
        let arm = self.arm();
        let n = arm.n();
        let mut e = DVector::zeros(n);
        let mut mdot_u = DVector::zeros(n);
        for p in self.points() {
            let i = p.projection.link();
            let o = arm.modal_offset(i);
            let pv = p.velocity_with(u, o, |k, dv, v| e[k] += p.mass * v.dot(&dv));
            // Ṗᵀ D t
            let d = p.projection.arms();
            let w_dot: f64 = p
                .station
                .psi
                .iter()
                .enumerate()
                .map(|(k, s)| s * u[o + k])
                .sum();
            for j in 0..=i {
                let mut d_dot = Vector2::new(0.0, w_dot);
                for k in j + 1..=i {
                    d_dot += u[k] * z_cross(&(d[k] - d[j]));
                }
                mdot_u[j] += p.mass * z_cross(&d_dot).dot(&pv.v);
            }
            // Pᵀ D Ṗu
            for (c, col) in &p.projection.cols {
                mdot_u[*c] += p.mass * (col[3] * pv.a_v.x + col[4] * pv.a_v.y);
            }
        }
        (e, mdot_u)
    }

    /// Accelerations `u̇ = M⁻¹(ṗ − Ṁ u)` given the momentum rate ṗ (eq. 43), or `None` if M is
    /// singular.
    #[must_use]
    pub fn accelerations(&self, u: &[f64], p_dot: &DVector<f64>) -> Option<DVector<f64>> {
        let (_, mdot_u) = self.kinetic_terms(u);
        solve(self.mass_matrix(), &(p_dot - mdot_u))
    }
}

/// Solve `M x = b` for symmetric positive definite M (Cholesky, LU as a fallback).
fn solve(m: DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    match m.clone().cholesky() {
        Some(c) => Some(c.solve(b)),
        None => m.lu().solve(b),
    }
}
