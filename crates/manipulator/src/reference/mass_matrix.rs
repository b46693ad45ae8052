//! The mass matrix M(q) (eq. 42) and the kinetic energy T (eq. 41).
//!
//! `M = Σ_i ∫_0^{L_i} Pᵀ D_e P dx + Σ_point masses Pᵀ D P`, with `D_e = diag(ρJ, ρA I)`
//! (eq. 40). For planar motion only `ω_z` is non-zero, so the rotational block enters through
//! its zz entry, the rotary inertia per length ρI; the in-plane entries are irrelevant and
//! set equal to it. The integral is the link's Gauss–Legendre rule (see [`quadrature`]).
//!
//! [`quadrature`]: crate::quadrature

use nalgebra::DMatrix;

use super::{MassPoint, StationKinematics};
use crate::screw::Screw;

/// `D t` for the inertia of a mass point (eq. 40).
pub(super) fn inertia_times(p: &MassPoint<'_>, t: &Screw) -> Screw {
    Screw::new(
        p.inertia * t[0],
        p.inertia * t[1],
        p.inertia * t[2],
        p.mass * t[3],
        p.mass * t[4],
        p.mass * t[5],
    )
}

impl StationKinematics<'_> {
    /// M(q) of eq. 42 (n×n, symmetric positive definite for a well-posed arm).
    #[must_use]
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        let n = self.arm().n();
        let mut m = DMatrix::zeros(n, n);
        for p in self.points() {
            let cols = &p.projection.cols;
            let (j, mass) = (p.inertia, p.mass);
            for (a, ca) in cols {
                let d = [
                    j * ca[0],
                    j * ca[1],
                    j * ca[2],
                    mass * ca[3],
                    mass * ca[4],
                    mass * ca[5],
                ];
                for (b, cb) in cols {
                    m[(*a, *b)] += d[0] * cb[0]
                        + d[1] * cb[1]
                        + d[2] * cb[2]
                        + d[3] * cb[3]
                        + d[4] * cb[4]
                        + d[5] * cb[5];
                }
            }
        }
        m
    }

    /// T = ½ Σ tᵀ D t (eq. 41) at speeds `u`.
    #[must_use]
    pub fn kinetic_energy(&self, u: &[f64]) -> f64 {
        self.points()
            .map(|p| {
                let t = p.projection.twist(u);
                0.5 * t.dot(&inertia_times(&p, &t))
            })
            .sum()
    }
}
