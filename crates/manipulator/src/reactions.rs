//! Reaction forces in the passive joints (section 5, eqs. 84–98), in the scene's
//! convention, contracted from the links' shape integrals.
//!
//! The method of auxiliary generalized speeds gives joint j a fictitious translation along
//! x_j and y_j: the auxiliary projection columns `V_{i_e,j}^{i,j} Π [L_x L_y]` (eqs. 88–89) of
//! every point outboard of the joint are the pure translations x_j, y_j. So eq. 97,
//! `ρ = M_r ϑ − G_r − τ_r F` written out per point, is Newton's law for everything outboard
//! of joint j, in the axes of frame j:
//!
//! ```text
//! ρ_j = R_0^j ( Σ_{i≥j} ∫ρA (a − g⃗) dx  −  Σ_{loads on links ≥ j} f )
//! ```
//!
//! with `a` the inertial acceleration of each mass point: `P u̇ + Ṗ u` plus the transport
//! term `Ω ẑ × v` of its link frame. All three are linear in the features φ = [1, x, ψ]
//! ([`kinematics`](crate::kinematics)), so per link, with `p` its linear momentum
//! (see [`kinetic_forces`](crate::kinetic_forces)) and a dot on the quantities at speeds u̇,
//!
//! ```text
//! ∫ρA a = (m V̇_x − Ω̇ ∫ρA w, m V̇_y + Ω̇ s₁ + ∫ρA ẅ) + (m A_x − Ω ∫ρA ẇ, m A_y) + Ω ẑ × p.
//! ```
//!
//! With geometric stiffening every point also moves with the shortening of its own link
//! and of the chords inboard of it, `Σ_{k<i} s_k e_k + u(x) e_i`
//! ([`geometric_stiffening`](crate::geometric_stiffening)), whose acceleration
//! `d²/dt²(σ e) = σ̈ e + 2σ̇ φ̇ n + σ(φ̈ n − φ̇² e)` adds to `∫ρA a` (with `∫ρA u = −½qᵀ(∫ρA S)q`).
//!
//! `ρ_{2j−1}, ρ_{2j}` is the force that the inboard body exerts on link j through joint j,
//! in the axes of frame j (x along link j's chord; for the pendulum from the pivot to the
//! payload). A pendulum at rest gives `ρ = (−m g, 0)`. Internal forces — strain, modal
//! damping, joint torques — do not enter. External forces are the actuator forces on their
//! pins and, when the lumped cylinder masses hang on springs, the spring–damper forces on the
//! pins; masses that move rigidly with a pin (the paper's eqs. 91–94, or the "rigidly
//! attached" scene) are point masses.

use nalgebra::{DVector, Vector2};

use crate::arm::{z_cross, Station};
use crate::kinematics::ArmKinematics;

/// A force (frame 0, N) applied at a station of the arm.
#[derive(Clone, Debug, PartialEq)]
pub struct PointLoad {
    /// Where it acts.
    pub station: Station,
    /// The force in frame 0.
    pub force: Vector2<f64>,
}

