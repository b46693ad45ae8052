//! The moving base: the arm's ground frame (frame 0) carried by a vessel, and the loads its
//! motion puts on the arm.
//!
//! The base frame sits at `(x(t), y(t))` in an inertial frame and is rolled by `θ(t)`
//! (counter-clockwise, about its origin, which is joint 1). Every coordinate of the arm
//! stays relative to the base: `q_1` is link 1's angle from the base's x axis, the pins on
//! the ground move with the base. Lagrange's equations in the inertial frame then read,
//! exactly (docs/offshore.md),
//!
//! ```text
//! d/dt (M(q) u_a) − E(q, u_a) = G(q; f) + (the other generalized forces)
//! u_a = u + θ̇ e₁        f = R(−θ) ((0, −g) − a_b)
//! ```
//!
//! because (i) M does not depend on q₁ (turning the whole arm about joint 1 changes no
//! distance), so a roll θ is the same as a turn of joint 1 by θ: the kinetic energy is
//! `½ u_aᵀ M u_a`, and its momentum `M u_a` is the I-field's state; (ii) the base's
//! translation `r_b(t)` adds `ṙ_b · d/dt(Σ m r) + ½ m |ṙ_b|²` to the kinetic energy, which up
//! to a total time derivative is the potential `m r̈_b · r_cm`: the uniform field −r̈_b,
//! added to gravity. `f` is that field in the base's axes. The roll's Coriolis, centrifugal
//! and Euler terms are carried by `E(q, u_a)` and `d/dt(M u_a)`; nothing is approximated.
//!
//! [`ArmKinematics::field_forces_into`] gives `G(q; f)` for any uniform field f; the paper's
//! gravity is `f = (0, −g)`.

use bondgraph::Motion;
use nalgebra::Vector2;

use crate::kinematics::ArmKinematics;

/// The base's motion: position `(x, y)` (m) and roll θ (rad) of frame 0 as functions of
/// time, each with exact first and second derivatives.
#[derive(Clone, Debug)]
pub struct Base {
    /// Horizontal position of joint 1 (m), inertial.
    pub x: Motion,
    /// Vertical position of joint 1 (m), inertial, up.
    pub y: Motion,
    /// Roll of the base frame (rad, counter-clockwise).
    pub roll: Motion,
}

/// The base at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseState {
    /// `[x, ẋ, ẍ]`.
    pub x: [f64; 3],
    /// `[y, ẏ, ÿ]`.
    pub y: [f64; 3],
    /// `[θ, θ̇, θ̈]`.
    pub roll: [f64; 3],
}

impl Base {
    /// A base that does not move.
    #[must_use]
    pub fn still() -> Self {
        Self {
            x: Motion::Const(0.0),
            y: Motion::Const(0.0),
            roll: Motion::Const(0.0),
        }
    }
    /// Whether the roll is a constant (θ̇ = θ̈ = 0 always).
    #[must_use]
    pub fn rolls(&self) -> bool {
        !self.roll.is_still()
    }
    /// The base at time `t`.
    #[must_use]
    #[inline]
    pub fn at(&self, t: f64) -> BaseState {
        BaseState {
            x: self.x.eval(t),
            y: self.y.eval(t),
            roll: self.roll.eval(t),
        }
    }
}

impl BaseState {
    /// The apparent gravity in the base's axes, `f = R(−θ)((0, −g) − a_b)` (m/s²).
    #[must_use]
    pub fn field(&self, g: f64) -> Vector2<f64> {
        let (s, c) = self.roll[0].sin_cos();
        let (fx, fy) = (-self.x[2], -g - self.y[2]);
        Vector2::new(c * fx + s * fy, -s * fx + c * fy)
    }
    /// A point `r` of the base frame in inertial coordinates: `r_b + R(θ) r`.
    #[must_use]
    pub fn to_inertial(&self, r: &Vector2<f64>) -> Vector2<f64> {
        let (s, c) = self.roll[0].sin_cos();
        Vector2::new(self.x[0] + c * r.x - s * r.y, self.y[0] + s * r.x + c * r.y)
    }
}

