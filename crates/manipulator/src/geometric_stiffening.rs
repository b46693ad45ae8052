//! Geometric stiffening: the second-order axial shortening of a bent link, kept in the
//! kinematics (a link option, [`Link::with_geometric_stiffening`]; off in the paper's scene).
//!
//! # The shortening
//! An inextensible link bent by `w(x) = Σ_k ψ_k(x) q_k` pulls its cross-sections towards its
//! root: to second order in the modal coordinates the cross-section at distance x along the
//! chord sits at `(x + u(x), w(x))` in the link's frame, with
//!
//! ```text
//! u(x) = −½ ∫₀ˣ (∂w/∂ξ)² dξ = −½ qᵀ S(x) q,     S(x) = ∫₀ˣ ψ'ψ'ᵀ dξ
//! ```
//!
//! and the end of its chord, where the next link's joint sits, moves by `s = u(L)` along the
//! chord: joint i+1 is at `o_i + (L_i + s_i) e_i` (`e_i = (cos φ_i, sin φ_i)`, `n_i = ẑ × e_i`).
//! Every point of link i is displaced from where the paper puts it by
//!
//! ```text
//! Δ = Σ_{j<i} s_j e_j + u_i(x) e_i
//! ```
//!
//! so that an axial force — the weight of the link and of what it carries, a cylinder force at
//! a pin, the centrifugal pull of its rotation — does work through the shortening, and
//! stiffens (tension) or softens (compression) the bending through the equations of motion.
//! No axial force is computed anywhere: it is the Lagrangian that carries it.
//!
//! # What is kept, exactly
//! * **Positions of pins and lumped-mass attachments** (actuator lengths, `τ_b`, `J_c`):
//!   `r = o'_i + R_i (x + u(x), w(x))` with `o'_i` the joint positions of the shortened chords
//!   ([`Pose::pivot`]); their gradients and Hessians follow ([`Pose::shortening_columns`],
//!   [`Pose::shortening_hessian`]).
//! * **Gravity**: `V_g` of every material point at its shortened position; since Δ adds to
//!   the position, `ΔV_g = g Σ_i sin φ_i (∫ρA u_i + m_out,i s_i) = −½ g Σ_i sin φ_i qᵀW_i q`
//!   with `W_i = ∫ρA S + m_out,i S(L)` (`m_out,i` the mass outboard of link i).
//! * **Kinetic energy** ([`kinetic`]): every material point at its shortened position, the
//!   outboard links on the shifted chord ends, kept to second order in the modal
//!   coordinates — the link frame's translation against the shortening (`∫ρA u̇`, `∫ρA u`),
//!   the centrifugal term (`∫ρA x u`, Southwell's) and the outboard links' momenta against
//!   `ṡ_j`, `s_j φ̇_j`. So the inertial axial forces of the frames' accelerations stiffen or
//!   soften like gravity does (a link on a base accelerating upward at a bends like the link
//!   under gravity a). Terms of third and fourth order (`Δv·w`, `|Δv|²`) are dropped, so M
//!   stays positive definite for deflections small against the links, not for any.
//!
//! Point masses on the link count in `∫ρA` (`m S(x₀)`, `m x₀ S(x₀)`). The model stays
//! Lagrangian: `T' = ½uᵀM'u` and `V'` are exact derivatives of what is kept, so energy is
//! conserved and the Jacobian is exact. The reaction block and the projections (eq. 38) use
//! the paper's kinematics.
//!
//! # Precomputed, once per link (by Gauss–Legendre quadrature, at least 64 points)
//! ```text
//! S(L) = ∫₀ᴸ ψ'ψ'ᵀ dξ      A = ∫ρA S(x) dx = ∫ ψ'ψ'ᵀ(ξ) ρA (L − ξ) dξ      D = ∫ρA x S(x) dx = ∫ ψ'ψ'ᵀ(ξ) ρA (L² − ξ²)/2 dξ
//! ```
//! and `S(x)` at every pin (in its [`Station`]). A right-hand side adds O(m²) per link.
//!
//! [`Link::with_geometric_stiffening`]: crate::Link::with_geometric_stiffening

use nalgebra::{DMatrix, Vector2};

use crate::arm::{Pose, Station};
use crate::kinematics::ArmKinematics;
use crate::link::Link;
use crate::mode_shape::ModeShape;
use crate::quadrature::GaussLegendre;

