//! Integrator `integrator`: y = ∫u dt, a signal block with limits and a reset.
//!
//! One state y (initial `initial`), one output `out` = clamp(y, min, max), the input `u` an
//! expression of signals and t.
//!
//! - **Limits without windup** (conditional integration): while y is at or beyond `max`
//!   and u > 0, or at or beyond `min` and u < 0, dy/dt = 0; so the state never stores what
//!   the limit cut off, and integration resumes the instant u turns back. The output is the
//!   state clamped, so a step that overshoots the limit by rounding does not show.
//! - **Reset by a signal threshold**: while the signal `reset` is ≥ 0.5, the state relaxes
//!   to `initial` with the time constant `reset_time` (default 1 ms): dy/dt =
//!   (initial − y)/reset_time. A held reset of a few reset_times brings y back to within
//!   e^(−n) of `initial`. It is a continuous law, not a jump of the state, so no event
//!   machinery is needed and the stiff solver takes it in its stride; a reset shorter
//!   than reset_time is only a partial reset.
//!
//! The right-hand side switches at the limits and at the reset threshold; the solver's
//! error control finds the switch (no events). A reset that lasts a short time should come
//! with a breakpoint (an input series, an event), or the solver may step over it.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Param, Ports, SignalSpec, Slot, Stage, StateSpec};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// An integrator with limits and a reset (see the module documentation).
#[derive(Debug)]
pub struct Integrator {
    input: Param,
    initial: f64,
    min: f64,
    max: f64,
    reset: Option<Param>,
    reset_time: f64,
}

impl Integrator {
    /// ∫`input` dt from `initial`, held within [`min`, `max`] (±∞ for none), reset to
    /// `initial` while `reset` ≥ 0.5 with time constant `reset_time`.
    ///
    /// # Errors
    /// `initial` not finite, `min` > `max`, `initial` outside [min, max], `reset_time` not
    /// positive.
    pub fn new(
        input: impl Into<Param>,
        initial: f64,
        (min, max): (f64, f64),
        reset: Option<Param>,
        reset_time: f64,
    ) -> Result<Self, ParamError> {
        ParamError::finite("initial", initial)?;
        ParamError::positive("reset_time", reset_time)?;
        if min.is_nan() || max.is_nan() || min > max {
            return Err(ParamError::shape("min", format!("min = {min} must not exceed max = {max}")));
        }
        if !(min..=max).contains(&initial) {
            return Err(ParamError::shape(
                "initial",
                format!("initial = {initial} is outside [min, max] = [{min}, {max}]"),
            ));
        }
        Ok(Self {
            input: input.into(),
            initial,
            min,
            max,
            reset,
            reset_time,
        })
    }
    /// dy/dt and what it is: 0 integrating, 1 held at a limit, 2 resetting.
    fn rate(&self, io: &Io<'_>) -> (f64, u8) {
        let y = io.states()[0];
        if let Some(r) = &self.reset {
            if r.value(io, self.input.n_inputs()) >= 0.5 {
                return ((self.initial - y) / self.reset_time, 2);
            }
        }
        let u = self.input.value(io, 0);
        if (y >= self.max && u > 0.0) || (y <= self.min && u < 0.0) {
            (0.0, 1)
        } else {
            (u, 0)
        }
    }
}

impl Element for Integrator {
    fn kind(&self) -> &str {
        "integrator"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("y", self.initial)]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        let mut s = self.input.signal_inputs();
        if let Some(r) = &self.reset {
            s.extend(r.signal_inputs());
        }
        s
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("out")]
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 1)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let y = io.states()[0];
        io.set_y(0, 0, y.clamp(self.min, self.max));
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = self.rate(io).0;
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let y = io.states()[0];
        let inside = y > self.min && y < self.max;
        jac.set(jac.row(Slot::Output(0), 0), jac.state_col(0), if inside { 1.0 } else { 0.0 });
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let row = jac.derivative_row(0);
        match self.rate(io).1 {
            0 => self
                .input
                .partials(io, 0, |k, d| jac.set(row, jac.input_col(k, 0), d)),
            2 => jac.set(row, jac.state_col(0), -1.0 / self.reset_time),
            _ => {}
        }
        true
    }
}