impl ArmKinematics<'_> {
    /// The generalized forces `G(q; f)_k = Σ m f · ∂r/∂q_k` of a uniform field `f` (m/s², in
    /// frame 0) into `forces` (length n), without allocating; returns its potential
    /// `−f · Σ m r` (J). With `f = (0, −g)` the same sums as
    /// [`gravity_into`](ArmKinematics::gravity_into) (eqs. 45–48), turned: per link i,
    /// with `m = ∫ρA`, `s₁ = ∫ρA x`, `W = ∫ρA w`, `a_k = ∫ρA ψ_k`,
    ///
    /// ```text
    /// Σ m r   = m o_i + (c s₁ − s W,  s s₁ + c W)
    /// G_j    += f · ẑ × (Σ m r − m o_j)          joints j ≤ i
    /// G_k    += a_k f · (−s, c)                  modes k
    /// ```
    ///
    /// # Panics
    /// With geometric stiffening (not combined with a moving base; the kind refuses it).
    pub fn field_forces_into(&self, f: &Vector2<f64>, forces: &mut [f64]) -> f64 {
        let arm = self.arm();
        assert!(
            !arm.has_geometric_stiffening(),
            "a uniform field other than gravity is not combined with geometric stiffening"
        );
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
            let mr = mass * oi + Vector2::new(c * s1 - s * w, s * s1 + c * w);
            v -= f.dot(&mr);
            for (j, fj) in forces.iter_mut().enumerate().take(i + 1) {
                let d = mr - mass * self.pose.origin(j);
                *fj += f.x * -d.y + f.y * d.x;
            }
            let along = -s * f.x + c * f.y;
            for k in 0..qb.len() {
                forces[o + k] += si.mode_mass(k) * along;
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::Link;
    use crate::PlanarArm;

    fn arm() -> PlanarArm {
        let beam = |l: f64| {
            Link::beam(l, 2e11, 7800.0, 1e-2, 1e-4)
                .unwrap()
                .with_sine_modes(2)
                .unwrap()
        };
        PlanarArm::new(
            vec![beam(4.0), beam(3.0), Link::pendulum(2.0, 50.0).unwrap()],
            9.81,
        )
        .unwrap()
    }

    #[test]
    fn base_field_of_gravity_is_the_papers_gravity() {
        let arm = arm();
        let q = [0.3, -1.1, 0.4, 0.01, -0.02, 0.005, 0.003];
        let kin = arm.kinematics(&q);
        let (g, vg) = kin.gravity_terms(true);
        let mut f = vec![0.0; arm.n()];
        let v = kin.field_forces_into(&Vector2::new(0.0, -9.81), &mut f);
        let scale = g.amax();
        for k in 0..arm.n() {
            assert!(
                (f[k] - g[k]).abs() <= 1e-12 * scale,
                "{k}: {} vs {}",
                f[k],
                g[k]
            );
        }
        assert!((v - vg).abs() <= 1e-12 * vg.abs().max(1.0));
    }

    #[test]
    fn base_field_is_gravity_turned_with_the_arm() {
        // a field f turned by β acts on the arm as gravity on the arm turned by −β at joint 1
        let arm = arm();
        let (g, beta) = (7.0, 0.37_f64);
        let q = [0.3, -1.1, 0.4, 0.01, -0.02, 0.005, 0.003];
        let field = Vector2::new(g * beta.sin(), -g * beta.cos());
        let mut f = vec![0.0; arm.n()];
        let v = arm.kinematics(&q).field_forces_into(&field, &mut f);
        let mut qt = q;
        qt[0] -= beta;
        let (gt, vt) = arm.kinematics(&qt).gravity_terms(true);
        let scale = gt.amax();
        for k in 0..arm.n() {
            let expect = gt[k] * g / 9.81;
            assert!(
                (f[k] - expect).abs() <= 1e-12 * scale,
                "{k}: {} vs {expect}",
                f[k]
            );
        }
        assert!((v - vt * g / 9.81).abs() <= 1e-10 * vt.abs());
    }

    #[test]
    fn base_field_forces_are_minus_the_gradient_of_the_potential() {
        let arm = arm();
        let q = [0.2, -0.9, 0.5, 0.02, -0.01, 0.004, -0.002];
        let field = Vector2::new(1.3, -8.2);
        let mut f = vec![0.0; arm.n()];
        arm.kinematics(&q).field_forces_into(&field, &mut f);
        let mut scratch = vec![0.0; arm.n()];
        for k in 0..arm.n() {
            let h = 1e-6;
            let (mut a, mut b) = (q, q);
            a[k] += h;
            b[k] -= h;
            let va = arm.kinematics(&a).field_forces_into(&field, &mut scratch);
            let vb = arm.kinematics(&b).field_forces_into(&field, &mut scratch);
            let fd = -(va - vb) / (2.0 * h);
            assert!(
                (fd - f[k]).abs() <= 1e-6 * f[k].abs().max(1.0),
                "{k}: {fd} vs {}",
                f[k]
            );
        }
    }
}
