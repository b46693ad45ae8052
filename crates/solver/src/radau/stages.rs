//! One step's work: the two LU factorisations, the simplified Newton iteration on the
//! transformed stage equations, the filtered error estimate and, on acceptance, the new
//! collocation polynomial.

use nalgebra::Complex;

use super::{OdeSystem, Radau5};

impl Radau5 {
    /// Form and factorise (γ/h)I − J and ((α + iβ)/h)I − J.
    pub(super) fn factorise(&mut self, h: f64) -> Result<(), ()> {
        let shift = Complex::new(self.tab.alpha / h, self.tab.beta / h);
        self.lin.factorise(self.tab.gamma / h, shift)
    }

    /// Simplified Newton for the stage values of a step of size h. Returns the number of
    /// iterations, or the factor to shrink h by.
    pub(super) fn newton(&mut self, sys: &mut impl OdeSystem, h: f64) -> Result<usize, f64> {
        let n = self.n;
        let tab = &self.tab;
        let (c1m1, c2m1) = (tab.c[0] - 1.0, tab.c[1] - 1.0);
        // Starting values: the last collocation polynomial, extrapolated.
        if self.has_poly {
            let ratio = h / self.h_last;
            let s = [tab.c[0] * ratio, tab.c[1] * ratio, tab.c[2] * ratio];
            // Every slice cut to n, so that the loops run without bounds checks.
            let [c0, c1, c2] = &self.cont;
            let (c0, c1, c2) = (&c0[..n], &c1[..n], &c2[..n]);
            let [z0, z1, z2] = &mut self.z;
            let (z0, z1, z2) = (&mut z0[..n], &mut z1[..n], &mut z2[..n]);
            let [w0, w1, w2] = &mut self.w;
            let (w0, w1, w2) = (&mut w0[..n], &mut w1[..n], &mut w2[..n]);
            for i in 0..n {
                let (a1, a2, a3) = (c0[i], c1[i], c2[i]);
                let zk = |k: usize| s[k] * (a1 + (s[k] - c2m1) * (a2 + (s[k] - c1m1) * a3));
                let zi = [zk(0), zk(1), zk(2)];
                (z0[i], z1[i], z2[i]) = (zi[0], zi[1], zi[2]);
                let wk =
                    |k: usize| tab.ti[k][0] * zi[0] + tab.ti[k][1] * zi[1] + tab.ti[k][2] * zi[2];
                (w0[i], w1[i], w2[i]) = (wk(0), wk(1), wk(2));
            }
        } else {
            for k in 0..3 {
                self.z[k].fill(0.0);
                self.w[k].fill(0.0);
            }
        }
        for ((s, a), y) in self.scal.iter_mut().zip(&self.atol).zip(&self.y) {
            *s = a + self.rtol * y.abs();
        }
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        self.theta = self.thet;
        let (fac1, alphn, betan) = (tab.gamma / h, tab.alpha / h, tab.beta / h);
        let nit = self.nit;
        let (mut dyno_old, mut thq_old) = (1.0, 1.0);
        let mut newt = 0;
        loop {
            if newt >= nit {
                return Err(0.5);
            }
            for k in 0..3 {
                for ((yt, y), z) in self.ytmp.iter_mut().zip(&self.y).zip(&self.z[k]) {
                    *yt = y + z;
                }
                sys.rhs(self.t + tab.c[k] * h, &self.ytmp, &mut self.fk[k]);
            }
            self.stats.rhs_evaluations += 3;
            // Right-hand sides of the transformed systems.
            {
                let [f0, f1, f2] = &self.fk;
                let (f0, f1, f2) = (&f0[..n], &f1[..n], &f2[..n]);
                let [w0, w1, w2] = &self.w;
                let (w0, w1, w2) = (&w0[..n], &w1[..n], &w2[..n]);
                let (dr, dre, dim) = (
                    &mut self.dw_real[..n],
                    &mut self.dw_re[..n],
                    &mut self.dw_im[..n],
                );
                for i in 0..n {
                    let (a1, a2, a3) = (f0[i], f1[i], f2[i]);
                    let g = |k: usize| tab.ti[k][0] * a1 + tab.ti[k][1] * a2 + tab.ti[k][2] * a3;
                    let (w1, w2, w3) = (w0[i], w1[i], w2[i]);
                    dr[i] = g(0) - fac1 * w1;
                    dre[i] = g(1) - (alphn * w2 - betan * w3);
                    dim[i] = g(2) - (betan * w2 + alphn * w3);
                }
            }
            self.lin.solve_real(&mut self.dw_real);
            self.lin.solve_complex(&mut self.dw_re, &mut self.dw_im);
            newt += 1;
            self.stats.newton_iterations += 1;
            // The new iterate w ← w + Δw, z = T·w, and each state's scaled |Δw|² (into ytmp,
            // free until the next right-hand sides), in one pass the compiler vectorises; then
            // their sum, in state order. On a return below before convergence z and w are
            // discarded: the next attempt starts them afresh.
            {
                let (dr, dre, dim) = (&self.dw_real[..n], &self.dw_re[..n], &self.dw_im[..n]);
                let (scal, sq) = (&self.scal[..n], &mut self.ytmp[..n]);
                let [w0, w1, w2] = &mut self.w;
                let (w0, w1, w2) = (&mut w0[..n], &mut w1[..n], &mut w2[..n]);
                let [z0, z1, z2] = &mut self.z;
                let (z0, z1, z2) = (&mut z0[..n], &mut z1[..n], &mut z2[..n]);
                for i in 0..n {
                    let s = scal[i];
                    let (a, b, c) = (dr[i] / s, dre[i] / s, dim[i] / s);
                    sq[i] = a * a + b * b + c * c;
                    w0[i] += dr[i];
                    w1[i] += dre[i];
                    w2[i] += dim[i];
                    let (v1, v2, v3) = (w0[i], w1[i], w2[i]);
                    let zk = |k: usize| tab.t[k][0] * v1 + tab.t[k][1] * v2 + tab.t[k][2] * v3;
                    (z0[i], z1[i], z2[i]) = (zk(0), zk(1), zk(2));
                }
            }
            let mut sum = 0.0;
            for &q in &self.ytmp[..n] {
                sum += q;
            }
            let dyno = (sum / (3 * n).max(1) as f64).sqrt();
            if !dyno.is_finite() {
                return Err(0.5);
            }
            if newt > 1 && newt < nit {
                let thq = dyno / dyno_old;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thq_old).sqrt()
                };
                thq_old = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let remaining = (nit - 1 - newt) as i32;
                    let dyth = self.faccon * dyno * self.theta.powi(remaining) / self.fnewt;
                    if dyth >= 1.0 {
                        // Not going to converge in time: shrink h by the predicted factor.
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        return Err(0.8 * qnewt.powf(-1.0 / (4.0 + f64::from(remaining))));
                    }
                } else {
                    return Err(0.5);
                }
            }
            dyno_old = dyno.max(f64::EPSILON);
            if self.faccon * dyno <= self.fnewt {
                return Ok(newt);
            }
        }
    }

    /// The filtered embedded error estimate, in the RMS norm scaled by the tolerances.
    pub(super) fn error_estimate(&mut self, sys: &mut impl OdeSystem, h: f64) -> f64 {
        let d = [self.tab.d[0] / h, self.tab.d[1] / h, self.tab.d[2] / h];
        let (n, rtol) = (self.n, self.rtol);
        let [z0, z1, z2] = &self.z;
        let (z0, z1, z2) = (&z0[..n], &z1[..n], &z2[..n]);
        let (f0, y, atol) = (&self.f0[..n], &self.y[..n], &self.atol[..n]);
        let (err_f, err_v, scal) = (
            &mut self.err_f[..n],
            &mut self.err_v[..n],
            &mut self.scal[..n],
        );
        for i in 0..n {
            let dz = d[0] * z0[i] + d[1] * z1[i] + d[2] * z2[i];
            err_f[i] = dz;
            err_v[i] = f0[i] + dz;
            let y1 = y[i] + z2[i];
            scal[i] = atol[i] + rtol * y[i].abs().max(y1.abs());
        }
        self.lin.solve_real(&mut self.err_v);
        let mut err = Self::norm(&self.err_v, &self.scal).max(1e-10);
        if err >= 1.0 && (self.ctrl.first() || self.reject) {
            // Second filtering: stiff components of the first estimate are unreliable.
            for ((yt, y), e) in self.ytmp.iter_mut().zip(&self.y).zip(&self.err_v) {
                *yt = y + e;
            }
            sys.rhs(self.t, &self.ytmp, &mut self.fk[0]);
            self.stats.rhs_evaluations += 1;
            for ((e, f), dz) in self.err_v.iter_mut().zip(&self.fk[0]).zip(&self.err_f) {
                *e = f + dz;
            }
            self.lin.solve_real(&mut self.err_v);
            err = Self::norm(&self.err_v, &self.scal).max(1e-10);
        }
        if err.is_finite() {
            err
        } else {
            1e10
        }
    }

    /// Move to the end of an accepted step of size h and keep its collocation polynomial.
    pub(super) fn accept(&mut self, h: f64, t_new: f64) {
        let c = self.tab.c;
        let (c1m1, c2m1, c1mc2) = (c[0] - 1.0, c[1] - 1.0, c[0] - c[1]);
        let n = self.n;
        let [za, zb, zc] = &self.z;
        let (za, zb, zc) = (&za[..n], &zb[..n], &zc[..n]);
        let (y, y_prev) = (&mut self.y[..n], &mut self.y_prev[..n]);
        let [k0, k1, k2] = &mut self.cont;
        let (k0, k1, k2) = (&mut k0[..n], &mut k1[..n], &mut k2[..n]);
        for i in 0..n {
            let (z1, z2, z3) = (za[i], zb[i], zc[i]);
            y_prev[i] = y[i];
            y[i] += z3;
            // Newton divided differences through s = 0, c₂−1, c₁−1, −1 (values z₃, z₂, z₁, 0
            // relative to y₁ − z₃).
            let d01 = (z2 - z3) / c2m1;
            let d12 = (z1 - z2) / c1mc2;
            let d23 = z1 / c[0];
            let d012 = (d12 - d01) / c1m1;
            let d123 = (d12 - d23) / c[1];
            k0[i] = d01;
            k1[i] = d012;
            k2[i] = d012 - d123;
        }
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.has_poly = true;
        self.f0_valid = false;
        self.jac_current = false;
        self.stats.steps += 1;
    }
}
