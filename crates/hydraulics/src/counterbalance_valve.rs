//! Counterbalance (over-centre) valve `hydraulics.counterbalance_valve`: holds a load on its
//! cylinder port `C`, lets it down under control when piloted from the opposite line `X`, and
//! passes oil freely from the valve port `V` into the cylinder through an integral check.
//!
//! ```text
//! main poppet:  x = ramp((P_C + ψ·P_X − p_set)/Δp_open)         meters C → V
//! check:        x_check = ramp((P_V − P_C − p_check)/Δp_check)   passes V → C
//! Q = (α·x + α_check·x_check)·regRoot(P_V − P_C) + g_leak·(P_V − P_C)     from V to C
//! ```
//!
//! The main poppet is a relief valve whose spring is also pushed by a pilot piston ψ times the
//! seat area (ψ the pilot ratio): it opens when `P_C + ψ·P_X ≥ p_set`. With the setting above
//! the highest load pressure (commonly 1.3 times it) the load alone never opens it; to lower,
//! the pilot pressure from the other line opens it just enough to pass the oil the pump
//! pushes into that line — the valve meters the load down at the pump's pace and does not let
//! it run away. The pressures are gauge and the spring chamber is taken as drained, so the
//! pressure at `V` does not act on the poppet. This is the static model of Bak & Hansen,
//! *Analysis of offshore knuckle boom crane — part one: modeling and parameter
//! identification* (Modeling, Identification and Control, 2013), with the orifice laws of
//! Merritt, *Hydraulic Control Systems* (1967). Both openings' corners are rounded
//! ([`crate::ramp`]).
//!
//! The pilot port `X` only senses its pressure (no flow). Causality: conductance at all three
//! ports. Dissipates Q·(P_V − P_C) ≥ 0. Publishes the openings `x` and `x_check`.

use crate::orifice;
use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, NO_SEAT_LEAK, SMOOTHING};

/// Parameters of a counterbalance valve; [`CounterbalanceValve::build`] makes the element.
#[derive(Clone, Debug, PartialEq)]
pub struct CounterbalanceValve {
    /// Orifice coefficient α of the main poppet at full opening, m³/(s·√Pa), > 0 (`alpha`, or
    /// `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Setting p_set, Pa, > 0 (`p_set`): the load pressure that opens it unpiloted.
    pub p_set: f64,
    /// Pilot ratio ψ, ≥ 0 (`ratio`, default 3).
    pub ratio: f64,
    /// Pressure rise from cracking to fully open, Pa, > 0 (`dp_open`, default 0.1·p_set).
    pub dp_open: f64,
    /// Orifice coefficient of the check at full opening, m³/(s·√Pa), > 0 (`alpha_check`,
    /// default α).
    pub alpha_check: f64,
    /// Cracking pressure of the check, Pa, ≥ 0 (`p_check`, default 1e5).
    pub p_check: f64,
    /// Pressure rise from cracking to fully open of the check, Pa, > 0 (`dp_check`,
    /// default 2e5).
    pub dp_check: f64,
    /// Half-width ε of the rounded corners, fraction of each band, in [0, 0.5] (`smoothing`,
    /// default 0.05).
    pub smoothing: f64,
    /// Leak conductance between V and C with both closed, m³/(s·Pa), ≥ 0 (`g_leak`, default
    /// 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
}

impl CounterbalanceValve {
    /// A counterbalance valve with coefficient `alpha` set at `p_set`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64, p_set: f64) -> Self {
        Self {
            alpha,
            p_set,
            ratio: 3.0,
            dp_open: 0.1 * p_set,
            alpha_check: alpha,
            p_check: 1e5,
            dp_check: 2e5,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
        }
    }

    /// The element (kind `hydraulics.counterbalance_valve`, ports `V`, `C`, `X`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::positive("p_set", self.p_set)?;
        ParamError::non_negative("ratio", self.ratio)?;
        ParamError::positive("dp_open", self.dp_open)?;
        ParamError::positive("alpha_check", self.alpha_check)?;
        ParamError::non_negative("p_check", self.p_check)?;
        ParamError::positive("dp_check", self.dp_check)?;
        let main = Opening {
            name: "x",
            alpha: self.alpha,
            c: [0.0, 1.0, self.ratio],
            p_set: self.p_set,
            band: self.dp_open,
            eps: self.smoothing,
        };
        let check = Opening {
            name: "x_check",
            alpha: self.alpha_check,
            c: [1.0, -1.0, 0.0],
            p_set: self.p_check,
            band: self.dp_check,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.counterbalance_valve",
            &["V", "C", "X"],
            vec![main, check],
            self.g_leak,
            self.p_tr,
            None,
        )
    }
}

