//! Check valve `hydraulics.check_valve`: a spring-loaded poppet that passes oil from `in` to
//! `out` once the drop exceeds its cracking pressure, and blocks the reverse (up to leakage).
//!
//! ```text
//! x = ramp((Δp − p_crack)/Δp_open)            Δp = P_in − P_out
//! Q = α·x·regRoot(Δp) + g_leak·Δp              from in to out
//! ```
//!
//! The law is the relief valve's (a check valve is a relief valve with a weak spring): the
//! poppet's lift grows with the pressure above cracking until it is fully open at
//! `p_crack + Δp_open`, and the oil passes the seat as through an orifice (Merritt, *Hydraulic
//! Control Systems*, 1967; Manring, *Hydraulic Control Systems*, 2005). In reverse (Δp < 0)
//! the poppet is seated and only the leak `g_leak·Δp` flows: a small conductance that keeps a
//! line between a closed check valve and another closed valve from having a zero row in the
//! Jacobian. The corners of the opening are rounded over ±ε·Δp_open ([`crate::ramp`]).
//!
//! Causality: conductance (both ports receive their pressure, set their flow). Dissipates
//! Q·Δp ≥ 0. Publishes the opening `x`.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, SMOOTHING};

/// Parameters of a check valve; [`CheckValve::build`] makes the element.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckValve {
    /// Orifice coefficient α at full opening, m³/(s·√Pa), > 0 (`alpha`, or `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Cracking pressure, Pa, ≥ 0 (`p_crack`, default 1e5).
    pub p_crack: f64,
    /// Pressure rise from cracking to fully open, Pa, > 0 (`dp_open`, default 2e5).
    pub dp_open: f64,
    /// Half-width ε of the rounded corners, fraction of `dp_open`, in [0, 0.5]
    /// (`smoothing`, default 0.05).
    pub smoothing: f64,
    /// Leak conductance of the seated poppet, m³/(s·Pa), ≥ 0 (`g_leak`, default 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
}

impl CheckValve {
    /// A check valve with coefficient `alpha`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64) -> Self {
        Self {
            alpha,
            p_crack: 1e5,
            dp_open: 2e5,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
        }
    }

    /// The element (kind `hydraulics.check_valve`, ports `in`, `out`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::non_negative("p_crack", self.p_crack)?;
        ParamError::positive("dp_open", self.dp_open)?;
        let opening = Opening {
            name: "x",
            alpha: self.alpha,
            c: [1.0, -1.0, 0.0],
            p_set: self.p_crack,
            band: self.dp_open,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.check_valve",
            &["in", "out"],
            vec![opening],
            self.g_leak,
            self.p_tr,
            None,
        )
    }
}

/// Kind `hydraulics.check_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.check_valve",
    "check valve in → out: x = ramp((Δp − p_crack)/dp_open), Q = α·x·regRoot(Δp) + g_leak·Δp",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_crack", "Pa", "cracking pressure")
            .non_negative()
            .default(1e5),
        ParamDecl::number("dp_open", "Pa", "pressure rise from cracking to fully open")
            .positive()
            .default(2e5),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
    ],
    |p| {
        let mut v = CheckValve::new(orifice::alpha_of(p)?);
        v.p_crack = p.number("p_crack")?;
        v.dp_open = p.number("dp_open")?;
        v.smoothing = p.number("smoothing")?;
        v.g_leak = p.number("g_leak")?;
        v.p_tr = p.number("p_tr")?;
        Ok(Box::new(v.build()?))
    },
)
.example("alpha = 1e-6");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reg_root;
    use bondgraph::Element;

    #[test]
    fn passes_forward_and_blocks_reverse() {
        let v = CheckValve::new(1e-6).build().unwrap();
        let q = |pin: f64, pout: f64| v.flow(&[pin, pout, 0.0]);
        // forward, fully open (Δp ≥ p_crack + (1 + ε)·Δp_open): the orifice law
        let e = 1e-6 * reg_root(5e6, 1e5) + 1e-15 * 5e6;
        assert!((q(15e6, 10e6) - e).abs() <= 1e-12 * e);
        // halfway through the opening band: x = ½
        let dp = 1e5 + 0.5 * 2e5;
        let e = 1e-6 * 0.5 * reg_root(dp, 1e5) + 1e-15 * dp;
        assert!((q(10e6 + dp, 10e6) - e).abs() <= 1e-12 * e);
        // reverse, at any pressure: the leak only
        for (pin, pout) in [(0.0, 20e6), (10e6, 10.5e6), (3e6, 3e6 + 1.0)] {
            let leak = 1e-15 * (pin - pout);
            assert!(
                (q(pin, pout) - leak).abs() <= 1e-12 * leak.abs(),
                "{pin} {pout}"
            );
        }
        assert_eq!(v.kind(), "hydraulics.check_valve");
        assert_eq!(
            v.ports(),
            bondgraph::Ports::Fixed(vec![
                bondgraph::PortSpec::new("in", 1),
                bondgraph::PortSpec::new("out", 1)
            ])
        );
    }

    #[test]
    fn opening_is_c1_at_cracking() {
        // the flow's slope in the inlet pressure does not jump at the ends of the rounded
        // corners: across ±1 Pa it changes by < 1e-3 of the slope in the middle of the band
        let v = CheckValve::new(1e-6).build().unwrap();
        let q = |pin: f64| v.flow(&[pin, 0.0, 0.0]);
        let slope = |p: f64| (q(p + 0.1) - q(p - 0.1)) / 0.2;
        let middle = slope(2e5);
        let band = 0.05 * 2e5;
        for edge in [1e5 - band, 1e5 + band, 3e5 - band, 3e5 + band] {
            let (l, r) = (slope(edge - 1.0), slope(edge + 1.0));
            assert!((l - r).abs() <= 1e-3 * middle, "{edge}: {l:e} {r:e}");
        }
        // whereas the hard clamp (ε = 0) jumps by about the middle slope at cracking
        let mut c = CheckValve::new(1e-6);
        c.smoothing = 0.0;
        let v = c.build().unwrap();
        let q = |pin: f64| v.flow(&[pin, 0.0, 0.0]);
        let jump = (q(1e5 + 1.1) - q(1e5 + 0.9)) / 0.2 - (q(1e5 - 0.9) - q(1e5 - 1.1)) / 0.2;
        assert!(jump > 0.4 * middle, "{jump:e} {middle:e}");
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(CheckValve::new(-1.0).build().is_err());
        let mut c = CheckValve::new(1e-6);
        c.p_crack = -1.0;
        assert!(c.build().is_err());
        c.p_crack = 0.0;
        assert!(c.build().is_ok(), "a check valve without spring");
        c.dp_open = 0.0;
        assert!(c.build().is_err());
    }
}
