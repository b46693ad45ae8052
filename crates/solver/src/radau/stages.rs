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
            for i in 0..n {
                let (a1, a2, a3) = (self.cont[0][i], self.cont[1][i], self.cont[2][i]);
                let mut zi = [0.0; 3];
                for k in 0..3 {
                    zi[k] = s[k] * (a1 + (s[k] - c2m1) * (a2 + (s[k] - c1m1) * a3));
                    self.z[k][i] = zi[k];
                }
                for k in 0..3 {
                    self.w[k][i] =
                        tab.ti[k][0] * zi[0] + tab.ti[k][1] * zi[1] + tab.ti[k][2] * zi[2];
                }
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
            for i in 0..n {
                let (a1, a2, a3) = (self.fk[0][i], self.fk[1][i], self.fk[2][i]);
                let g = |k: usize| tab.ti[k][0] * a1 + tab.ti[k][1] * a2 + tab.ti[k][2] * a3;
                let (w1, w2, w3) = (self.w[0][i], self.w[1][i], self.w[2][i]);
                self.dw_real[i] = g(0) - fac1 * w1;
                self.dw_re[i] = g(1) - (alphn * w2 - betan * w3);
                self.dw_im[i] = g(2) - (betan * w2 + alphn * w3);
            }
            self.lin.solve_real(&mut self.dw_real);
            self.lin.solve_complex(&mut self.dw_re, &mut self.dw_im);
            newt += 1;
            self.stats.newton_iterations += 1;
            let mut sum = 0.0;
            for i in 0..n {
                let s = self.scal[i];
                let (a, b, c) = (self.dw_real[i] / s, self.dw_re[i] / s, self.dw_im[i] / s);
                sum += a * a + b * b + c * c;
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
            for i in 0..n {
                self.w[0][i] += self.dw_real[i];
                self.w[1][i] += self.dw_re[i];
                self.w[2][i] += self.dw_im[i];
                let (w1, w2, w3) = (self.w[0][i], self.w[1][i], self.w[2][i]);
                for k in 0..3 {
                    self.z[k][i] = tab.t[k][0] * w1 + tab.t[k][1] * w2 + tab.t[k][2] * w3;
                }
            }
            if self.faccon * dyno <= self.fnewt {
                return Ok(newt);
            }
        }
    }

    /// The filtered embedded error estimate, in the RMS norm scaled by the tolerances.
    pub(super) fn error_estimate(&mut self, sys: &mut impl OdeSystem, h: f64) -> f64 {
        let d = [self.tab.d[0] / h, self.tab.d[1] / h, self.tab.d[2] / h];
        for i in 0..self.n {
            let dz = d[0] * self.z[0][i] + d[1] * self.z[1][i] + d[2] * self.z[2][i];
            self.err_f[i] = dz;
            self.err_v[i] = self.f0[i] + dz;
            let y1 = self.y[i] + self.z[2][i];
            self.scal[i] = self.atol[i] + self.rtol * self.y[i].abs().max(y1.abs());
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
        for i in 0..self.n {
            let (z1, z2, z3) = (self.z[0][i], self.z[1][i], self.z[2][i]);
            self.y_prev[i] = self.y[i];
            self.y[i] += z3;
            // Newton divided differences through s = 0, c₂−1, c₁−1, −1 (values z₃, z₂, z₁, 0
            // relative to y₁ − z₃).
            let d01 = (z2 - z3) / c2m1;
            let d12 = (z1 - z2) / c1mc2;
            let d23 = z1 / c[0];
            let d012 = (d12 - d01) / c1m1;
            let d123 = (d12 - d23) / c[1];
            self.cont[0][i] = d01;
            self.cont[1][i] = d012;
            self.cont[2][i] = d012 - d123;
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