mod kinetic;
use bondgraph::ParamError;

/// The integrals of a link's shortening, m × m each.
#[derive(Clone, Debug, PartialEq)]
pub struct ShorteningIntegrals {
    /// `S(L) = ∫₀ᴸ ψ'ψ'ᵀ`: the chord's shortening `s = −½ qᵀ S(L) q`.
    chord: DMatrix<f64>,
    /// `∫ρA S(x) dx + Σ m S(x₀)`.
    mass: DMatrix<f64>,
    /// `∫ρA x S(x) dx + Σ m x₀ S(x₀)`.
    moment: DMatrix<f64>,
}

/// Quadrature points for the shortening integrals (at least).
const POINTS: usize = 64;

/// `S(x) = ∫₀ˣ ψ'ψ'ᵀ dξ`, row-major m × m.
pub(crate) fn slope_products(modes: &[std::sync::Arc<dyn ModeShape>], x: f64) -> Vec<f64> {
    let m = modes.len();
    let mut s = vec![0.0; m * m];
    if x <= 0.0 {
        return s;
    }
    // the 64-point rule, computed once per process (stations are made at build time, often)
    static RULE: std::sync::OnceLock<Option<GaussLegendre>> = std::sync::OnceLock::new();
    let Some(rule) = RULE
        .get_or_init(|| GaussLegendre::new(POINTS).ok())
        .as_ref()
    else {
        return s;
    };
    let mut slope = vec![0.0; m];
    for (xi, w) in rule.on(x) {
        for (t, mode) in slope.iter_mut().zip(modes) {
            *t = mode.slope(xi);
        }
        for a in 0..m {
            for b in 0..m {
                s[a * m + b] += w * slope[a] * slope[b];
            }
        }
    }
    s
}

impl ShorteningIntegrals {
    /// The integrals of `link` with `max(points, 64)` Gauss–Legendre points.
    pub fn of(link: &Link, points: usize) -> Result<Self, ParamError> {
        let m = link.modes().len();
        if m > kinetic::MAX_MODES {
            return Err(ParamError::invalid(
                "modes",
                m as f64,
                "at most 64 modes per link with geometric stiffening",
            ));
        }
        let l = link.length();
        let rho_a = link.mass_per_length();
        let mut out = Self {
            chord: DMatrix::zeros(m, m),
            mass: DMatrix::zeros(m, m),
            moment: DMatrix::zeros(m, m),
        };
        let rule = GaussLegendre::new(points.max(POINTS))?;
        let mut slope = vec![0.0; m];
        for (xi, w) in rule.on(l) {
            for (t, mode) in slope.iter_mut().zip(link.modes()) {
                *t = mode.slope(xi);
            }
            // ∫_ξ^L ρA dx and ∫_ξ^L ρA x dx
            let (wa, wd) = if link.is_uniform() {
                (rho_a * (l - xi), rho_a * 0.5 * (l * l - xi * xi))
            } else {
                rule.on(l - xi).fold((0.0, 0.0), |(a, d), (y, wy)| {
                    let x = xi + y;
                    let m = wy * link.mass_per_length_at(x);
                    (a + m, d + m * x)
                })
            };
            for a in 0..m {
                for b in 0..m {
                    let p = w * slope[a] * slope[b];
                    out.chord[(a, b)] += p;
                    out.mass[(a, b)] += wa * p;
                    out.moment[(a, b)] += wd * p;
                }
            }
        }
        for pm in link.point_masses() {
            let s = slope_products(link.modes(), pm.x);
            for a in 0..m {
                for b in 0..m {
                    out.mass[(a, b)] += pm.mass * s[a * m + b];
                    out.moment[(a, b)] += pm.mass * pm.x * s[a * m + b];
                }
            }
        }
        Ok(out)
    }

    /// `S(L) = ∫₀ᴸ ψ'ψ'ᵀ`.
    #[must_use]
    pub fn chord(&self) -> &DMatrix<f64> {
        &self.chord
    }
    /// `∫ρA S(x) dx` (point masses included).
    #[must_use]
    pub fn mass(&self) -> &DMatrix<f64> {
        &self.mass
    }
    /// `∫ρA x S(x) dx` (point masses included).
    #[must_use]
    pub fn moment(&self) -> &DMatrix<f64> {
        &self.moment
    }
}

