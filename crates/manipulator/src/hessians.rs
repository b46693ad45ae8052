//! Second derivatives for the exact Jacobian of the elements: of the kinetic energy
//! T(q, u), of the gravitational potential V_g(q), of the position of a point of the arm and
//! of an actuator's length.
//!
//! # Kinetic energy
//! Per link, T depends on q only through `V = Σ_{j≤i} u_j ẑ × c_j` and the modal
//! coordinates (see [`kinematics`](crate::kinematics)); `∂T/∂V = p`, the link's linear
//! momentum, and with `∂V/∂q_l = δ_l`, `∂²V/∂q_l∂q_m = −ẑ × δ_{min(l,m)}`,
//! `∂²V/∂u_j∂q_l = −[j<l] (c_l − c_j)`:
//!
//! ```text
//! H = ∂²T/∂q²:     H_lm = m δ_l·δ_m − p·(ẑ × δ_{min(l,m)})      H_l,k = −Ω a_k δ_lx      H_kj = Ω² P_kj
//! B = ∂²T/∂u∂q:    B_jl = (m ẑ × c_j + (−∫ρA w, s₁))·δ_l − [j<l] p·(c_l − c_j)
//!                  B_k,l = a_k δ_ly       B_j,k = (Ω c_jy − V_x) a_k + 2Ω (Pq)_k       B_k,j' = 0
//! ```
//!
//! (j, l, m joints ≤ i; k, j' modes). B's column k is `(∂M/∂q_k) u` and `∂E/∂u = Bᵀ`, so
//! `∂u/∂q = −M⁻¹B` for `u = M⁻¹p` and `∂E/∂q|_p = H − BᵀM⁻¹B`.
//!
//! # Gravity and geometry
//! Turning joint l rotates everything outboard of it about `o_l`, so for a point r of link i
//! `∂²r/∂q_j∂q_l = −(r − o_{max(j,l)})`, `∂²r/∂q_j∂q^b_k = −ψ_k R_i x̂`, and
//! `∂²V_g/∂q_j∂q_l = −g Σ_{i≥max(j,l)} (m_i (o_i − o_{max}) + R_i S_i)_y` with
//! `S_i = (s₁, ∫ρA w)` the link's first moment in its frame; `∂²V_g/∂q_j∂q^b_k = −g sin φ_i a_k`.
//! An actuator's length `l = |r_b − r_a|` has `∇²l = (J_dᵀJ_d − ∇l ∇lᵀ)/l + e·(∇²r_b − ∇²r_a)`
//! with `J_d = ∂(r_b − r_a)/∂q` and `e` the unit vector from a to b.

use nalgebra::{DMatrix, Vector2};

use crate::actuator::turns;
use crate::arm::{z_cross, Pose, Station};
use crate::kinematics::ArmKinematics;
use crate::pin::PinPoint;

