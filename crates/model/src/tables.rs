//! Lookup tables (`[tables]`): 1-D `y(x)` and 2-D `z(x, y)`, called like functions in any
//! expression (`valve_flow(x_v)`, `eta(n, dp)`), with their exact derivatives for the
//! Jacobian.
//!
//! ```toml
//! [tables]
//! valve_flow = { x = [0, 0.5, 1], y = [0, 2e-4, 1e-3], interp = "cubic" }
//! eta = { x = [1000, 2000], y = [0, 1e7, 2e7], z = [[0.9, 0.85, 0.8], [0.92, 0.88, 0.84]] }
//! pump = { file = "pump_eff.csv", interp = "linear", extrapolate = "hold" }
//! ```
//!
//! * `interp = "linear"` (the default): piecewise linear in 1-D, bilinear in 2-D.
//!   `"cubic"`: piecewise cubic Hermite with Fritsch–Carlson slopes (monotone data stay
//!   monotone, no overshoot; C¹), and in 2-D the tensor product of the same (bicubic
//!   Hermite: slopes along x and y by Fritsch–Carlson, the cross slope by Fritsch–Carlson
//!   of the x-slopes along y; C¹).
//! * `extrapolate = "hold"` (the default: the end values, zero slope), `"linear"` (the end
//!   pieces' slopes go on), `"error"` (outside the table the value is NaN, which stops the
//!   run naming the element that read it).
//! * In 2-D, `z[i][j]` is the value at `(x[i], y[j])`: one row per x.
//!
//! Evaluation allocates nothing: a binary search per argument and a few multiplications;
//! [`Table::eval`] returns the value and writes the partial derivatives with respect to
//! each argument (exact for the piecewise polynomial; at a knot, the right piece's).
//!
//! Written here rather than taken from a crate: the interpolation crates on crates.io
//! (`splines`, `ndarray-interp`, `interp`, `enterpolation`) either allocate per call, lack
//! the derivative, lack a monotone (Fritsch–Carlson) cubic, or lack 2-D; the whole of what
//! is needed is the 150 lines below, tested against central differences and closed forms.

/// How a table goes from one knot to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableInterp {
    /// Linear (1-D), bilinear (2-D).
    Linear,
    /// Monotone cubic Hermite (Fritsch–Carlson), bicubic Hermite in 2-D.
    Cubic,
}

/// What a table does outside its knots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableExtrapolate {
    /// The end value (zero slope).
    Hold,
    /// The end piece's slope goes on.
    Linear,
    /// NaN: the run stops, naming the element that read it.
    Error,
}

/// One axis of a table: its knots, and the piece holding an argument.
#[derive(Clone, Debug)]
struct Axis {
    knots: Vec<f64>,
}

/// Where an argument falls on an axis: the piece `i` (between knots i and i + 1), the
/// local coordinate `s` in [0, 1] (beyond it when extrapolating linearly), and whether it
/// was held at an end (its derivative is then zero).
#[derive(Clone, Copy, Debug)]
struct Place {
    i: usize,
    s: f64,
    h: f64,
    held: bool,
    outside: bool,
}

impl Axis {
    fn place(&self, v: f64, ex: TableExtrapolate) -> Place {
        let k = &self.knots;
        let n = k.len();
        let i = k.partition_point(|&x| x <= v).clamp(1, n - 1) - 1;
        let h = k[i + 1] - k[i];
        let mut s = (v - k[i]) / h;
        let outside = v < k[0] || v > k[n - 1];
        let held = outside && ex != TableExtrapolate::Linear;
        if held {
            s = s.clamp(0.0, 1.0);
        }
        Place {
            i,
            s,
            h,
            held,
            outside,
        }
    }
}

/// Fritsch–Carlson slopes of the data `y` over knots `x` (monotone cubic Hermite).
fn fritsch_carlson(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let delta: Vec<f64> = (0..n - 1)
        .map(|k| (y[k + 1] - y[k]) / (x[k + 1] - x[k]))
        .collect();
    let mut m = vec![0.0; n];
    m[0] = delta[0];
    m[n - 1] = delta[n - 2];
    for k in 1..n - 1 {
        m[k] = if delta[k - 1] * delta[k] <= 0.0 {
            0.0
        } else {
            (delta[k - 1] + delta[k]) / 2.0
        };
    }
    for k in 0..n - 1 {
        if delta[k] == 0.0 {
            m[k] = 0.0;
            m[k + 1] = 0.0;
            continue;
        }
        let (a, b) = (m[k] / delta[k], m[k + 1] / delta[k]);
        let r = a * a + b * b;
        if r > 9.0 {
            let t = 3.0 / r.sqrt();
            m[k] = t * a * delta[k];
            m[k + 1] = t * b * delta[k];
        }
    }
    m
}