/// `(Xq)_k`.
fn times(x: &DMatrix<f64>, q: &[f64], k: usize) -> f64 {
    q.iter().enumerate().map(|(l, ql)| x[(k, l)] * ql).sum()
}

impl Pose<'_> {
    /// The axial displacement `u(x) = −½ qᵀS(x)q` of a station (zero without stiffening).
    #[must_use]
    pub fn axial_shortening(&self, s: &Station) -> f64 {
        let m = s.psi.len();
        if s.shortening.is_empty() {
            return 0.0;
        }
        let q = self.modal(s.link);
        let mut v = 0.0;
        for a in 0..m {
            let sq: f64 = (0..m).map(|b| s.shortening[a * m + b] * q[b]).sum();
            v += q[a] * sq;
        }
        -0.5 * v
    }

    /// Calls `f(j, S_j, q_j, e_j)` for every link j ≤ station's link whose shortening moves
    /// the station: the chord of j < i (S(L)), and the station's own link (S(x)).
    fn shortening_terms(
        &self,
        s: &Station,
        own: bool,
        mut f: impl FnMut(usize, &dyn Fn(usize, usize) -> f64),
    ) {
        let arm = self.arm();
        for j in 0..s.link {
            if let Some(sh) = arm.shape_integrals(j).shortening() {
                let c = sh.chord();
                f(j, &|a, b| c[(a, b)]);
            }
        }
        if own && !s.shortening.is_empty() {
            let m = s.psi.len();
            f(s.link, &|a, b| s.shortening[a * m + b]);
        }
    }

    /// The columns `∂Δ/∂q^b_k = −(S q)_k e_j` of the shortening of a station, for the modes
    /// of its link and of the links inboard of it: `column(k, ·)`.
    pub fn shortening_columns(&self, s: &Station, column: impl FnMut(usize, Vector2<f64>)) {
        self.shortening_columns_of(s, true, column);
    }

    /// [`shortening_columns`](Self::shortening_columns), of the inboard links only if `!own`.
    pub(crate) fn shortening_columns_of(
        &self,
        s: &Station,
        own: bool,
        mut column: impl FnMut(usize, Vector2<f64>),
    ) {
        let arm = self.arm();
        self.shortening_terms(s, own, |j, sm| {
            let q = self.modal(j);
            let (c, sn) = self.cos_sin(j);
            let o = arm.modal_offset(j);
            for k in 0..q.len() {
                let sq: f64 = (0..q.len()).map(|l| sm(k, l) * q[l]).sum();
                column(o + k, -sq * Vector2::new(c, sn));
            }
        });
    }

    /// The second derivatives of the shortening Δ of a station in the pairs that hold a
    /// modal coordinate (both orders): `∂²Δ/∂q_a∂q^b_k = −(Sq)_k n_j` for the joints a ≤ j,
    /// `∂²Δ/∂q^b_k∂q^b_l = −S_kl e_j`. The joint–joint pairs are those of a rigid rotation
    /// about the shifted joints ([`pivot`](Self::pivot)).
    pub fn shortening_hessian(
        &self,
        s: &Station,
        mut entry: impl FnMut(usize, usize, Vector2<f64>),
    ) {
        let arm = self.arm();
        self.shortening_terms(s, true, |j, sm| {
            let q = self.modal(j);
            let (c, sn) = self.cos_sin(j);
            let (e, n) = (Vector2::new(c, sn), Vector2::new(-sn, c));
            let o = arm.modal_offset(j);
            for k in 0..q.len() {
                let sq: f64 = (0..q.len()).map(|l| sm(k, l) * q[l]).sum();
                let v = -sq * n;
                for a in 0..=j {
                    entry(a, o + k, v);
                    entry(o + k, a, v);
                }
                for l in 0..q.len() {
                    entry(o + k, o + l, -sm(k, l) * e);
                }
            }
        });
    }
}

