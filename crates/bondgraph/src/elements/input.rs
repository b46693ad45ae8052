//! External input: u = a value set from outside the model (a force, a valve command, a
//! joystick), held constant or following a time series.
//!
//! A signal block with no ports, no states and no signal inputs: one stage writes its one
//! output, which the plan publishes under the input's bare name (`F`, not `F.out`), so any
//! expression, modulated parameter or signal port reads it like a signal. Because the value
//! is the output of a stage of its own element, the Jacobian's forward mode can seed it as a
//! column (∂f/∂u): its gradient slot is that of the signal at
//! [`StateEquations::input_signal_offset`](crate::StateEquations::input_signal_offset).
//!
//! The value lives inside the element, behind interior mutability, so that it can be set
//! between solver steps through [`StateEquations::set_input`](crate::StateEquations::set_input)
//! and [`StateEquations::set_input_series`](crate::StateEquations::set_input_series) without
//! rebuilding the plan. Evaluating it allocates nothing (a [`Series`] lookup is a cached
//! piece index, moved by one in the usual case, a binary search otherwise).
//!
//! A series is piecewise: linear between samples ([`Interp::Linear`]) or held from one
//! sample to the next ([`Interp::Hold`], zero-order hold, right-continuous: the value at a
//! sample time is that sample's). Outside its times it holds the first or last value. Its
//! corners (the sample times) are *breakpoints*: the simulation stops and restarts on them,
//! and inside one segment between two stops the series is evaluated on the one piece the
//! segment started in ([`Input::lock_at`]), so the solver never sees a corner inside a step.

use std::cell::{Cell, RefCell};

use crate::element::{CausalRule, Element, Io, Ports, SignalSpec, Slot, Stage};
use crate::error::ParamError;
use crate::local_jacobian::LocalJacobian;
use crate::PortCausality;

/// How a [`Series`] goes from one sample to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interp {
    /// Linear between samples (the default).
    #[default]
    Linear,
    /// Zero-order hold: each sample's value until the next sample time.
    Hold,
    /// A C² cubic spline through the samples, not-a-knot ends (see [`Series::jet`]).
    Spline,
}

impl Interp {
    /// Parse `linear`, `hold` (also `zoh`, `zero-order-hold`) or `spline`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "linear" => Some(Self::Linear),
            "hold" | "zoh" | "zero-order-hold" => Some(Self::Hold),
            "spline" => Some(Self::Spline),
            _ => None,
        }
    }
    /// The name `parse` accepts.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Hold => "hold",
            Self::Spline => "spline",
        }
    }
}

/// A sampled signal: strictly increasing, finite times and finite values.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    times: Vec<f64>,
    values: Vec<f64>,
    interp: Interp,
    /// The spline's second derivatives at the samples ([`Interp::Spline`]; else empty).
    curvature: Vec<f64>,
}

