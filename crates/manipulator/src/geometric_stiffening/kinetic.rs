//! The kinetic energy of the shortening: every material point, pin and outboard link moved
//! by it, to the order that carries the axial forces.
//!
//! # The energy
//! A point of link i sits at `o'_i + R_i (x + u_i(x), w_i(x))`, with the joints moved by the
//! chords' shortenings, `o'_i = o_i + Σ_{j<i} s_j e_j`. Its velocity is the paper's `v₀`
//! ([`kinematics`](crate::kinematics)) plus
//!
//! ```text
//! Δv = Σ_{j<i} (ṡ_j e_j + s_j φ̇_j n_j) + R_i (u̇, Ω_i u)
//! ```
//!
//! and `T = ½∫ρA|v₀ + Δv|²` keeps, of `∫ρA v₀·Δv + ½∫ρA|Δv|²`, every term of second order in
//! the modal coordinates (u and s are of second order; `Δv·w`, `|Δv|²` are of third and
//! fourth and are dropped, as in the consistent second-order theories of dynamic stiffening).
//! With `ȯ_i = Σ_{k<i} L_k φ̇_k n_k` (the paper's chords) and `P_i = m_i ȯ_i + s₁,i φ̇_i n_i`
//! (the link's momentum as a rigid chord, frame 0):
//!
//! ```text
//! ΔT = Σ_i [ (e_i·ȯ_i) U̇_i + φ̇_i (n_i·ȯ_i) U_i + φ̇_i² X_i
//!          + Σ_{j<i} (ṡ_j e_j + s_j φ̇_j n_j)·P_i ]
//! U_i = ∫ρA u = −½ qᵀA_iq,  X_i = ∫ρA x u = −½ qᵀD_iq,  s_j = −½ q_jᵀS_j(L)q_j
//! ```
//!
//! — the frame's translation against the shortening (`U̇`, `U`), the centrifugal term
//! (`X`, Southwell's), and the outboard links riding on the shifted chord ends (`P_i`). Since
//! `e_a·n_b = sin(φ_a − φ_b)` and `n_a·n_b = cos(φ_a − φ_b)`, ΔT is a sum of terms of two
//! shapes (`Q = −½qᵀXq`, `B = −qᵀXq̇` of one link's modes; `f` a sine or cosine of a
//! difference of chord angles, `Δ = φ_c − φ_d`):
//!
//! ```text
//! I:  κ φ̇_a φ̇_b f(Δ) Q          II:  κ φ̇_a f(Δ) B
//! ```
//!
//! ([`Term`]), whose M, E = ∂T/∂q, Ṁu, B = ∂²T/∂u∂q and H = ∂²T/∂q² follow term by term below.
//! All come from the one energy, so T + V is conserved and the Jacobian is exact.

use nalgebra::DMatrix;

use crate::kinematics::ArmKinematics;

/// One term of ΔT: `κ φ̇_a φ̇_b f(φ_c − φ_d) Q` (`b` given) or `κ φ̇_a f(φ_c − φ_d) B`.
struct Term<'s> {
    kappa: f64,
    a: usize,
    b: Option<usize>,
    c: usize,
    d: usize,
    sine: bool,
    /// The link whose modes `Q`, `B` are of, and its matrix X.
    link: usize,
    x: &'s DMatrix<f64>,
}

/// `(Xq)_k`.
fn times(x: &DMatrix<f64>, q: &[f64], k: usize) -> f64 {
    q.iter().enumerate().map(|(l, ql)| x[(k, l)] * ql).sum()
}

/// `φ̇_a = Σ_{r≤a} u_r`.
fn rate(u: &[f64], a: usize) -> f64 {
    u[..=a].iter().sum()
}

/// `[r ≤ c] − [r ≤ d]`: `∂(φ_c − φ_d)/∂q_r`.
fn turns(r: usize, c: usize, d: usize) -> f64 {
    f64::from(u8::from(r <= c)) - f64::from(u8::from(r <= d))
}