impl ArmKinematics<'_> {
    /// `Ω_i = φ̇_i` and the modal coordinates of each stiffened link: `f(i, o, q_i, Ω_i, sh)`.
    fn stiffened(
        &self,
        u: Option<&[f64]>,
        mut f: impl FnMut(usize, usize, &[f64], f64, &ShorteningIntegrals),
    ) {
        let arm = self.arm();
        let mut omega = 0.0;
        for i in 0..arm.n_links() {
            if let Some(u) = u {
                omega += u[i];
            }
            if let Some(sh) = arm.shape_integrals(i).shortening() {
                f(i, arm.modal_offset(i), self.pose.modal(i), omega, sh);
            }
        }
    }

    /// `(W_i q)_k` with `W_i = ∫ρA S + m_out,i S(L)`.
    fn weight_times(&self, i: usize, sh: &ShorteningIntegrals, q: &[f64], k: usize) -> f64 {
        times(sh.mass(), q, k) + self.arm().outboard_mass(i) * times(sh.chord(), q, k)
    }

    /// `G += −∂ΔV_g/∂q`; returns `ΔV_g = −½ g Σ sin φ_i qᵀW_iq`.
    pub(crate) fn add_stiffening_gravity(&self, forces: &mut [f64]) -> f64 {
        let g = self.arm().gravity();
        let mut v = 0.0;
        self.stiffened(None, |i, o, q, _, sh| {
            let (c, s) = self.pose.cos_sin(i);
            let mut qwq = 0.0;
            for k in 0..q.len() {
                let wq = self.weight_times(i, sh, q, k);
                qwq += q[k] * wq;
                forces[o + k] += g * s * wq;
            }
            v -= 0.5 * g * s * qwq;
            for fj in forces.iter_mut().take(i + 1) {
                *fj += 0.5 * g * c * qwq;
            }
        });
        v
    }

    /// `h += ∂²ΔV_g/∂q²`.
    pub(crate) fn add_stiffening_gravity_hessian(&self, h: &mut DMatrix<f64>) {
        let g = self.arm().gravity();
        self.stiffened(None, |i, o, q, _, sh| {
            let (c, s) = self.pose.cos_sin(i);
            let mut qwq = 0.0;
            let outboard = self.arm().outboard_mass(i);
            for k in 0..q.len() {
                let wq = self.weight_times(i, sh, q, k);
                qwq += q[k] * wq;
                for j in 0..=i {
                    h[(j, o + k)] -= g * c * wq;
                    h[(o + k, j)] -= g * c * wq;
                }
                for l in 0..q.len() {
                    h[(o + k, o + l)] -=
                        g * s * (sh.mass()[(k, l)] + outboard * sh.chord()[(k, l)]);
                }
            }
            for j in 0..=i {
                for l in 0..=i {
                    h[(j, l)] += 0.5 * g * s * qwq;
                }
            }
        });
    }
}

impl ArmKinematics<'_> {
    /// `d²/dt² (σ e_j)` in frame 0 for `σ = −½ q_jᵀXq_j` of link j's modes, at speeds u and
    /// accelerations u̇: `σ̈ e_j + 2σ̇ φ̇_j n_j + σ (φ̈_j n_j − φ̇_j² e_j)` — the acceleration a
    /// shortening adds to the points it moves (the reaction block's Newton's law).
    pub(crate) fn shortening_acceleration(
        &self,
        j: usize,
        x: impl Fn(usize, usize) -> f64,
        u: &[f64],
        u_dot: &[f64],
    ) -> Vector2<f64> {
        let (q, qd) = self.modal(j, u);
        let (_, qdd) = self.modal(j, u_dot);
        let (mut s, mut sd, mut sdd) = (0.0, 0.0, 0.0);
        for a in 0..q.len() {
            for b in 0..q.len() {
                let xab = x(a, b);
                s -= 0.5 * q[a] * xab * q[b];
                sd -= q[a] * xab * qd[b];
                sdd -= qd[a] * xab * qd[b] + q[a] * xab * qdd[b];
            }
        }
        let (rate, accel): (f64, f64) = (u[..=j].iter().sum(), u_dot[..=j].iter().sum());
        let (c, sn) = self.pose.cos_sin(j);
        let (e, n) = (Vector2::new(c, sn), Vector2::new(-sn, c));
        (sdd - s * rate * rate) * e + (2.0 * sd * rate + s * accel) * n
    }

    /// The acceleration (frame 0) the shortened chords j < i add to every point of link i.
    pub(crate) fn chord_shortening_acceleration(
        &self,
        i: usize,
        u: &[f64],
        u_dot: &[f64],
    ) -> Vector2<f64> {
        let arm = self.arm();
        (0..i)
            .filter_map(|j| {
                let c = arm.shape_integrals(j).shortening()?.chord();
                Some(self.shortening_acceleration(j, |a, b| c[(a, b)], u, u_dot))
            })
            .sum()
    }
}