impl Series {
    /// A series of samples `(times[k], values[k])`.
    ///
    /// # Errors
    /// [`ParamError`] if the lengths differ, there is no sample, a time or value is not
    /// finite, or the times are not strictly increasing (naming the first bad sample).
    pub fn new(times: Vec<f64>, values: Vec<f64>, interp: Interp) -> Result<Self, ParamError> {
        if times.len() != values.len() {
            return Err(ParamError::shape(
                "times",
                format!(
                    "{} times and {} values: they must be as many",
                    times.len(),
                    values.len()
                ),
            ));
        }
        if times.is_empty() {
            return Err(ParamError::shape(
                "times",
                "a series needs at least one sample",
            ));
        }
        for (k, (t, v)) in times.iter().zip(&values).enumerate() {
            if !t.is_finite() {
                return Err(ParamError::shape(
                    "times",
                    format!("sample {k}: time {t} is not finite"),
                ));
            }
            if !v.is_finite() {
                return Err(ParamError::shape(
                    "values",
                    format!("sample {k}: value {v} is not finite"),
                ));
            }
            if k > 0 && *t <= times[k - 1] {
                return Err(ParamError::shape(
                    "times",
                    format!(
                        "sample {k}: time {t} is not after the time before it, {}: times must increase strictly",
                        times[k - 1]
                    ),
                ));
            }
        }
        let curvature = if interp == Interp::Spline {
            not_a_knot(&times, &values)
        } else {
            Vec::new()
        };
        Ok(Self {
            times,
            values,
            interp,
            curvature,
        })
    }
    /// A constant as a one-sample series.
    #[must_use]
    pub fn constant(value: f64) -> Self {
        Self {
            times: vec![0.0],
            values: vec![value],
            interp: Interp::Hold,
            curvature: Vec::new(),
        }
    }
    /// The sample times: the series' breakpoints (its corners).
    #[must_use]
    pub fn times(&self) -> &[f64] {
        &self.times
    }
    /// The sample values.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// The interpolation.
    #[must_use]
    pub fn interp(&self) -> Interp {
        self.interp
    }
    /// The piece holding time `t`: the number of sample times at or before `t` (0: before
    /// the first sample; `len`: at or after the last). Times within the simulation's time
    /// tolerance of a sample count as on it.
    #[must_use]
    pub fn piece(&self, t: f64) -> usize {
        let tol = time_tolerance(t);
        self.times.partition_point(|&s| s <= t + tol)
    }
    /// The value of piece `j` (see [`piece`](Self::piece)) at `t`, extended beyond the
    /// piece's ends by its own law.
    #[must_use]
    pub fn on_piece(&self, j: usize, t: f64) -> f64 {
        let n = self.times.len();
        if j == 0 {
            return self.values[0];
        }
        if j >= n {
            return self.values[n - 1];
        }
        match self.interp {
            Interp::Hold => self.values[j - 1],
            Interp::Linear => {
                let (t0, t1) = (self.times[j - 1], self.times[j]);
                let (v0, v1) = (self.values[j - 1], self.values[j]);
                v0 + (v1 - v0) * ((t - t0) / (t1 - t0))
            }
            Interp::Spline => self.jet_on_piece(j, t)[0],
        }
    }
    /// [value, d/dt, d²/dt²] of piece `j` at `t`, exact for the piece's own law: a constant
    /// outside the samples and for [`Interp::Hold`], a line for [`Interp::Linear`], and for
    /// [`Interp::Spline`] the cubic with second derivatives Mᵢ, Mᵢ₊₁ at its ends
    /// (h = tᵢ₊₁ − tᵢ, a = tᵢ₊₁ − t, b = t − tᵢ):
    ///
    /// s = Mᵢa³/6h + Mᵢ₊₁b³/6h + (yᵢ/h − Mᵢh/6)·a + (yᵢ₊₁/h − Mᵢ₊₁h/6)·b.
    #[must_use]
    pub fn jet_on_piece(&self, j: usize, t: f64) -> [f64; 3] {
        let n = self.times.len();
        if j == 0 {
            return [self.values[0], 0.0, 0.0];
        }
        if j >= n {
            return [self.values[n - 1], 0.0, 0.0];
        }
        let (t0, t1) = (self.times[j - 1], self.times[j]);
        let (y0, y1) = (self.values[j - 1], self.values[j]);
        let h = t1 - t0;
        match self.interp {
            Interp::Hold => [y0, 0.0, 0.0],
            Interp::Linear => {
                let slope = (y1 - y0) / h;
                [y0 + (y1 - y0) * ((t - t0) / h), slope, 0.0]
            }
            Interp::Spline => {
                let (m0, m1) = (self.curvature[j - 1], self.curvature[j]);
                let (a, b) = (t1 - t, t - t0);
                let value = (m0 * a * a * a + m1 * b * b * b) / (6.0 * h)
                    + (y0 / h - m0 * h / 6.0) * a
                    + (y1 / h - m1 * h / 6.0) * b;
                let rate = (-m0 * a * a + m1 * b * b) / (2.0 * h) - (y0 / h - m0 * h / 6.0)
                    + (y1 / h - m1 * h / 6.0);
                let accel = (m0 * a + m1 * b) / h;
                [value, rate, accel]
            }
        }
    }
    /// [value, d/dt, d²/dt²] at `t` (see [`jet_on_piece`](Self::jet_on_piece)).
    #[must_use]
    pub fn jet(&self, t: f64) -> [f64; 3] {
        self.jet_on_piece(self.piece(t), t)
    }
    /// The value at `t`.
    #[must_use]
    pub fn at(&self, t: f64) -> f64 {
        self.on_piece(self.piece(t), t)
    }
    /// The first breakpoint strictly after `t` (beyond the time tolerance), if any.
    #[must_use]
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.times.get(self.piece(t)).copied()
    }
}