/// Modes per link the kinetic terms of the shortening handle (their products are kept on
/// the stack); [`ShorteningIntegrals::of`](super::ShorteningIntegrals::of) refuses more.
pub(crate) const MAX_MODES: usize = 64;

/// What a term needs at (q, u): f, f′, f″ of its angle, and `Xq`, `Xq̇`, `Q = −½qᵀXq`,
/// `B = −qᵀXq̇`, `q̇ᵀXq̇` of its link's modes — kept while consecutive terms share X.
struct At<'s> {
    f: [f64; 3],
    o: usize,
    m: usize,
    x: Option<&'s DMatrix<f64>>,
    link: usize,
    xq: [f64; MAX_MODES],
    xu: [f64; MAX_MODES],
    quad: f64,
    bil: f64,
    uxu: f64,
}

impl At<'_> {
    fn new() -> Self {
        Self {
            f: [0.0; 3],
            o: 0,
            m: 0,
            x: None,
            link: usize::MAX,
            xq: [0.0; MAX_MODES],
            xu: [0.0; MAX_MODES],
            quad: 0.0,
            bil: 0.0,
            uxu: 0.0,
        }
    }
}

impl<'a> ArmKinematics<'a> {
    /// Calls `visit` for every term of ΔT (module docs).
    fn shortening_terms_of_t(&self, mut visit: impl FnMut(&Term<'a>)) {
        let arm = self.arm();
        let length = |k: usize| arm.links()[k].length();
        for i in 0..arm.n_links() {
            let g = arm.shape_integrals(i);
            if let Some(sh) = g.shortening() {
                let x = sh.mass();
                for j in 0..i {
                    #[rustfmt::skip]
                    let both = [
                        Term { kappa: length(j), a: j, b: None, c: i, d: j, sine: true, link: i, x },
                        Term { kappa: length(j), a: i, b: Some(j), c: i, d: j, sine: false, link: i, x },
                    ];
                    both.iter().for_each(&mut visit);
                }
                #[rustfmt::skip]
                visit(&Term { kappa: 1.0, a: i, b: Some(i), c: i, d: i, sine: false, link: i, x: sh.moment() });
            }
            let (mi, s1) = (g.mass(), g.first_moment());
            for j in 0..i {
                let Some(shj) = arm.shape_integrals(j).shortening() else {
                    continue;
                };
                let x = shj.chord();
                for k in 0..i {
                    let kappa = mi * length(k);
                    #[rustfmt::skip]
                    let both = [
                        Term { kappa, a: k, b: None, c: j, d: k, sine: true, link: j, x },
                        Term { kappa, a: j, b: Some(k), c: j, d: k, sine: false, link: j, x },
                    ];
                    both.iter().for_each(&mut visit);
                }
                #[rustfmt::skip]
                let both = [
                    Term { kappa: s1, a: i, b: None, c: j, d: i, sine: true, link: j, x },
                    Term { kappa: s1, a: j, b: Some(i), c: j, d: i, sine: false, link: j, x },
                ];
                both.iter().for_each(&mut visit);
            }
        }
    }

    /// `at` for the term `t` at the current q and speeds u (`u` empty: at q only, `B` zero);
    /// the products with X are recomputed only when X or the link changes.
    fn term_at<'s>(&self, at: &mut At<'s>, t: &Term<'s>, u: &[f64]) {
        let (cc, sc) = self.pose.cos_sin(t.c);
        let (cd, sd) = self.pose.cos_sin(t.d);
        let (cos, sin) = (cc * cd + sc * sd, sc * cd - cc * sd);
        at.f = if t.sine {
            [sin, cos, -sin]
        } else {
            [cos, -sin, -cos]
        };
        if at.link == t.link && at.x.is_some_and(|x| std::ptr::eq(x, t.x)) {
            return;
        }
        let q = self.pose.modal(t.link);
        let ub = if u.is_empty() {
            u
        } else {
            self.modal(t.link, u).1
        };
        let m = q.len();
        (at.x, at.link, at.m, at.o) = (Some(t.x), t.link, m, self.arm().modal_offset(t.link));
        (at.quad, at.bil, at.uxu) = (0.0, 0.0, 0.0);
        for k in 0..m {
            let (xq, xu) = (
                times(t.x, q, k),
                ub.get(k).map_or(0.0, |_| times(t.x, ub, k)),
            );
            at.xq[k] = xq;
            at.xu[k] = xu;
            at.quad -= 0.5 * q[k] * xq;
            if let Some(uk) = ub.get(k) {
                at.bil -= xq * uk;
                at.uxu += xu * uk;
            }
        }
    }