/// Cubic Hermite basis at s ∈ [0, 1] and its derivative in s: (h00, h10, h01, h11).
fn hermite(s: f64) -> ([f64; 4], [f64; 4]) {
    let (s2, s3) = (s * s, s * s * s);
    (
        [
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        ],
        [
            6.0 * s2 - 6.0 * s,
            3.0 * s2 - 4.0 * s + 1.0,
            -6.0 * s2 + 6.0 * s,
            3.0 * s2 - 2.0 * s,
        ],
    )
}

/// The weights of the two knots' values and slopes along one axis at a place, and their
/// derivatives with respect to the argument: (values w0, w1; slopes m0, m1).
fn weights(p: &Place, interp: TableInterp) -> ([f64; 4], [f64; 4]) {
    let s = p.s;
    let (w, dw) = match interp {
        TableInterp::Linear => ([1.0 - s, 0.0, s, 0.0], [-1.0, 0.0, 1.0, 0.0]),
        TableInterp::Cubic if p.outside => {
            // linear extrapolation of the cubic: the end value and end slope
            let at_end = if s >= 1.0 { 1.0 } else { 0.0 };
            let d = s - at_end;
            if at_end > 0.0 {
                ([0.0, 0.0, 1.0, d], [0.0, 0.0, 0.0, 1.0])
            } else {
                ([1.0, d, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0])
            }
        }
        TableInterp::Cubic => {
            let (h, dh) = hermite(s);
            ([h[0], h[1], h[2], h[3]], [dh[0], dh[1], dh[2], dh[3]])
        }
    };
    // slopes are per unit of the argument: the basis of a slope carries the piece length
    let w = [w[0], w[1] * p.h, w[2], w[3] * p.h];
    let scale = if p.held { 0.0 } else { 1.0 / p.h };
    let dw = [
        dw[0] * scale,
        dw[1] * p.h * scale,
        dw[2] * scale,
        dw[3] * p.h * scale,
    ];
    (w, dw)
}

/// A lookup table (see the module documentation).
#[derive(Clone, Debug)]
pub struct Table {
    /// Its name in expressions.
    pub name: String,
    x: Axis,
    y: Option<Axis>,
    /// Values: `nx` (1-D) or `nx·ny` row-major (2-D).
    v: Vec<f64>,
    /// Slopes along x, along y, and cross (cubic only).
    vx: Vec<f64>,
    vy: Vec<f64>,
    vxy: Vec<f64>,
    interp: TableInterp,
    extrapolate: TableExtrapolate,
}

impl Table {
    /// A 1-D table `y(x)`; the data are checked by the loader ([`crate::load`]).
    #[must_use]
    pub fn one(
        name: &str,
        x: Vec<f64>,
        y: Vec<f64>,
        interp: TableInterp,
        extrapolate: TableExtrapolate,
    ) -> Self {
        let vx = match interp {
            TableInterp::Cubic => fritsch_carlson(&x, &y),
            TableInterp::Linear => Vec::new(),
        };
        Self {
            name: name.to_owned(),
            x: Axis { knots: x },
            y: None,
            v: y,
            vx,
            vy: Vec::new(),
            vxy: Vec::new(),
            interp,
            extrapolate,
        }
    }

    /// A 2-D table `z(x, y)`, `z[i][j]` at `(x[i], y[j])`.
    #[must_use]
    pub fn two(
        name: &str,
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<Vec<f64>>,
        interp: TableInterp,
        extrapolate: TableExtrapolate,
    ) -> Self {
        let (nx, ny) = (x.len(), y.len());
        let v: Vec<f64> = z.iter().flatten().copied().collect();
        let (mut vx, mut vy, mut vxy) = (Vec::new(), Vec::new(), Vec::new());
        if interp == TableInterp::Cubic {
            vx = vec![0.0; nx * ny];
            vy = vec![0.0; nx * ny];
            vxy = vec![0.0; nx * ny];
            for j in 0..ny {
                let col: Vec<f64> = (0..nx).map(|i| v[i * ny + j]).collect();
                for (i, m) in fritsch_carlson(&x, &col).into_iter().enumerate() {
                    vx[i * ny + j] = m;
                }
            }
            for i in 0..nx {
                let row = &v[i * ny..(i + 1) * ny];
                vy[i * ny..(i + 1) * ny].copy_from_slice(&fritsch_carlson(&y, row));
                let rowx: Vec<f64> = vx[i * ny..(i + 1) * ny].to_vec();
                vxy[i * ny..(i + 1) * ny].copy_from_slice(&fritsch_carlson(&y, &rowx));
            }
        }
        Self {
            name: name.to_owned(),
            x: Axis { knots: x },
            y: Some(Axis { knots: y }),
            v,
            vx,
            vy,
            vxy,
            interp,
            extrapolate,
        }
    }

