//! The mass matrix M(q) (eq. 42) and the kinetic energy T (eq. 41), contracted from the
//! links' shape integrals.
//!
//! `M = Σ_i ∫ Pᵀ D_e P dx + Σ_point masses Pᵀ D P` with `D_e = diag(ρI, ρA I)` (eq. 40; planar
//! motion uses only the zz entry of the rotational block). The columns of a point of link i
//! are `∂v/∂u_j = ẑ × d_j = (−(c_jy + w), c_jx + x)`, `∂ω/∂u_j = 1` for its joints j ≤ i and
//! `∂v/∂u^b_k = ψ_k ŷ`, `∂ω/∂u^b_k = θ_k` for its modes (see [`kinematics`](crate::kinematics)),
//! so link i adds
//!
//! ```text
//! M_jl += m c_j·c_l + (c_jx + c_lx) s₁ + s₂ + (c_jy + c_ly) ∫ρA w + ∫ρA w² + ∫ρI     j, l ≤ i
//! M_jk += c_jx a_k + b_k + ∫ρI θ_k                                                   mode k
//! M_kl += P_kl + ∫ρI θ_k θ_l
//! ```
//!
//! with `m = ∫ρA`, `s₁ = ∫ρA x`, `s₂ = ∫ρA x²`, `a = ∫ρA ψ`, `b = ∫ρA x ψ`, `P = ∫ρA ψψᵀ`
//! (point masses included: [`ShapeIntegrals`](crate::ShapeIntegrals)). With
//! `v = (V_x − Ω w, V_y + Ω x + ẇ)` and `ω = Ω + θ·u^b`, `T = ½∫ρA |v|² + ½∫ρI ω²` likewise.

use nalgebra::DMatrix;

use crate::kinematics::ArmKinematics;

impl ArmKinematics<'_> {
    /// M(q) of eq. 42 (n×n, symmetric positive definite for a well-posed arm).
    #[must_use]
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        let n = self.arm().n();
        let mut m = DMatrix::zeros(n, n);
        self.mass_matrix_into(&mut m);
        m
    }

    /// M(q) into `m` (n×n), without allocating.
    ///
    /// # Panics
    /// If `m` is not n×n.
    pub fn mass_matrix_into(&self, m: &mut DMatrix<f64>) {
        let arm = self.arm();
        let n = arm.n();
        assert_eq!(m.shape(), (n, n), "M must be n×n");
        // column-major: M[(r, c)] at c n + r
        let ms = m.as_mut_slice();
        ms.fill(0.0);
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            let o = arm.modal_offset(i);
            let qb = self.pose.modal(i);
            let (w, w_w) = g.deflection_and_square(qb);
            let (mass, s1, s2) = (g.mass(), g.first_moment(), g.second_moment());
            let common = s2 + w_w + g.rotary();
            for j in 0..=i {
                let cj = self.pose.chord_offset(i, j);
                for l in 0..=j {
                    let cl = self.pose.chord_offset(i, l);
                    let v = mass * cj.dot(&cl) + (cj.x + cl.x) * s1 + (cj.y + cl.y) * w + common;
                    ms[l * n + j] += v;
                    if l != j {
                        ms[j * n + l] += v;
                    }
                }
                for (k, c) in g.joint_mode_constants().iter().enumerate() {
                    let v = cj.x * c[0] + c[1] + c[2];
                    ms[(o + k) * n + j] += v;
                    ms[j * n + o + k] += v;
                }
            }
            // the modes' own block, constant: link i alone writes it (0 + (P + ∫ρI θθᵀ))
            let mm = qb.len();
            if mm > 0 {
                for (l, col) in g.modal_mass().chunks_exact(mm).enumerate() {
                    ms[(o + l) * n + o..(o + l) * n + o + mm].copy_from_slice(col);
                }
            }
        }
        if arm.has_geometric_stiffening() {
            self.add_stiffening_mass(m);
        }
    }

    /// T = ½ uᵀ M u (eq. 41) at speeds `u`.
    #[must_use]
    pub fn kinetic_energy(&self, u: &[f64]) -> f64 {
        let arm = self.arm();
        let mut t = 0.0;
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            let (qb, ub) = self.modal(i, u);
            let d = g.deflection_moments(qb, ub);
            let f = self.link_motion(i, u);
            let (om, v) = (f.omega, f.v);
            // ∫ρA |v|², v = (V_x − Ω w, V_y + Ω x + ẇ)
            let translation = g.mass() * v.norm_squared() - 2.0 * v.x * om * d.w
                + om * om * (d.w_w + g.second_moment())
                + d.w_dot_w_dot
                + 2.0 * v.y * (om * g.first_moment() + d.w_dot)
                + 2.0 * om * d.x_w_dot;
            // ∫ρI ω², ω = Ω + θ·u^b
            let mut rotation = g.rotary() * om * om;
            for (k, uk) in ub.iter().enumerate() {
                rotation += 2.0 * om * g.rotary_mode(k) * uk;
                for (l, ul) in ub.iter().enumerate() {
                    rotation += uk * g.rotary_product(k, l) * ul;
                }
            }
            t += 0.5 * (translation + rotation);
        }
        if arm.has_geometric_stiffening() {
            t += self.stiffening_kinetic_energy(u);
        }
        t
    }
}