impl ArmKinematics<'_> {
    /// Inertial acceleration of a station (frame of its link).
    fn station_acceleration(&self, s: &Station, u: &[f64], u_dot: &[f64]) -> Vector2<f64> {
        let i = s.link;
        let (qb, ub) = self.modal(i, u);
        let (_, udb) = self.modal(i, u_dot);
        let dot = |v: &[f64]| -> f64 { s.psi.iter().zip(v).map(|(p, x)| p * x).sum() };
        let (w, w_dot, w_ddot) = (dot(qb), dot(ub), dot(udb));
        let (f, fd) = (self.link_motion(i, u), self.link_motion(i, u_dot));
        let v = Vector2::new(f.v.x - f.omega * w, f.v.y + f.omega * s.x + w_dot);
        let pa = Vector2::new(fd.v.x - fd.omega * w, fd.v.y + fd.omega * s.x + w_ddot);
        let a_v = Vector2::new(f.a.x - f.omega * w_dot, f.a.y);
        pa + a_v + f.omega * z_cross(&v)
    }

    /// Inertial acceleration of a station in frame 0 at speeds `u` and accelerations `u_dot`.
    #[must_use]
    pub fn point_acceleration(&self, s: &Station, u: &[f64], u_dot: &[f64]) -> Vector2<f64> {
        self.pose
            .to_base(s.link, &self.station_acceleration(s, u, u_dot))
    }

    /// The reaction forces ρ (2 per joint, eq. 97) at speeds `u` and accelerations `u_dot`,
    /// with external `loads` and extra point masses `rigid_masses` moving with their stations.
    #[must_use]
    pub fn reactions(
        &self,
        u: &[f64],
        u_dot: &[f64],
        loads: &[PointLoad],
        rigid_masses: &[(Station, f64)],
    ) -> DVector<f64> {
        let mut rho = DVector::zeros(2 * self.arm().n_links());
        self.reactions_into(
            u,
            u_dot,
            loads.iter().map(|l| (&l.station, l.force)),
            rigid_masses,
            rho.as_mut_slice(),
        );
        rho
    }

    /// As [`reactions`](Self::reactions), into `rho` (length 2 n_links), with the loads as
    /// (station, force in frame 0) pairs; no allocation.
    pub fn reactions_into<'s>(
        &self,
        u: &[f64],
        u_dot: &[f64],
        loads: impl IntoIterator<Item = (&'s Station, Vector2<f64>)>,
        rigid_masses: &[(Station, f64)],
        rho: &mut [f64],
    ) {
        let weight = Vector2::new(0.0, self.arm().gravity());
        self.reactions_in_field_into(u, u_dot, loads, rigid_masses, weight, rho);
    }

    /// As [`reactions_into`](Self::reactions_into) in a uniform field of acceleration
    /// `−weight` (frame 0; gravity is `weight = (0, g)`): on a moving base
    /// ([`base`](crate::base)) the apparent gravity, with the absolute speeds.
    pub fn reactions_in_field_into<'s>(
        &self,
        u: &[f64],
        u_dot: &[f64],
        loads: impl IntoIterator<Item = (&'s Station, Vector2<f64>)>,
        rigid_masses: &[(Station, f64)],
        weight: Vector2<f64>,
        rho: &mut [f64],
    ) {
        let arm = self.arm();
        rho.fill(0.0);
        // Σ (m a − m g⃗) of link i (frame 0), onto every joint j ≤ i.
        let add = |i: usize, f: Vector2<f64>, rho: &mut [f64]| {
            for j in 0..=i {
                let fj = self.pose.to_frame(j, &f);
                rho[2 * j] += fj.x;
                rho[2 * j + 1] += fj.y;
            }
        };
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            let (qb, ub) = self.modal(i, u);
            let (_, udb) = self.modal(i, u_dot);
            let d = g.deflection_moments(qb, ub);
            let w_ddot: f64 = (0..qb.len()).map(|k| g.mode_mass(k) * udb[k]).sum();
            let (f, fd) = (self.link_motion(i, u), self.link_motion(i, u_dot));
            let (mass, s1, om) = (g.mass(), g.first_moment(), f.omega);
            let p = f.momentum(g, &d);
            let ma = Vector2::new(
                mass * fd.v.x - fd.omega * d.w,
                mass * fd.v.y + fd.omega * s1 + w_ddot,
            ) + Vector2::new(mass * f.a.x - om * d.w_dot, mass * f.a.y)
                + om * z_cross(&p);
            let mut ma = self.pose.to_base(i, &ma);
            if arm.has_geometric_stiffening() {
                // the shortening of the inboard chords and of the link itself
                ma += mass * self.chord_shortening_acceleration(i, u, u_dot);
                if let Some(sh) = g.shortening() {
                    let x = sh.mass();
                    ma += self.shortening_acceleration(i, |a, b| x[(a, b)], u, u_dot);
                }
            }
            add(i, ma + mass * weight, rho);
        }
        for (s, m) in rigid_masses {
            let mut a = self.point_acceleration(s, u, u_dot);
            if arm.has_geometric_stiffening() {
                a += self.chord_shortening_acceleration(s.link, u, u_dot);
                if !s.shortening.is_empty() {
                    let n = s.psi.len();
                    let x = |a: usize, b: usize| s.shortening[a * n + b];
                    a += self.shortening_acceleration(s.link, x, u, u_dot);
                }
            }
            add(s.link, *m * (a + weight), rho);
        }
        for (s, f) in loads {
            add(s.link, -f, rho);
        }
    }
}