    /// Number of arguments: 1 or 2.
    #[must_use]
    pub fn arity(&self) -> usize {
        if self.y.is_some() {
            2
        } else {
            1
        }
    }

    /// The value at `args` (as many as [`arity`](Self::arity)), and the partial derivative
    /// with respect to each argument in `d`.
    pub fn eval(&self, args: &[f64], d: &mut [f64; 2]) -> f64 {
        *d = [0.0; 2];
        let ex = self.extrapolate;
        let px = self.x.place(args[0], ex);
        let (wx, dwx) = weights(&px, self.interp);
        let i = px.i;
        let Some(yaxis) = &self.y else {
            if px.outside && ex == TableExtrapolate::Error {
                return f64::NAN;
            }
            let (m0, m1) = match self.interp {
                TableInterp::Cubic => (self.vx[i], self.vx[i + 1]),
                TableInterp::Linear => (0.0, 0.0),
            };
            let (m0, m1) = if self.interp == TableInterp::Linear && px.outside {
                (0.0, 0.0)
            } else {
                (m0, m1)
            };
            let c = [self.v[i], m0, self.v[i + 1], m1];
            d[0] = (0..4).map(|k| dwx[k] * c[k]).sum();
            return (0..4).map(|k| wx[k] * c[k]).sum();
        };
        let py = yaxis.place(args[1], ex);
        if (px.outside || py.outside) && ex == TableExtrapolate::Error {
            return f64::NAN;
        }
        let (wy, dwy) = weights(&py, self.interp);
        let ny = yaxis.knots.len();
        let j = py.i;
        // the 4 × 4 Hermite coefficients: rows (value, x-slope) × two x knots, columns
        // (value, y-slope) × two y knots
        let at = |a: &[f64], ii: usize, jj: usize| if a.is_empty() { 0.0 } else { a[ii * ny + jj] };
        let mut value = 0.0;
        let (mut ddx, mut ddy) = (0.0, 0.0);
        for (a, (ii, xslope)) in [(i, false), (i, true), (i + 1, false), (i + 1, true)]
            .into_iter()
            .enumerate()
        {
            for (b, (jj, yslope)) in [(j, false), (j, true), (j + 1, false), (j + 1, true)]
                .into_iter()
                .enumerate()
            {
                let c = match (xslope, yslope) {
                    (false, false) => self.v[ii * ny + jj],
                    (true, false) => at(&self.vx, ii, jj),
                    (false, true) => at(&self.vy, ii, jj),
                    (true, true) => at(&self.vxy, ii, jj),
                };
                if c == 0.0 {
                    continue;
                }
                value += wx[a] * wy[b] * c;
                ddx += dwx[a] * wy[b] * c;
                ddy += wx[a] * dwy[b] * c;
            }
        }
        *d = [ddx, ddy];
        value
    }
}

/// The model's tables, shared by every compiled expression that calls one.
#[derive(Clone, Debug, Default)]
pub struct Tables {
    /// In file order; an expression calls table `k` by its index.
    pub list: Vec<Table>,
}

