//! Pilot-operated check valve `hydraulics.pilot_check_valve`: a check valve (free flow from
//! `in` to `out`) whose poppet a pilot piston lifts off its seat, so that oil may also flow
//! back from `out` to `in` when the pilot port `X` is pressurised.
//!
//! ```text
//! x = ramp((P_in − P_out + ψ·P_X − p_crack)/Δp_open)
//! Q = α·x·regRoot(P_in − P_out) + g_leak·(P_in − P_out)       from in to out
//! ```
//!
//! The poppet sees P_in on its seat area pushing it open, P_out pushing it shut, and the pilot
//! piston of ψ times the seat area (ψ the pilot ratio) pushing it open with P_X (its other side
//! drained). With X unpressurised this is the check valve; holding a load at P_out with the
//! inlet at tank, it opens when `ψ·P_X ≥ P_out + p_crack`. Once open the poppet is an orifice
//! both ways (Merritt, *Hydraulic Control Systems*, 1967; Manring, *Hydraulic Control Systems*,
//! 2005). Unlike the counterbalance valve it does not meter: piloted, it is simply open.
//!
//! The pilot port only senses its pressure (no flow). Causality: conductance at all three
//! ports. Dissipates Q·(P_in − P_out) ≥ 0. Publishes the opening `x`.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, SMOOTHING};

/// Parameters of a pilot-operated check valve; [`PilotCheckValve::build`] makes the element.
#[derive(Clone, Debug, PartialEq)]
pub struct PilotCheckValve {
    /// Orifice coefficient α at full opening, m³/(s·√Pa), > 0 (`alpha`, or `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Pilot ratio ψ, > 0 (`ratio`, default 3).
    pub ratio: f64,
    /// Cracking pressure, Pa, ≥ 0 (`p_crack`, default 1e5).
    pub p_crack: f64,
    /// Pressure (of the drive) from cracking to fully open, Pa, > 0 (`dp_open`, default 2e5).
    pub dp_open: f64,
    /// Half-width ε of the rounded corners, fraction of `dp_open`, in [0, 0.5] (`smoothing`,
    /// default 0.05).
    pub smoothing: f64,
    /// Leak conductance of the seated poppet, m³/(s·Pa), ≥ 0 (`g_leak`, default 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
}

impl PilotCheckValve {
    /// A pilot-operated check valve with coefficient `alpha`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64) -> Self {
        Self {
            alpha,
            ratio: 3.0,
            p_crack: 1e5,
            dp_open: 2e5,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
        }
    }

    /// The element (kind `hydraulics.pilot_check_valve`, ports `in`, `out`, `X`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::positive("ratio", self.ratio)?;
        ParamError::non_negative("p_crack", self.p_crack)?;
        ParamError::positive("dp_open", self.dp_open)?;
        let opening = Opening {
            name: "x",
            alpha: self.alpha,
            c: [1.0, -1.0, self.ratio],
            p_set: self.p_crack,
            band: self.dp_open,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.pilot_check_valve",
            &["in", "out", "X"],
            vec![opening],
            self.g_leak,
            self.p_tr,
            None,
        )
    }
}

/// Kind `hydraulics.pilot_check_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.pilot_check_valve",
    "pilot-operated check in → out, pilot X: x = ramp((Δp + ratio·P_X − p_crack)/dp_open), Q = α·x·regRoot(Δp)",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("ratio", "1", "pilot ratio ψ (pilot piston over seat area)").positive().default(3.0),
        ParamDecl::number("p_crack", "Pa", "cracking pressure").non_negative().default(1e5),
        ParamDecl::number("dp_open", "Pa", "rise of the drive from cracking to fully open").positive().default(2e5),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
    ],
    |p| {
        let mut v = PilotCheckValve::new(orifice::alpha_of(p)?);
        v.ratio = p.number("ratio")?;
        v.p_crack = p.number("p_crack")?;
        v.dp_open = p.number("dp_open")?;
        v.smoothing = p.number("smoothing")?;
        v.g_leak = p.number("g_leak")?;
        v.p_tr = p.number("p_tr")?;
        Ok(Box::new(v.build()?))
    },
)
.example("alpha = 1e-6, ratio = 4");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reg_root;

    #[test]
    fn checks_until_piloted_then_opens_both_ways() {
        let v = PilotCheckValve::new(1e-6).build().unwrap();
        // holding 15 MPa with the inlet at tank: unpiloted, the leak only
        let q = v.flow(&[0.0, 15e6, 0.0]);
        assert!((q + 1.5e-8).abs() <= 1e-20, "{q:e}");
        // piloted at ψ·P_X = P_out + p_crack + Δp_open (+ the rounding): fully open, backwards
        let p_x = (15e6 + 1e5 + 1.1 * 2e5) / 3.0;
        let q = v.flow(&[0.0, 15e6, p_x]);
        let e = -(1e-6 * reg_root(15e6, 1e5) + 1.5e-8);
        assert!((q - e).abs() <= 1e-12 * e.abs(), "{q:e} {e:e}");
        // forward it is the check valve, pilot or not
        let check = crate::CheckValve::new(1e-6).build().unwrap();
        for (pin, pout) in [(10.25e6, 10e6), (12e6, 10e6)] {
            let (q, e) = (v.flow(&[pin, pout, 0.0]), check.flow(&[pin, pout, 0.0]));
            assert!((q - e).abs() <= 1e-15 * e.abs(), "{pin}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        let mut c = PilotCheckValve::new(1e-6);
        c.ratio = 0.0;
        assert!(c.build().is_err(), "no pilot: use the check valve");
        c.ratio = 3.0;
        c.dp_open = -1.0;
        assert!(c.build().is_err());
    }
}