/// The time tolerance of the simulation near `t` (two times closer than this are one).
fn time_tolerance(t: f64) -> f64 {
    1e-10 * (1.0 + t.abs())
}

/// The second derivatives Mᵢ of the not-a-knot cubic spline through (tᵢ, yᵢ): the third
/// derivative is continuous at the second and the last-but-one samples, so the first two
/// pieces are one cubic and so are the last two (a cubic is reproduced exactly). Interior
/// rows: hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6(Δᵢ − Δᵢ₋₁), Δᵢ = (yᵢ₊₁ − yᵢ)/hᵢ; the end
/// conditions, e.g. h₁M₀ − (h₀ + h₁)M₁ + h₀M₂ = 0, are eliminated into the first and last
/// rows, leaving a tridiagonal system (Thomas algorithm). Three samples give their parabola,
/// two their line, one a constant.
fn not_a_knot(t: &[f64], y: &[f64]) -> Vec<f64> {
    let n = t.len();
    if n < 3 {
        return vec![0.0; n];
    }
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    if n == 3 {
        let m = 2.0 * (d[1] - d[0]) / (h[0] + h[1]);
        return vec![m; 3];
    }
    // unknowns M₁ … M_{n−2}: sub, diag, sup, rhs
    let k = n - 2;
    let mut sub = vec![0.0; k];
    let mut diag = vec![0.0; k];
    let mut sup = vec![0.0; k];
    let mut rhs = vec![0.0; k];
    for r in 0..k {
        let i = r + 1;
        sub[r] = h[i - 1];
        diag[r] = 2.0 * (h[i - 1] + h[i]);
        sup[r] = h[i];
        rhs[r] = 6.0 * (d[i] - d[i - 1]);
    }
    // M₀ = ((h₀ + h₁)M₁ − h₀M₂)/h₁ into row 1
    diag[0] += h[0] * (h[0] + h[1]) / h[1];
    sup[0] -= h[0] * h[0] / h[1];
    // M_{n−1} = ((h_{n−2} + h_{n−3})M_{n−2} − h_{n−2}M_{n−3})/h_{n−3} into the last row
    let (a, b) = (h[n - 2], h[n - 3]);
    diag[k - 1] += a * (a + b) / b;
    sub[k - 1] -= a * a / b;
    // Thomas
    for r in 1..k {
        let w = sub[r] / diag[r - 1];
        diag[r] -= w * sup[r - 1];
        rhs[r] -= w * rhs[r - 1];
    }
    let mut m = vec![0.0; n];
    m[k] = rhs[k - 1] / diag[k - 1];
    for r in (0..k - 1).rev() {
        m[r + 1] = (rhs[r] - sup[r] * m[r + 2]) / diag[r];
    }
    m[0] = ((h[0] + h[1]) * m[1] - h[0] * m[2]) / h[1];
    m[n - 1] = ((a + b) * m[n - 2] - a * m[n - 3]) / b;
    m
}

/// What an input is, for listings (`bg-sim check`) and for programs driving the model.
#[derive(Clone, Debug, PartialEq)]
pub struct InputSpec {
    /// The input's name: the element's name and the signal it publishes (`F`).
    pub name: String,
    /// Unit, as written in the model (`N`; empty if none).
    pub unit: String,
    /// Value when nothing sets it.
    pub default: f64,
    /// What it is.
    pub description: String,
}