impl ArmKinematics<'_> {
    /// `δ_l = Σ_{j<l} u_j (c_j − c_l)` of link i.
    fn delta(&self, i: usize, l: usize, u: &[f64]) -> Vector2<f64> {
        let cl = self.pose.chord_offset(i, l);
        (0..l).fold(Vector2::zeros(), |acc, j| {
            acc + u[j] * (self.pose.chord_offset(i, j) - cl)
        })
    }

    /// `B = ∂²T/∂u∂q` (B[(a, k)], column k = `(∂M/∂q_k) u`) and `H = ∂²T/∂q²` at speeds u,
    /// into n×n matrices, without allocating.
    ///
    /// # Panics
    /// If `b` or `h` is not n×n.
    pub fn kinetic_partials_into(&self, u: &[f64], b: &mut DMatrix<f64>, h: &mut DMatrix<f64>) {
        let arm = self.arm();
        let n = arm.n();
        assert!(
            b.shape() == (n, n) && h.shape() == (n, n),
            "B and H must be n×n"
        );
        b.as_mut_slice().fill(0.0);
        h.as_mut_slice().fill(0.0);
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            let o = arm.modal_offset(i);
            let (qb, ub) = self.modal(i, u);
            let d = g.deflection_moments(qb, ub);
            let f = self.link_motion(i, u);
            let (mass, s1, om) = (g.mass(), g.first_moment(), f.omega);
            let p = f.momentum(g, &d);
            for l in 0..=i {
                let dl = self.delta(i, l, u);
                let cl = self.pose.chord_offset(i, l);
                for m in 0..=i {
                    let dm = self.delta(i, m, u);
                    let dmin = if m < l { dm } else { dl };
                    h[(l, m)] += mass * dl.dot(&dm) - p.dot(&z_cross(&dmin));
                }
                for j in 0..=i {
                    let cj = self.pose.chord_offset(i, j);
                    let dp = mass * z_cross(&cj) + Vector2::new(-d.w, s1);
                    let mut v = dp.dot(&dl);
                    if j < l {
                        v -= p.dot(&(cl - cj));
                    }
                    b[(j, l)] += v;
                }
                for k in 0..qb.len() {
                    let a = g.mode_mass(k);
                    h[(l, o + k)] -= om * a * dl.x;
                    h[(o + k, l)] -= om * a * dl.x;
                    b[(o + k, l)] += a * dl.y;
                    b[(l, o + k)] +=
                        (om * cl.y - f.v.x) * a + 2.0 * om * g.mode_times_deflection(k, qb);
                }
            }
            for k in 0..qb.len() {
                for j in 0..qb.len() {
                    h[(o + k, o + j)] += om * om * g.mode_product(k, j);
                }
            }
        }
        if arm.has_geometric_stiffening() {
            self.add_stiffening_kinetic_partials(u, b, h);
        }
    }

    /// `∂²V_g/∂q²` (= −∂G/∂q) into an n×n matrix, without allocating.
    ///
    /// # Panics
    /// If `h` is not n×n.
    pub fn gravity_hessian_into(&self, h: &mut DMatrix<f64>) {
        let arm = self.arm();
        let n = arm.n();
        assert_eq!(h.shape(), (n, n), "the Hessian must be n×n");
        let g = arm.gravity();
        h.fill(0.0);
        for i in 0..arm.n_links() {
            let si = arm.shape_integrals(i);
            let o = arm.modal_offset(i);
            let qb = self.pose.modal(i);
            let w: f64 = (0..qb.len()).map(|k| si.mode_mass(k) * qb[k]).sum();
            let (_, s) = self.pose.cos_sin(i);
            let moment = self.pose.to_base(i, &Vector2::new(si.first_moment(), w));
            let oi = self.pose.origin(i);
            for j in 0..=i {
                for l in 0..=i {
                    let omax = self.pose.origin(j.max(l));
                    h[(j, l)] -= g * (si.mass() * (oi.y - omax.y) + moment.y);
                }
                for k in 0..qb.len() {
                    let v = -g * s * si.mode_mass(k);
                    h[(j, o + k)] += v;
                    h[(o + k, j)] += v;
                }
            }
        }
        if arm.has_geometric_stiffening() {
            self.add_stiffening_gravity_hessian(h);
        }
    }
}

