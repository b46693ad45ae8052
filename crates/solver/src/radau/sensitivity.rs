//! Forward sensitivities alongside Radau IIA, by the staggered direct method.
//!
//! For y' = f(t, y, p) the sensitivities s_k = ∂y/∂p_k obey the linear equations
//! s_k' = J(t, y)·s_k + ∂f/∂p_k (J = ∂f/∂y). After each accepted step of the state, the
//! same Radau IIA collocation is applied to them on the step's stage points (tₙ + cⱼh,
//! Yⱼ): with Σⱼ = Sⱼ − sₙ the stage increments,
//!
//! ```text
//!   Σ = h (A⊗I) G(Σ),   Gⱼ = J(tₙ + cⱼh, Yⱼ)(sₙ + Σⱼ) + ∂f/∂p(tₙ + cⱼh, Yⱼ)
//! ```
//!
//! a linear system, solved by the same transformed iteration as the state's Newton step and
//! with the step's own LU factors of (γ/h)I − J̃ and ((α + iβ)/h)I − J̃ (J̃ the Jacobian the
//! step used): each iteration costs three products Gⱼ and one real plus one complex solve
//! per parameter. The residual uses the exact Jacobian at every stage point, so the
//! sensitivities are the Radau IIA solution of their own equations (order 5, consistent
//! with the state), not an approximation frozen at J̃; the iteration converges at the rate
//! of the state's Newton iteration (h‖J − J̃‖), to round-off.
//!
//! No error control of the sensitivities: they follow the state's steps (the usual choice
//! of the staggered direct method; the tests measure their error against differences of
//! whole runs). Dense output: the stages' collocation polynomial, as for the state.
//! Nothing here allocates after [`Sensitivities::new`].

use super::linear::Linear;
use super::{DMatrix, Radau5, RadauError};

/// What the sensitivity equations need of the problem on each stage point of an accepted
/// step.
pub trait SensitivityRhs {
    /// Number of parameters (columns of s).
    fn n_params(&self) -> usize;
    /// Get ready for `apply` at stage `stage` (0, 1, 2) of the step just accepted, at the
    /// stage point (t, y): the Jacobian there, ∂f/∂p there.
    fn prepare(&mut self, stage: usize, t: f64, y: &[f64]);
    /// `out = J·s + ∂f/∂p_k` at the prepared stage `stage`.
    fn apply(&mut self, stage: usize, k: usize, s: &[f64], out: &mut [f64]);
    /// The dense Jacobian at the last stage point (the step's end), if prepared: when the
    /// step's LU is too far from the stages' Jacobians for the iteration to converge, the
    /// integrator takes it (it is current there) and factorises anew.
    fn end_jacobian(&self) -> Option<&DMatrix<f64>> {
        None
    }
}

/// Iterations of the stage solve before the LU is renewed (the linear system converges at
/// the state's Newton rate, usually ≤ 0.03: a few iterations), and after.
const MAX_ITERATIONS: usize = 12;
const MAX_ITERATIONS_RENEWED: usize = 40;
/// Convergence rate above which the LU is renewed at once.
const SLOW: f64 = 0.3;

/// The sensitivities of one run: n states × `n_params` columns, stored column by column
/// (`s[k·n + i]` = ∂yᵢ/∂p_k).
#[derive(Clone, Debug)]
pub struct Sensitivities {
    n: usize,
    np: usize,
    /// The nodes c of the tableau.
    c: [f64; 3],
    s: Vec<f64>,
    s_prev: Vec<f64>,
    /// Divided differences of the last step's collocation polynomial, per column.
    cont: [Vec<f64>; 3],
    has_poly: bool,
    t: f64,
    t_prev: f64,
    h_last: f64,
    /// The integrator's accepted steps when this last caught up.
    steps_seen: usize,
    z: [Vec<f64>; 3],
    w: [Vec<f64>; 3],
    g: [Vec<f64>; 3],
    stmp: Vec<f64>,
    ytmp: Vec<f64>,
    dr: Vec<f64>,
    dre: Vec<f64>,
    dim: Vec<f64>,
    /// Iterations of the stage solves, summed over steps and parameters.
    pub iterations: usize,
    /// Steps the sensitivities followed.
    pub steps: usize,
    /// Times the step's LU was renewed for them.
    pub renewals: usize,
}