/// The value an input has now.
#[derive(Clone, Debug)]
enum Source {
    Value(f64),
    Series(Series),
    /// A function of time with exact derivatives (a sea state).
    Motion(crate::Motion),
}

/// An external input (see the module documentation).
#[derive(Debug)]
pub struct Input {
    spec: InputSpec,
    source: RefCell<Source>,
    /// The piece of the series the current segment evaluates on (`None`: look `t` up).
    locked: Cell<Option<usize>>,
    /// The piece last found, where the next lookup starts.
    hint: Cell<usize>,
}

impl Input {
    /// An input at its default value.
    ///
    /// # Errors
    /// [`ParamError`] if the default is not finite.
    pub fn new(spec: InputSpec) -> Result<Self, ParamError> {
        ParamError::finite("default", spec.default)?;
        Ok(Self {
            source: RefCell::new(Source::Value(spec.default)),
            spec,
            locked: Cell::new(None),
            hint: Cell::new(0),
        })
    }
    /// Name, unit, default, description.
    #[must_use]
    pub fn spec(&self) -> &InputSpec {
        &self.spec
    }
    /// Hold `value` from now on (replacing a series).
    pub fn set(&self, value: f64) {
        *self.source.borrow_mut() = Source::Value(value);
        self.locked.set(None);
    }
    /// Follow `series` from now on.
    pub fn set_series(&self, series: Series) {
        *self.source.borrow_mut() = Source::Series(series);
        self.locked.set(None);
        self.hint.set(0);
    }
    /// Follow the function of time `motion` from now on (a sea state): no breakpoints.
    pub fn set_motion(&self, motion: crate::Motion) {
        *self.source.borrow_mut() = Source::Motion(motion);
        self.locked.set(None);
    }
    /// The series followed, if any.
    #[must_use]
    pub fn series(&self) -> Option<Series> {
        match &*self.source.borrow() {
            Source::Series(s) => Some(s.clone()),
            Source::Value(_) | Source::Motion(_) => None,
        }
    }
    /// [value, d/dt, d²/dt²] at `t`: a value stands still; a series gives its piece's
    /// derivatives (exact inside a segment between breakpoints); a motion its own.
    #[must_use]
    pub fn jet(&self, t: f64) -> [f64; 3] {
        match &*self.source.borrow() {
            Source::Value(v) => [*v, 0.0, 0.0],
            Source::Series(s) => {
                let j = match self.locked.get() {
                    Some(j) => j,
                    None => self.lookup(s, t),
                };
                s.jet_on_piece(j, t)
            }
            Source::Motion(m) => m.eval(t),
        }
    }
    /// The value at `t`.
    #[must_use]
    pub fn value(&self, t: f64) -> f64 {
        match &*self.source.borrow() {
            Source::Value(v) => *v,
            Source::Series(s) => {
                let j = match self.locked.get() {
                    Some(j) => j,
                    None => self.lookup(s, t),
                };
                s.on_piece(j, t)
            }
            Source::Motion(m) => m.eval(t)[0],
        }
    }
    /// The piece of `s` at `t`, starting from the last one found.
    fn lookup(&self, s: &Series, t: f64) -> usize {
        let times = s.times();
        let tol = time_tolerance(t);
        let h = self.hint.get().min(times.len());
        // piece h holds t when times[h-1] ≤ t < times[h]
        let after_lo = h == 0 || times[h - 1] <= t + tol;
        let before_hi = h == times.len() || times[h] > t + tol;
        let j = if after_lo && before_hi {
            h
        } else if after_lo && (h + 1 == times.len() || times[h + 1] > t + tol) {
            // before_hi failed, so h < len and times[h] ≤ t: the next piece
            h + 1
        } else {
            s.piece(t)
        };
        self.hint.set(j);
        j
    }
    /// Evaluate the series, until [`unlock`](Self::unlock), on the piece holding `t`
    /// (a segment of the run starting at `t`, ending at the next breakpoint at the latest).
    pub fn lock_at(&self, t: f64) {
        let j = match &*self.source.borrow() {
            Source::Series(s) => Some(s.piece(t)),
            Source::Value(_) | Source::Motion(_) => None,
        };
        self.locked.set(j);
    }
    /// Evaluate the series by looking every time up (dense data, no stops at breakpoints).
    pub fn unlock(&self) {
        self.locked.set(None);
    }
    /// The first breakpoint strictly after `t`, if the input follows a series.
    #[must_use]
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match &*self.source.borrow() {
            Source::Series(s) => s.next_breakpoint(t),
            Source::Value(_) | Source::Motion(_) => None,
        }
    }
}