impl Pose<'_> {
    /// The non-zero second derivatives `∂²r/∂q_a∂q_b` of a station's position (frame 0),
    /// every ordered pair: `entry(a, b, ∂²r/∂q_a∂q_b)`.
    pub fn point_hessian(&self, s: &Station, mut entry: impl FnMut(usize, usize, Vector2<f64>)) {
        let i = s.link;
        let r = self.position(s);
        for j in 0..=i {
            for l in 0..=i {
                entry(j, l, self.pivot(j.max(l)) - r);
            }
        }
        let (c, sn) = self.cos_sin(i);
        let o = self.arm().modal_offset(i);
        for (k, psi) in s.psi.iter().enumerate() {
            let v = -psi * Vector2::new(c, sn);
            for j in 0..=i {
                entry(j, o + k, v);
                entry(o + k, j, v);
            }
        }
        if self.arm().has_geometric_stiffening() {
            self.shortening_hessian(s, entry);
        }
    }

    /// `out += Σ f·∂²r/∂q∂q` for a force `f` (frame 0) at a resolved pin: the derivative in q
    /// of its generalized force at constant f.
    pub fn add_pin_force_hessian(&self, pin: &PinPoint, f: &Vector2<f64>, out: &mut DMatrix<f64>) {
        if let PinPoint::Station(s) = pin {
            self.point_hessian(s, |a, b, v| out[(a, b)] += f.dot(&v));
        }
    }

    /// The Hessian `∇²l` of the length of an actuator between resolved pins, into `hess`
    /// (n×n); `jd` (n entries) is scratch for `J_d = ∂(r_b − r_a)/∂q`. Joints that turn both
    /// pins are handled as a whole (`∂d/∂q_j = ẑ × d`, `∂²d/∂q_j∂q_l = −d`), so no large
    /// terms cancel. No allocation.
    pub fn actuator_length_hessian(
        &self,
        a: &PinPoint,
        b: &PinPoint,
        jd: &mut [Vector2<f64>],
        hess: &mut DMatrix<f64>,
    ) {
        let (ra, rb) = (self.pin_point_position(a), self.pin_point_position(b));
        let d = rb - ra;
        let l = d.norm();
        let e = d / l;
        let n_links = self.arm().n_links();
        jd.fill(Vector2::zeros());
        for (j, c) in jd.iter_mut().enumerate().take(n_links) {
            *c = self.pin_pair_joint_column(a, b, (&ra, &rb), j);
        }
        self.pin_pair_mode_columns(a, b, |k, col| jd[k] += col);
        for (k, jk) in jd.iter().enumerate() {
            for (m, jm) in jd.iter().enumerate() {
                hess[(k, m)] = (jk.dot(jm) - jk.dot(&e) * jm.dot(&e)) / l;
            }
        }
        // e·∂²d/∂q_j∂q_l for joints: −(r − o_max) per pin the joint `max` turns
        for j in 0..n_links {
            for m in 0..n_links {
                let top = j.max(m);
                let o = self.pivot(top);
                let v = match (turns(a, top), turns(b, top)) {
                    (true, true) => -l,
                    (false, true) => -e.dot(&(rb - o)),
                    (true, false) => e.dot(&(ra - o)),
                    (false, false) => 0.0,
                };
                hess[(j, m)] += v;
            }
        }
        // joint–mode: −ψ_k R_i x̂ per pin, for the joints that turn it
        for (pin, sign) in [(b, 1.0), (a, -1.0)] {
            if let PinPoint::Station(s) = pin {
                let (c, sn) = self.cos_sin(s.link);
                let o = self.arm().modal_offset(s.link);
                for (k, psi) in s.psi.iter().enumerate() {
                    let v = -sign * psi * e.dot(&Vector2::new(c, sn));
                    for j in 0..=s.link {
                        hess[(j, o + k)] += v;
                        hess[(o + k, j)] += v;
                    }
                }
            }
        }
        // the shortening of geometric stiffening: e·∂²Δ/∂q∂q in the pairs with a mode
        if self.arm().has_geometric_stiffening() {
            for (pin, sign) in [(b, 1.0), (a, -1.0)] {
                if let PinPoint::Station(s) = pin {
                    self.shortening_hessian(s, |r, c, v| hess[(r, c)] += sign * e.dot(&v));
                }
            }
        }
        // l does not depend at all on a joint that turns both pins: its row and column are
        // exactly zero (what the sums above give up to rounding)
        for j in (0..n_links).filter(|&j| turns(a, j) && turns(b, j)) {
            hess.row_mut(j).fill(0.0);
            hess.column_mut(j).fill(0.0);
        }
    }
}