    /// `ΔT` at speeds u.
    pub(crate) fn stiffening_kinetic_energy(&self, u: &[f64]) -> f64 {
        let (mut sum, mut at) = (0.0, At::new());
        self.shortening_terms_of_t(|t| {
            self.term_at(&mut at, t, u);
            sum += t.kappa
                * at.f[0]
                * match t.b {
                    Some(b) => rate(u, t.a) * rate(u, b) * at.quad,
                    None => rate(u, t.a) * at.bil,
                };
        });
        sum
    }

    /// `M += ΔM`.
    pub(crate) fn add_stiffening_mass(&self, m: &mut DMatrix<f64>) {
        let mut at = At::new();
        self.shortening_terms_of_t(|t| {
            self.term_at(&mut at, t, &[]);
            let kf = t.kappa * at.f[0];
            match t.b {
                // T = κ f Q φ̇_a φ̇_b: M_rs += κ f Q ([r≤a][s≤b] + [r≤b][s≤a])
                Some(b) => {
                    for r in 0..=t.a {
                        for s in 0..=b {
                            m[(r, s)] += kf * at.quad;
                            m[(s, r)] += kf * at.quad;
                        }
                    }
                }
                // T = κ f φ̇_a (−Xq)·q̇: M_{s,k} = M_{k,s} += κ f (−Xq)_k, s ≤ a
                None => {
                    for k in 0..at.m {
                        let v = -kf * at.xq[k];
                        for s in 0..=t.a {
                            m[(s, at.o + k)] += v;
                            m[(at.o + k, s)] += v;
                        }
                    }
                }
            }
        });
    }

    /// `E += ∂ΔT/∂q` and `Ṁu += (∂ΔM/∂q · u) u` at speeds u.
    pub(crate) fn add_stiffening_kinetic(
        &self,
        u: &[f64],
        e: &mut [f64],
        mut mdot_u: Option<&mut [f64]>,
    ) {
        let mut at = At::new();
        self.shortening_terms_of_t(|t| {
            self.term_at(&mut at, t, u);
            let (kf, kf1) = (t.kappa * at.f[0], t.kappa * at.f[1]);
            let phi_a = rate(u, t.a);
            // Δ̇ = φ̇_c − φ̇_d
            let turn_rate = rate(u, t.c) - rate(u, t.d);
            match t.b {
                Some(b) => {
                    let phi_b = rate(u, b);
                    let ab = phi_a * phi_b;
                    for k in 0..at.m {
                        e[at.o + k] -= kf * ab * at.xq[k];
                    }
                    for (r, er) in e.iter_mut().enumerate().take(t.c.max(t.d) + 1) {
                        *er += kf1 * ab * at.quad * turns(r, t.c, t.d);
                    }
                    if let Some(md) = mdot_u.as_deref_mut() {
                        // Ṁu_s = κ w_s (f B + f′ Q Δ̇), w_s = [s≤a]φ̇_b + [s≤b]φ̇_a
                        let c = kf * at.bil + kf1 * at.quad * turn_rate;
                        for ms in md.iter_mut().take(t.a + 1) {
                            *ms += c * phi_b;
                        }
                        for ms in md.iter_mut().take(b + 1) {
                            *ms += c * phi_a;
                        }
                    }
                }
                None => {
                    for k in 0..at.m {
                        e[at.o + k] -= kf * phi_a * at.xu[k];
                    }
                    for (r, er) in e.iter_mut().enumerate().take(t.c.max(t.d) + 1) {
                        *er += kf1 * phi_a * at.bil * turns(r, t.c, t.d);
                    }
                    if let Some(md) = mdot_u.as_deref_mut() {
                        // joints s ≤ a: κ (f (−Xq̇)·q̇ + f′ B Δ̇)
                        let c = -kf * at.uxu + kf1 * at.bil * turn_rate;
                        for ms in md.iter_mut().take(t.a + 1) {
                            *ms += c;
                        }
                        // modes: κ φ̇_a (f (−Xq̇)_k + f′ (−Xq)_k Δ̇)
                        for k in 0..at.m {
                            md[at.o + k] -= phi_a * (kf * at.xu[k] + kf1 * at.xq[k] * turn_rate);
                        }
                    }
                }
            }
        });
    }