impl Element for Input {
    fn kind(&self) -> &str {
        "input"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("value")]
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: vec![Slot::Output(0)],
            reads: Vec::new(),
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let v = self.value(io.time());
        io.set_y(0, 0, v);
    }
    /// The value depends on time alone: no partials in the element's variables.
    fn stage_partials(&self, _: usize, _: &Io<'_>, _: &mut LocalJacobian<'_>) -> bool {
        true
    }
    fn as_input(&self) -> Option<&Input> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    fn spec() -> InputSpec {
        InputSpec {
            name: "F".into(),
            unit: "N".into(),
            default: 2.0,
            description: String::new(),
        }
    }

    #[test]
    fn series_interpolate_linearly_or_hold_and_extrapolate_by_holding() {
        let lin = Series::new(vec![0.0, 1.0, 3.0], vec![0.0, 10.0, 30.0], Interp::Linear).unwrap();
        assert_eq!(lin.at(-1.0), 0.0);
        assert!((lin.at(0.5) - 5.0).abs() < 1e-12);
        assert!((lin.at(2.0) - 20.0).abs() < 1e-12);
        assert_eq!(lin.at(5.0), 30.0);
        let hold = Series::new(vec![0.0, 1.0, 3.0], vec![0.0, 10.0, 30.0], Interp::Hold).unwrap();
        assert_eq!(hold.at(0.999), 0.0);
        assert_eq!(hold.at(1.0), 10.0); // right-continuous
        assert_eq!(hold.at(2.9), 10.0);
        assert_eq!(hold.next_breakpoint(1.0), Some(3.0));
        assert_eq!(hold.next_breakpoint(0.5), Some(1.0));
        assert_eq!(hold.next_breakpoint(3.0), None);
    }

    #[test]
    fn bad_series_are_refused_naming_the_sample() {
        let e = Series::new(vec![0.0, 1.0, 1.0], vec![0.0; 3], Interp::Linear).unwrap_err();
        assert!(e.to_string().contains("sample 2"), "{e}");
        assert!(Series::new(vec![0.0], vec![f64::NAN], Interp::Linear).is_err());
        assert!(Series::new(vec![0.0, 1.0], vec![0.0], Interp::Linear).is_err());
        assert!(Series::new(vec![], vec![], Interp::Linear).is_err());
    }

    #[test]
    fn an_input_holds_a_value_or_follows_a_series_and_locks_on_a_piece() {
        let u = Input::new(spec()).unwrap();
        assert_eq!(u.value(7.0), 2.0);
        u.set(5.0);
        assert_eq!(u.value(0.0), 5.0);
        u.set_series(Series::new(vec![0.0, 1.0], vec![0.0, 10.0], Interp::Hold).unwrap());
        assert_eq!(u.value(0.5), 0.0);
        assert_eq!(u.value(1.5), 10.0);
        assert_eq!(u.value(0.2), 0.0); // the hint moves back
                                       // locked on the piece [0, 1): the corner at 1 is not seen inside the segment
        u.lock_at(0.0);
        assert_eq!(u.value(1.0), 0.0);
        u.unlock();
        assert_eq!(u.value(1.0), 10.0);
        assert_eq!(u.next_breakpoint(0.0), Some(1.0));
    }

    #[test]
    fn lookups_with_the_hint_match_binary_search() {
        let times: Vec<f64> = (0..50).map(|k| f64::from(k) * 0.1).collect();
        let values: Vec<f64> = times.iter().map(|t| (3.0 * t).sin()).collect();
        let s = Series::new(times, values, Interp::Linear).unwrap();
        let u = Input::new(spec()).unwrap();
        u.set_series(s.clone());
        for k in 0..2000 {
            // forwards, backwards, jumps
            let t = (f64::from(k) * 0.37).sin() * 3.0 + 2.0 + f64::from(k % 7) * 0.013;
            assert_eq!(u.value(t), s.at(t), "t = {t}");
        }
    }

    #[test]
    fn a_not_a_knot_spline_reproduces_a_cubic_with_its_derivatives() {
        let f = |t: f64| [
            2.0 - t + 0.5 * t * t - 0.3 * t * t * t,
            -1.0 + t - 0.9 * t * t,
            1.0 - 1.8 * t,
        ];
        let times = vec![0.0, 0.4, 1.1, 1.5, 2.6, 3.0, 4.2];
        let values = times.iter().map(|&t| f(t)[0]).collect();
        let s = Series::new(times, values, Interp::Spline).unwrap();
        for k in 0..84 {
            let t = f64::from(k) * 0.05;
            let (got, want) = (s.jet(t), f(t));
            for d in 0..3 {
                assert!((got[d] - want[d]).abs() < 1e-11, "t {t}, derivative {d}: {got:?} vs {want:?}");
            }
        }
        // three samples: their parabola; two: their line
        let p = Series::new(vec![0.0, 1.0, 3.0], vec![1.0, 2.0, 10.0], Interp::Spline).unwrap();
        // y = 1 + 0·t + t²... through (0,1), (1,2), (3,10): y = 1 + t²·1 + 0·t
        assert!((p.jet(2.0)[0] - 5.0).abs() < 1e-12 && (p.jet(2.0)[2] - 2.0).abs() < 1e-12);
        let l = Series::new(vec![0.0, 2.0], vec![1.0, 5.0], Interp::Spline).unwrap();
        assert_eq!(l.jet(0.5), [2.0, 2.0, 0.0]);
    }

    #[test]
    fn spline_derivatives_match_finite_differences_and_the_spline_is_c2() {
        let times: Vec<f64> = (0..30).map(|k| f64::from(k) * 0.3 + 0.01 * f64::from(k % 4)).collect();
        let values: Vec<f64> = times.iter().map(|t| (1.3 * t).sin() + 0.2 * t).collect();
        let s = Series::new(times.clone(), values, Interp::Spline).unwrap();
        let h = 1e-5;
        for k in 1..200 {
            let t = f64::from(k) * 0.043;
            let j = s.piece(t);
            let [v, d1, d2] = s.jet_on_piece(j, t);
            let (p, m) = (s.jet_on_piece(j, t + h), s.jet_on_piece(j, t - h));
            assert!((d1 - (p[0] - m[0]) / (2.0 * h)).abs() < 1e-7, "t {t}");
            assert!((d2 - (p[1] - m[1]) / (2.0 * h)).abs() < 1e-7, "t {t}");
            assert!((v - s.at(t)).abs() < 1e-15);
        }
        // continuity of value, slope and curvature at the interior samples
        for (i, &tk) in times.iter().enumerate().skip(1).take(times.len() - 2) {
            let (left, right) = (s.jet_on_piece(i, tk), s.jet_on_piece(i + 1, tk));
            for d in 0..3 {
                assert!((left[d] - right[d]).abs() < 1e-9, "sample {i}, derivative {d}");
            }
        }
    }

    #[test]
    fn an_input_follows_a_motion_with_its_derivatives_and_no_breakpoints() {
        let u = Input::new(spec()).unwrap();
        u.set_motion(crate::Motion::law(|t| [t.sin(), t.cos(), -t.sin()]));
        assert_eq!(u.value(0.5), 0.5f64.sin());
        assert_eq!(u.jet(0.5), [0.5f64.sin(), 0.5f64.cos(), -(0.5f64.sin())]);
        assert_eq!(u.next_breakpoint(0.0), None);
        u.set(3.0);
        assert_eq!(u.jet(1.0), [3.0, 0.0, 0.0]);
    }
}