impl Tables {
    /// The index of table `name`.
    #[must_use]
    pub fn index(&self, name: &str) -> Option<usize> {
        self.list.iter().position(|t| t.name == name)
    }
    /// Every table's name and number of arguments (what the expression parser accepts).
    #[must_use]
    pub fn signatures(&self) -> Vec<(String, usize)> {
        self.list
            .iter()
            .map(|t| (t.name.clone(), t.arity()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    fn check_derivatives(t: &Table, points: &[[f64; 2]]) {
        for p in points {
            let mut d = [0.0; 2];
            let _ = t.eval(p, &mut d);
            for k in 0..t.arity() {
                let h = 1e-6 * p[k].abs().max(1.0);
                let (mut a, mut b) = (*p, *p);
                a[k] += h;
                b[k] -= h;
                let mut dd = [0.0; 2];
                let fd = (t.eval(&a, &mut dd) - t.eval(&b, &mut dd)) / (2.0 * h);
                assert!(
                    (fd - d[k]).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "{} at {p:?}: ∂{k} {} vs central difference {fd}",
                    t.name,
                    d[k]
                );
            }
        }
    }

    #[test]
    fn linear_1d_interpolates_holds_and_extrapolates() {
        let x = vec![0.0, 1.0, 3.0];
        let y = vec![0.0, 2.0, 3.0];
        let mut d = [0.0; 2];
        let t = Table::one(
            "t",
            x.clone(),
            y.clone(),
            TableInterp::Linear,
            TableExtrapolate::Hold,
        );
        assert!((t.eval(&[0.5], &mut d) - 1.0).abs() < 1e-15);
        assert!((d[0] - 2.0).abs() < 1e-15);
        assert!((t.eval(&[2.0], &mut d) - 2.5).abs() < 1e-15);
        assert_eq!(t.eval(&[5.0], &mut d), 3.0);
        assert_eq!(d[0], 0.0);
        let t = Table::one(
            "t",
            x.clone(),
            y.clone(),
            TableInterp::Linear,
            TableExtrapolate::Linear,
        );
        assert!((t.eval(&[5.0], &mut d) - 4.0).abs() < 1e-15);
        assert!((t.eval(&[-1.0], &mut d) + 2.0).abs() < 1e-15);
        let t = Table::one("t", x, y, TableInterp::Linear, TableExtrapolate::Error);
        assert!(t.eval(&[5.0], &mut d).is_nan());
        check_derivatives(&t, &[[0.3, 0.0], [2.2, 0.0]]);
    }

    #[test]
    fn cubic_1d_is_exact_at_knots_monotone_and_c1() {
        let x = vec![0.0, 1.0, 2.0, 3.0, 4.0];
        let y = vec![0.0, 0.1, 0.2, 5.0, 5.1]; // a steep rise: a plain spline overshoots
        let t = Table::one(
            "c",
            x.clone(),
            y.clone(),
            TableInterp::Cubic,
            TableExtrapolate::Linear,
        );
        let mut d = [0.0; 2];
        for (xi, yi) in x.iter().zip(&y) {
            assert!((t.eval(&[*xi], &mut d) - yi).abs() < 1e-14);
        }
        let mut last = f64::NEG_INFINITY;
        for k in 0..=400 {
            let v = t.eval(&[f64::from(k) * 0.01], &mut d);
            assert!(v >= last - 1e-15, "not monotone at {k}");
            assert!(d[0] >= -1e-12);
            last = v;
        }
        // C¹ at the knots: the slope from the left equals the slope from the right
        for xi in &x[1..4] {
            let (mut dl, mut dr) = ([0.0; 2], [0.0; 2]);
            let _ = t.eval(&[xi - 1e-9], &mut dl);
            let _ = t.eval(&[xi + 1e-9], &mut dr);
            assert!((dl[0] - dr[0]).abs() < 1e-6, "slope jumps at {xi}");
        }
        check_derivatives(
            &t,
            &[[0.5, 0.0], [2.5, 0.0], [3.7, 0.0], [-0.5, 0.0], [4.5, 0.0]],
        );
        // a cubic through linear data is the line
        let l = Table::one(
            "l",
            x.clone(),
            x.iter().map(|v| 2.0 * v + 1.0).collect(),
            TableInterp::Cubic,
            TableExtrapolate::Hold,
        );
        assert!((l.eval(&[1.7], &mut d) - 4.4).abs() < 1e-13);
        assert!((d[0] - 2.0).abs() < 1e-13);
    }

    #[test]
    fn tables_2d_reproduce_bilinear_data_and_have_exact_partials() {
        let x = vec![0.0, 1.0, 2.0];
        let y = vec![0.0, 10.0, 20.0, 40.0];
        let f = |a: f64, b: f64| 1.0 + 2.0 * a + 0.1 * b + 0.05 * a * b;
        let z: Vec<Vec<f64>> = x
            .iter()
            .map(|&a| y.iter().map(|&b| f(a, b)).collect())
            .collect();
        for interp in [TableInterp::Linear, TableInterp::Cubic] {
            let t = Table::two(
                "eta",
                x.clone(),
                y.clone(),
                z.clone(),
                interp,
                TableExtrapolate::Hold,
            );
            let mut d = [0.0; 2];
            let v = t.eval(&[0.5, 15.0], &mut d);
            if interp == TableInterp::Linear {
                // bilinear reproduces a bilinear function exactly
                assert!((v - f(0.5, 15.0)).abs() < 1e-12, "{v}");
                assert!((d[0] - (2.0 + 0.05 * 15.0)).abs() < 1e-12);
                assert!((d[1] - (0.1 + 0.05 * 0.5)).abs() < 1e-12);
            }
            assert_eq!(t.arity(), 2);
            check_derivatives(
                &t,
                &[
                    [0.5, 15.0],
                    [1.3, 33.0],
                    [1.9, 2.0],
                    [3.0, 15.0],
                    [0.5, -5.0],
                ],
            );
            // the knots are exact
            assert!((t.eval(&[1.0, 20.0], &mut d) - f(1.0, 20.0)).abs() < 1e-12);
        }
    }
}