    /// `B[(s, c)] += ∂²ΔT/∂u_s∂q_c`, `H += ∂²ΔT/∂q²` at speeds u.
    pub(crate) fn add_stiffening_kinetic_partials(
        &self,
        u: &[f64],
        bm: &mut DMatrix<f64>,
        h: &mut DMatrix<f64>,
    ) {
        let mut at = At::new();
        self.shortening_terms_of_t(|t| {
            self.term_at(&mut at, t, u);
            let [kf, kf1, kf2] = at.f.map(|f| t.kappa * f);
            let phi_a = rate(u, t.a);
            let (m, o) = (at.m, at.o);
            let joints = t.c.max(t.d) + 1;
            match t.b {
                Some(b) => {
                    let phi_b = rate(u, b);
                    let ab = phi_a * phi_b;
                    for k in 0..m {
                        let xq = at.xq[k];
                        for l in 0..m {
                            h[(o + k, o + l)] -= kf * ab * t.x[(k, l)];
                        }
                        for r in 0..joints {
                            let v = -kf1 * ab * xq * turns(r, t.c, t.d);
                            h[(o + k, r)] += v;
                            h[(r, o + k)] += v;
                        }
                    }
                    for r in 0..joints {
                        for r2 in 0..joints {
                            h[(r, r2)] +=
                                kf2 * ab * at.quad * turns(r, t.c, t.d) * turns(r2, t.c, t.d);
                        }
                    }
                    // ∂T/∂u_s = κ f Q w_s
                    let w = |s: usize| {
                        f64::from(u8::from(s <= t.a)) * phi_b + f64::from(u8::from(s <= b)) * phi_a
                    };
                    for s in 0..=t.a.max(b) {
                        let ws = w(s);
                        for k in 0..m {
                            bm[(s, o + k)] -= kf * ws * at.xq[k];
                        }
                        for r in 0..joints {
                            bm[(s, r)] += kf1 * at.quad * ws * turns(r, t.c, t.d);
                        }
                    }
                }
                None => {
                    for k in 0..m {
                        let xu = at.xu[k];
                        for r in 0..joints {
                            let v = -kf1 * phi_a * xu * turns(r, t.c, t.d);
                            h[(o + k, r)] += v;
                            h[(r, o + k)] += v;
                        }
                    }
                    for r in 0..joints {
                        for r2 in 0..joints {
                            h[(r, r2)] +=
                                kf2 * phi_a * at.bil * turns(r, t.c, t.d) * turns(r2, t.c, t.d);
                        }
                    }
                    for s in 0..=t.a {
                        for k in 0..m {
                            bm[(s, o + k)] -= kf * at.xu[k];
                        }
                        for r in 0..joints {
                            bm[(s, r)] += kf1 * at.bil * turns(r, t.c, t.d);
                        }
                    }
                    for s in 0..m {
                        let xq = at.xq[s];
                        for k in 0..m {
                            bm[(o + s, o + k)] -= kf * phi_a * t.x[(s, k)];
                        }
                        for r in 0..joints {
                            bm[(o + s, r)] -= kf1 * phi_a * xq * turns(r, t.c, t.d);
                        }
                    }
                }
            }
        });
    }
}