/// Kind `hydraulics.counterbalance_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.counterbalance_valve",
    "counterbalance valve V, C, pilot X: opens C → V when P_C + ratio·P_X ≥ p_set; free flow V → C through a check",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_set", "Pa", "setting: the load pressure that opens it unpiloted").positive(),
        ParamDecl::number("ratio", "1", "pilot ratio ψ").non_negative().default(3.0),
        ParamDecl::number("dp_open", "Pa", "rise of the drive from cracking to fully open").positive().optional("0.1·p_set"),
        ParamDecl::number("alpha_check", "m³/(s·√Pa)", "orifice coefficient of the check at full opening").positive().optional("alpha"),
        ParamDecl::number("p_check", "Pa", "cracking pressure of the check").non_negative().default(1e5),
        ParamDecl::number("dp_check", "Pa", "pressure rise of the check from cracking to fully open").positive().default(2e5),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
    ],
    build,
)
.simplifications(&[NO_SEAT_LEAK])
.example("alpha = 6e-7, p_set = 1.1e7");

fn build(p: &dyn Params) -> Result<Box<dyn bondgraph::Element>, BuildError> {
    let mut v = CounterbalanceValve::new(orifice::alpha_of(p)?, p.number("p_set")?);
    v.ratio = p.number("ratio")?;
    if let Some(d) = p.optional("dp_open")? {
        v.dp_open = d;
    }
    if let Some(a) = p.optional("alpha_check")? {
        v.alpha_check = a;
    }
    v.p_check = p.number("p_check")?;
    v.dp_check = p.number("dp_check")?;
    v.smoothing = p.number("smoothing")?;
    v.g_leak = p.number("g_leak")?;
    v.p_tr = p.number("p_tr")?;
    Ok(Box::new(v.build()?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reg_root;

    fn cbv() -> PressureValve {
        let mut c = CounterbalanceValve::new(1e-6, 20e6);
        c.ratio = 4.0;
        c.dp_open = 2e6;
        c.build().unwrap()
    }

    #[test]
    fn holds_the_load_without_pilot() {
        // load pressure below the setting, tank at V, no pilot: the seat's leak only
        let v = cbv();
        for p_c in [1e6, 10e6, 18e6] {
            let q = v.flow(&[0.0, p_c, 0.0]);
            assert!(
                (q + 1e-15 * p_c).abs() <= 1e-12 * 1e-15 * p_c,
                "{p_c}: {q:e}"
            );
        }
        // and relieves above the setting (a load spike): x = (P_C − p_set)/Δp_open
        let q = v.flow(&[0.0, 21e6, 0.0]);
        let e = -(1e-6 * 0.5 * reg_root(21e6, 1e5) + 1e-15 * 21e6);
        assert!((q - e).abs() <= 1e-12 * e.abs(), "{q:e} {e:e}");
    }

    #[test]
    fn pilot_opens_it_at_the_pilot_ratio() {
        // P_C + ψ·P_X = p_set + ½Δp_open → x = ½; the pilot needed falls by ψ per Pa of load
        let v = cbv();
        for p_c in [5e6, 12e6] {
            let p_x = (20e6 + 1e6 - p_c) / 4.0;
            let q = v.flow(&[1e5, p_c, p_x]);
            let e = -(1e-6 * 0.5 * reg_root(p_c - 1e5, 1e5) + 1e-15 * (p_c - 1e5));
            assert!((q - e).abs() <= 1e-12 * e.abs(), "{p_c}: {q:e} {e:e}");
            // just below cracking (less the rounding): closed again
            let p_x = (20e6 - 0.06 * 2e6 - p_c) / 4.0;
            let q = v.flow(&[1e5, p_c, p_x]);
            assert!((q + 1e-15 * (p_c - 1e5)).abs() <= 1e-20, "{p_c}: {q:e}");
        }
    }

    #[test]
    fn free_flow_into_the_cylinder_through_the_check() {
        let v = cbv();
        // V above C by more than p_check + (1 + ε)·Δp_check: the check fully open
        let (p_v, p_c) = (12e6, 11e6);
        let q = v.flow(&[p_v, p_c, 0.0]);
        let e = 1e-6 * reg_root(1e6, 1e5) + 1e-15 * 1e6;
        assert!((q - e).abs() <= 1e-12 * e, "{q:e} {e:e}");
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(CounterbalanceValve::new(1e-6, 0.0).build().is_err());
        let mut c = CounterbalanceValve::new(1e-6, 20e6);
        c.ratio = -1.0;
        assert!(c.build().is_err());
        c.ratio = 0.0;
        assert!(c.build().is_ok(), "an unpiloted load-holding valve");
        c.alpha_check = 0.0;
        assert!(c.build().is_err());
    }
}