impl Sensitivities {
    /// Start at the integrator's current time with `s0` (n × `np`, column by column).
    pub fn new(radau: &Radau5, np: usize, s0: &[f64]) -> Result<Self, RadauError> {
        let n = radau.n;
        if s0.len() != n * np {
            return Err(RadauError::DimensionMismatch {
                what: "the initial sensitivities",
                expected: n * np,
                got: s0.len(),
            });
        }
        let buf = |m: usize| vec![0.0; m];
        Ok(Self {
            n,
            np,
            c: radau.tab.c,
            s: s0.to_vec(),
            s_prev: s0.to_vec(),
            cont: [buf(n * np), buf(n * np), buf(n * np)],
            has_poly: false,
            t: radau.t,
            t_prev: radau.t,
            h_last: 0.0,
            steps_seen: radau.stats.steps,
            z: [buf(n), buf(n), buf(n)],
            w: [buf(n), buf(n), buf(n)],
            g: [buf(n), buf(n), buf(n)],
            stmp: buf(n),
            ytmp: buf(n),
            dr: buf(n),
            dre: buf(n),
            dim: buf(n),
            iterations: 0,
            steps: 0,
            renewals: 0,
        })
    }

    /// The current sensitivities (column k = ∂y/∂p_k).
    #[must_use]
    pub fn s(&self) -> &[f64] {
        &self.s
    }

    /// Number of parameters.
    #[must_use]
    pub fn n_params(&self) -> usize {
        self.np
    }

    /// Follow the integrator after [`Radau5::restart`] (or a new integrator at the same
    /// time): keep s, forget the polynomial.
    pub fn restart(&mut self, radau: &Radau5) {
        self.steps_seen = radau.stats.steps;
        self.s_prev.copy_from_slice(&self.s);
        self.t = radau.t;
        self.t_prev = radau.t;
        self.has_poly = false;
    }

    /// Advance over the step `radau` has just accepted (nothing if it accepted none since
    /// the last call, e.g. a landing on its stop time within round-off).
    pub fn step(
        &mut self,
        radau: &mut Radau5,
        sys: &mut impl SensitivityRhs,
    ) -> Result<(), RadauError> {
        if radau.stats.steps == self.steps_seen {
            self.t = radau.t;
            return Ok(());
        }
        if radau.stats.steps != self.steps_seen + 1 {
            return Err(RadauError::InvalidOption {
                option: "sensitivities",
                message: "must follow every accepted step".into(),
            });
        }
        self.steps_seen = radau.stats.steps;
        let (n, h, t0) = (self.n, radau.h_last, radau.t_prev);
        let tab = radau.tab.clone();
        for j in 0..3 {
            for ((yt, y), z) in self.ytmp.iter_mut().zip(&radau.y_prev).zip(&radau.z[j]) {
                *yt = y + z;
            }
            sys.prepare(j, t0 + tab.c[j] * h, &self.ytmp);
        }
        let (fac1, alphn, betan) = (tab.gamma / h, tab.alpha / h, tab.beta / h);
        // Converged to well below the state's own tolerance.
        let tol = (1e-3 * radau.rtol).clamp(1e-13, 1e-8);
        self.s_prev.copy_from_slice(&self.s);
        for k in 0..self.np {
            let col = k * n..(k + 1) * n;
            // Starting values: the last step's collocation polynomial, extrapolated (as the
            // state's Newton iteration starts).
            if self.has_poly {
                let ratio = h / self.h_last;
                let sc = [tab.c[0] * ratio, tab.c[1] * ratio, tab.c[2] * ratio];
                let (c1m1, c2m1) = (tab.c[0] - 1.0, tab.c[1] - 1.0);
                for i in 0..n {
                    let ci = k * n + i;
                    let (a1, a2, a3) = (self.cont[0][ci], self.cont[1][ci], self.cont[2][ci]);
                    let zk = |q: usize| sc[q] * (a1 + (sc[q] - c2m1) * (a2 + (sc[q] - c1m1) * a3));
                    let zi = [zk(0), zk(1), zk(2)];
                    for q in 0..3 {
                        self.z[q][i] = zi[q];
                        self.w[q][i] =
                            tab.ti[q][0] * zi[0] + tab.ti[q][1] * zi[1] + tab.ti[q][2] * zi[2];
                    }
                }
            } else {
                for j in 0..3 {
                    self.z[j].fill(0.0);
                    self.w[j].fill(0.0);
                }
            }
            let mut converged = false;
            let mut renewed = false;
            loop {
                let sp = &self.s_prev[col.clone()];
                let scale = sp.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let mut last = f64::INFINITY;
                let limit = if renewed {
                    MAX_ITERATIONS_RENEWED
                } else {
                    MAX_ITERATIONS
                };
                for it in 0..limit {
                    for j in 0..3 {
                        for ((st, s), z) in self.stmp.iter_mut().zip(sp).zip(&self.z[j]) {
                            *st = s + z;
                        }
                        sys.apply(j, k, &self.stmp, &mut self.g[j]);
                    }
                    let [g0, g1, g2] = &self.g;
                    let [w0, w1, w2] = &self.w;
                    for i in 0..n {
                        let (a1, a2, a3) = (g0[i], g1[i], g2[i]);
                        let gk =
                            |m: usize| tab.ti[m][0] * a1 + tab.ti[m][1] * a2 + tab.ti[m][2] * a3;
                        let (v1, v2, v3) = (w0[i], w1[i], w2[i]);
                        self.dr[i] = gk(0) - fac1 * v1;
                        self.dre[i] = gk(1) - (alphn * v2 - betan * v3);
                        self.dim[i] = gk(2) - (betan * v2 + alphn * v3);
                    }
                    radau.lin.solve_real(&mut self.dr);
                    radau.lin.solve_complex(&mut self.dre, &mut self.dim);
                    self.iterations += 1;
                    let (mut dmax, mut zmax) = (0.0f64, 0.0f64);
                    let [w0, w1, w2] = &mut self.w;
                    let [z0, z1, z2] = &mut self.z;
                    for i in 0..n {
                        let (a, b, c) = (self.dr[i], self.dre[i], self.dim[i]);
                        dmax = dmax.max(a.abs()).max(b.abs()).max(c.abs());
                        w0[i] += a;
                        w1[i] += b;
                        w2[i] += c;
                        let (v1, v2, v3) = (w0[i], w1[i], w2[i]);
                        let zk = |m: usize| tab.t[m][0] * v1 + tab.t[m][1] * v2 + tab.t[m][2] * v3;
                        (z0[i], z1[i], z2[i]) = (zk(0), zk(1), zk(2));
                        zmax = zmax.max(z0[i].abs()).max(z1[i].abs()).max(z2[i].abs());
                    }
                    if !dmax.is_finite() {
                        break;
                    }
                    if dmax <= tol * (scale + zmax) || dmax == 0.0 {
                        converged = true;
                        break;
                    }
                    if !renewed && it >= 2 && dmax > SLOW * last {
                        break;
                    }
                    last = dmax;
                }
                if converged || renewed {
                    break;
                }
                // Too slow with the step's LU: renew it from the Jacobian at the step's end.
                renewed = true;
                let Some(jac) = sys.end_jacobian() else { break };
                let Linear::Dense { jac: j, .. } = &mut radau.lin else {
                    break;
                };
                j.copy_from(jac);
                if radau.factorise(h).is_err() {
                    radau.lu_h = None;
                    radau.need_jac = true;
                    break;
                }
                radau.lu_h = Some(h);
                radau.jac_current = true;
                radau.need_jac = false;
                for j in 0..3 {
                    self.z[j].fill(0.0);
                    self.w[j].fill(0.0);
                }
                self.renewals += 1;
            }
            if !converged {
                return Err(RadauError::NewtonDiverged { t: t0, h });
            }
            // s₁ = s₀ + Σ₃ and the collocation polynomial (as `Radau5::accept`).
            let c = tab.c;
            let (c1m1, c2m1, c1mc2) = (c[0] - 1.0, c[1] - 1.0, c[0] - c[1]);
            for i in 0..n {
                let (z1, z2, z3) = (self.z[0][i], self.z[1][i], self.z[2][i]);
                self.s[k * n + i] = self.s_prev[k * n + i] + z3;
                let d01 = (z2 - z3) / c2m1;
                let d12 = (z1 - z2) / c1mc2;
                let d23 = z1 / c[0];
                let d012 = (d12 - d01) / c1m1;
                let d123 = (d12 - d23) / c[1];
                self.cont[0][k * n + i] = d01;
                self.cont[1][k * n + i] = d012;
                self.cont[2][k * n + i] = d012 - d123;
            }
        }
        self.t_prev = t0;
        self.t = radau.t;
        self.h_last = h;
        self.has_poly = true;
        self.steps += 1;
        Ok(())
    }