/// Kind `integrator`: `dy/dt = u`, with limits and a reset.
pub const KIND: KindDecl = KindDecl::element(
    "integrator",
    "integrator: dy/dt = input, output clamp(y, min, max) without windup, reset while reset ≥ 0.5",
    &[
        ParamDecl::modulated("input", "", "the integrand: an expression of signals and t"),
        ParamDecl::number("initial", "", "initial value and reset value").default(0.0),
        ParamDecl::number("min", "", "lower limit").default(f64::NEG_INFINITY),
        ParamDecl::number("max", "", "upper limit").default(f64::INFINITY),
        ParamDecl::modulated("reset", "", "reset signal: y relaxes to `initial` while it is ≥ 0.5")
            .default(0.0),
        ParamDecl::number("reset_time", "s", "time constant of the reset").default(1e-3).positive(),
    ],
    |p| {
        let reset = if p.has("reset") {
            Some(p.modulated("reset")?)
        } else {
            None
        };
        Ok(Box::new(Integrator::new(
            p.modulated("input")?,
            p.number("initial")?,
            (p.number("min")?, p.number("max")?),
            reset,
            p.number("reset_time")?,
        )?))
    },
)
.example("input = \"t\", max = 1.0");

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;
    use crate::{assign_causality, check_partials, simulate, BondGraph, Settings, StateEquations};

    fn run(el: Integrator, t_end: f64) -> f64 {
        run_with(el, t_end, None)
    }

    /// With an input `r` following `reset` (its corners are breakpoints the run stops on).
    fn run_with(el: Integrator, t_end: f64, reset: Option<crate::Series>) -> f64 {
        let mut g = BondGraph::new();
        g.add("int", el).unwrap();
        let spec = crate::InputSpec {
            name: "r".into(),
            unit: String::new(),
            default: 0.0,
            description: String::new(),
        };
        g.add("r", crate::Input::new(spec).unwrap()).unwrap();
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        if let Some(s) = reset {
            eqs.set_input_series(eqs.input_index("r").unwrap(), s).unwrap();
        }
        let x0 = eqs.initial_state();
        let settings = Settings {
            t_end,
            rtol: 1e-10,
            atol: 1e-12,
            ..Settings::default()
        };
        let r = simulate(&mut eqs, &x0, &settings, &[], vec![]);
        assert!(r.error.is_none(), "{:?}", r.error);
        r.x_final[0]
    }

    fn law(f: fn(f64) -> f64) -> Param {
        Param::modulated(Vec::new(), move |t, _| f(t))
    }

    #[test]
    fn integrates_exactly_a_polynomial() {
        // ∫₀² (1 + 3t²) dt = 2 + 8
        let y = run(Integrator::new(law(|t| 1.0 + 3.0 * t * t), 0.5, (f64::NEG_INFINITY, f64::INFINITY), None, 1e-3).unwrap(), 2.0);
        assert!((y - 10.5).abs() < 1e-8, "{y}");
    }

    #[test]
    fn the_limit_holds_without_windup() {
        // u = cos(t): y = sin(t) would reach 1 at π/2; capped at 0.5 from t = π/6 until u
        // turns negative at π/2, then y = 0.5 + sin(t) − 1 (no stored excess): at t = π,
        // y = −0.5 (a windup integrator would give sin(π) = 0).
        let y = run(Integrator::new(law(f64::cos), 0.0, (-10.0, 0.5), None, 1e-3).unwrap(), std::f64::consts::PI);
        assert!((y + 0.5).abs() < 1e-5, "{y}");
    }

    #[test]
    fn a_held_reset_brings_the_state_back() {
        // u = 1; reset held from t = 1 to 1.05 (50 reset times): y(1.05) = 2 + e^(−50)·…
        // then integrates 1 again: y(2) = 2 + 0.95
        let reset = Param::modulated(vec!["r".into()], |_, u| u[0]);
        let r = crate::Series::new(vec![1.0, 1.05], vec![1.0, 0.0], crate::Interp::Hold).unwrap();
        let el = Integrator::new(law(|_| 1.0), 2.0, (f64::NEG_INFINITY, f64::INFINITY), Some(reset), 1e-3);
        let y = run_with(el.unwrap(), 2.0, Some(r));
        assert!((y - 2.95).abs() < 1e-4, "{y}");
    }

    #[test]
    fn partials_match_central_differences_and_bad_limits_are_refused() {
        let u = Param::modulated(vec!["a".into()], |_, u| 2.0 * u[0] * u[0]);
        let el = Integrator::new(u, 0.0, (-1.0, 1.0), None, 1e-3).unwrap();
        // a, y
        assert_eq!(check_partials(&el, &[], &[0.7, 0.2]), Ok(2));
        assert!(Integrator::new(law(|_| 1.0), 0.0, (1.0, -1.0), None, 1e-3).is_err());
        assert!(Integrator::new(law(|_| 1.0), 2.0, (-1.0, 1.0), None, 1e-3).is_err());
        assert!(Integrator::new(law(|_| 1.0), 0.0, (-1.0, 1.0), None, 0.0).is_err());
    }
}
