//! The kinetic forces `E = ∂T/∂q` at constant u (eq. 44), the velocity-product term `Ṁu`,
//! and the accelerations `u̇ = M⁻¹(ṗ − Ṁu)` of the momentum form (eq. 43), contracted from
//! the links' shape integrals.
//!
//! With `∂v/∂q_k = δ_k`, `∂v/∂q^b_k = −Ω ψ_k x̂` and `Ṗu = (A_x − Ω ẇ, A_y)`
//! ([`kinematics`](crate::kinematics)), and the link's linear momentum
//! `p = ∫ρA v = (m V_x − Ω ∫ρA w, m V_y + Ω s₁ + ∫ρA ẇ)`, link i adds (ω does not depend on q)
//!
//! ```text
//! E_k    += δ_k · p                                                   joints k ≤ i
//! E_k    += −Ω (V_x a_k − Ω (Pq)_k)                                   modes k
//! (Ṁu)_j += ∫ρA ((d/dt ∂v/∂u_j)·v + ∂v/∂u_j·Ṗu)
//!         = −ċ_jy p_x + ċ_jx p_y − ∫ρA ẇ v_x
//!           − c_jy (m A_x − Ω ∫ρA ẇ) − A_x ∫ρA w + Ω ∫ρA w ẇ + (m c_jx + s₁) A_y   joints j ≤ i
//! (Ṁu)_k += a_k A_y                                                   modes k
//! ```
//!
//! with `ċ_j = Σ_{j<k≤i} u_k ẑ × (c_k − c_j)` and `∫ρA ẇ v_x = V_x ∫ρA ẇ − Ω ∫ρA w ẇ`. The tests
//! check E against central differences of T, Ṁu against differences of M, and both against
//! the per-station [`reference`](crate::reference).

use nalgebra::{DMatrix, DVector, Vector2};

use crate::arm::z_cross;
use crate::cholesky::Cholesky;
use crate::kinematics::ArmKinematics;

impl ArmKinematics<'_> {
    /// E = ∂T/∂q at constant u (eq. 44).
    #[must_use]
    pub fn kinetic_forces(&self, u: &[f64]) -> DVector<f64> {
        let mut e = DVector::zeros(self.arm().n());
        self.kinetic_terms_into(u, e.as_mut_slice(), None);
        e
    }

    /// (E, Ṁ u) at speeds u.
    #[must_use]
    pub fn kinetic_terms(&self, u: &[f64]) -> (DVector<f64>, DVector<f64>) {
        let n = self.arm().n();
        let (mut e, mut mdot_u) = (DVector::zeros(n), DVector::zeros(n));
        self.kinetic_terms_into(u, e.as_mut_slice(), Some(mdot_u.as_mut_slice()));
        (e, mdot_u)
    }

    /// E into `e` and, if given, Ṁu into `mdot_u` (each of length n), without allocating.
    pub fn kinetic_terms_into(&self, u: &[f64], e: &mut [f64], mut mdot_u: Option<&mut [f64]>) {
        let arm = self.arm();
        e.fill(0.0);
        if let Some(md) = mdot_u.as_deref_mut() {
            md.fill(0.0);
        }
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            let o = arm.modal_offset(i);
            let (qb, ub) = self.modal(i, u);
            let d = g.deflection_moments(qb, ub);
            let f = self.link_motion(i, u);
            let (mass, s1, om) = (g.mass(), g.first_moment(), f.omega);
            let p = f.momentum(g, &d);
            let s_total = Vector2::new(f.v.y, -f.v.x); // Σ_{j≤i} u_j c_j
            let (mut u_before, mut s_before) = (0.0, Vector2::zeros());
            for (k, uk) in u.iter().enumerate().take(i + 1) {
                let ck = self.pose.chord_offset(i, k);
                e[k] += (s_before - u_before * ck).dot(&p);
                u_before += uk;
                s_before += *uk * ck;
                if let Some(md) = mdot_u.as_deref_mut() {
                    let c_dot = z_cross(&((s_total - s_before) - (om - u_before) * ck));
                    let wdot_vx = f.v.x * d.w_dot - om * d.w_w_dot;
                    md[k] += -c_dot.y * p.x + c_dot.x * p.y
                        - wdot_vx
                        - ck.y * (mass * f.a.x - om * d.w_dot)
                        - f.a.x * d.w
                        + om * d.w_w_dot
                        + (mass * ck.x + s1) * f.a.y;
                }
            }
            for k in 0..qb.len() {
                let a = g.mode_mass(k);
                e[o + k] -= om * (f.v.x * a - om * g.mode_times_deflection(k, qb));
                if let Some(md) = mdot_u.as_deref_mut() {
                    md[o + k] += a * f.a.y;
                }
            }
        }
        if arm.has_geometric_stiffening() {
            self.add_stiffening_kinetic(u, e, mdot_u);
        }
    }

    /// Accelerations `u̇ = M⁻¹(ṗ − Ṁ u)` given the momentum rate ṗ (eq. 43), or `None` if M is
    /// not positive definite.
    #[must_use]
    pub fn accelerations(&self, u: &[f64], p_dot: &DVector<f64>) -> Option<DVector<f64>> {
        let n = self.arm().n();
        let (_, mdot_u) = self.kinetic_terms(u);
        let mut factor = Cholesky::new(n);
        let mut m = DMatrix::zeros(n, n);
        self.mass_matrix_into(&mut m);
        let mut x = p_dot - mdot_u;
        factor.factor(&m).then(|| {
            factor.solve_in_place(x.as_mut_slice());
            x
        })
    }
}