    /// The sensitivities at `t` inside the last step (its collocation polynomial), into
    /// `out` (n × `np`, column by column).
    pub fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), RadauError> {
        if out.len() != self.s.len() {
            return Err(RadauError::DimensionMismatch {
                what: "the sensitivity buffer",
                expected: self.s.len(),
                got: out.len(),
            });
        }
        let slack = 8.0 * f64::EPSILON * (self.t.abs().max(self.t_prev.abs()) + self.h_last);
        if !(t >= self.t_prev - slack && t <= self.t + slack) {
            return Err(RadauError::OutsideStep {
                t,
                t_prev: self.t_prev,
                t_now: self.t,
            });
        }
        if t >= self.t || !self.has_poly {
            out.copy_from_slice(&self.s);
            return Ok(());
        }
        if t <= self.t_prev {
            out.copy_from_slice(&self.s_prev);
            return Ok(());
        }
        let c = self.c;
        let s = (t - self.t) / self.h_last;
        let (c1m1, c2m1) = (c[0] - 1.0, c[1] - 1.0);
        for (i, o) in out.iter_mut().enumerate() {
            let (a1, a2, a3) = (self.cont[0][i], self.cont[1][i], self.cont[2][i]);
            *o = self.s[i] + s * (a1 + (s - c2m1) * (a2 + (s - c1m1) * a3));
        }
        Ok(())
    }
}
