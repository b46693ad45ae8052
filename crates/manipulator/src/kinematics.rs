//! [`ArmKinematics`]: the arm at one configuration, and the motion of each link's frame that
//! the dynamics contract with the link's [`ShapeIntegrals`].
//!
//! # The velocity of a station as coefficients of its features
//! A point of link i sits at `(x, w)` in frame i. With `c_j = R_0^i (o_i − o_j)`
//! ([`Pose::chord_offset`]), its moment arm about joint j is `d_j = c_j + (x, w)`, and the
//! columns of its projection (eq. 38) give the linear velocity (frame i) and the rotation
//!
//! ```text
//! v = Σ_{j≤i} u_j ẑ × d_j + ẇ ŷ = (V_x − Ω w,  V_y + Ω x + ẇ)      ω = Ω + Σ_k θ_k u^b_k
//! Ω = φ̇_i = Σ_{j≤i} u_j                V = Σ_{j≤i} u_j ẑ × c_j
//! ```
//!
//! — linear in the features `φ = [1, x, ψ]` and `χ = [1, θ]` with coefficients that depend
//! on q and u only. Turning joint k ≤ i turns the inboard joints the other way about it,
//! `∂c_j/∂q_k = ẑ × (c_k − c_j)` for j < k, and a modal coordinate moves the point along y_i,
//! so at constant u
//!
//! ```text
//! ∂v/∂q_k   = δ_k = −Σ_{j<k} u_j (c_k − c_j)     (uniform along the link)
//! ∂v/∂q^b_k = −Ω ψ_k x̂
//! Ṗu = Σ_k u_k ∂v/∂q_k = (A_x − Ω ẇ, A_y)        A = Σ_{k≤i} u_k δ_k
//! ```
//!
//! (`LinkMotion`). Every integral of a product of two such fields is a contraction with
//! the Gram matrices G_A, G_I of the link.
//!
//! [`ShapeIntegrals`]: crate::ShapeIntegrals

use nalgebra::Vector2;

use crate::arm::{z_cross, PlanarArm, Pose};
use crate::shape_integrals::{DeflectionMoments, ShapeIntegrals};

/// The arm at configuration q.
#[derive(Clone, Debug)]
pub struct ArmKinematics<'a> {
    pub(crate) pose: Pose<'a>,
}

/// The motion of link i's frame at speeds u: `Ω = φ̇_i`, `V = Σ u_j ẑ × c_j`, `A = Σ u_k δ_k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LinkMotion {
    pub(crate) omega: f64,
    pub(crate) v: Vector2<f64>,
    pub(crate) a: Vector2<f64>,
}

impl LinkMotion {
    /// The link's linear momentum in its own frame, P = ∫ρA v dx
    /// = (m·V_x − Ω·∫ρA w, m·V_y + Ω·∫ρA x + ∫ρA ẇ), from its shape integrals `g` and the
    /// deflection moments `d` at the current modal coordinates and speeds.
    pub(crate) fn momentum(&self, g: &ShapeIntegrals, d: &DeflectionMoments) -> Vector2<f64> {
        Vector2::new(
            g.mass() * self.v.x - self.omega * d.w,
            g.mass() * self.v.y + self.omega * g.first_moment() + d.w_dot,
        )
    }
}

impl PlanarArm {
    /// Kinematics at `q`.
    ///
    /// # Panics
    /// If `q.len() != self.n()`.
    #[must_use]
    pub fn kinematics<'a>(&'a self, q: &'a [f64]) -> ArmKinematics<'a> {
        ArmKinematics::new(self.pose(q))
    }
}

impl<'a> ArmKinematics<'a> {
    /// Kinematics at a pose (from [`PlanarArm::pose_in`] to avoid allocating).
    #[must_use]
    pub fn new(pose: Pose<'a>) -> Self {
        Self { pose }
    }
    /// The configuration.
    #[must_use]
    pub fn pose(&self) -> &Pose<'a> {
        &self.pose
    }
    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &'a PlanarArm {
        self.pose.arm()
    }
    /// Modal coordinates and speeds of link i.
    pub(crate) fn modal<'b>(&self, i: usize, u: &'b [f64]) -> (&[f64], &'b [f64]) {
        let q = self.pose.modal(i);
        let o = self.arm().modal_offset(i);
        (q, &u[o..o + q.len()])
    }

    /// Ω, V and A of link i at speeds u (running sums over the joints j ≤ i).
    pub(crate) fn link_motion(&self, i: usize, u: &[f64]) -> LinkMotion {
        let (mut omega, mut s, mut a) = (0.0, Vector2::zeros(), Vector2::zeros());
        for (k, uk) in u.iter().enumerate().take(i + 1) {
            let ck = self.pose.chord_offset(i, k);
            // δ_k = −(Σ_{j<k} u_j) c_k + Σ_{j<k} u_j c_j
            a += *uk * (s - omega * ck);
            omega += uk;
            s += *uk * ck;
        }
        LinkMotion {
            omega,
            v: z_cross(&s),
            a,
        }
    }
}
