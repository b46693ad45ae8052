//! Pressure-reducing valve `hydraulics.pressure_reducing_valve`: a normally open valve from
//! `P` to `A` that throttles as the outlet pressure rises, holding `A` near its setting
//! whatever the inlet.
//!
//! ```text
//! x = ramp((p_set − P_A)/Δp_band)
//! Q = α·x·regRoot(P_P − P_A) + g_leak·(P_P − P_A)       from P to A
//! ```
//!
//! The spool senses the outlet pressure against its spring (spring chamber drained): fully
//! open while P_A ≤ p_set − Δp_band, shut at P_A = p_set, in between an orifice whose
//! opening falls linearly with the outlet pressure (the direct-acting two-way reducing valve
//! of Manring, *Hydraulic Control Systems*, 2005; orifice law from Merritt, *Hydraulic
//! Control Systems*, 1967). A consumer drawing Q from `A` finds the outlet pressure where the
//! valve passes Q: within Δp_band below the setting for any flow up to the fully open one. It
//! is the two-way kind: it cannot relieve an outlet pushed above the setting (no drain port).
//! Corners rounded ([`crate::ramp`]).
//!
//! Causality: conductance at both ports. Dissipates Q·(P_P − P_A) ≥ 0. Publishes `x`.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, SMOOTHING};

/// Parameters of a pressure-reducing valve; [`PressureReducingValve::build`] makes it.
#[derive(Clone, Debug, PartialEq)]
pub struct PressureReducingValve {
    /// Orifice coefficient α at full opening, m³/(s·√Pa), > 0 (`alpha`, or `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Outlet pressure at which it shuts, Pa, > 0 (`p_set`).
    pub p_set: f64,
    /// Outlet pressure band from fully open to shut, Pa, > 0 (`dp_band`, default
    /// 0.1·p_set).
    pub dp_band: f64,
    /// Half-width ε of the rounded corners, fraction of `dp_band`, in [0, 0.5]
    /// (`smoothing`, default 0.05).
    pub smoothing: f64,
    /// Leak conductance when shut, m³/(s·Pa), ≥ 0 (`g_leak`, default 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
}

impl PressureReducingValve {
    /// A reducing valve with coefficient `alpha` set at `p_set`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64, p_set: f64) -> Self {
        Self {
            alpha,
            p_set,
            dp_band: 0.1 * p_set,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
        }
    }

    /// The element (kind `hydraulics.pressure_reducing_valve`, ports `P`, `A`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::positive("p_set", self.p_set)?;
        ParamError::positive("dp_band", self.dp_band)?;
        // ξ = (p_set − P_A)/Δp_band = (−P_A − (−p_set))/Δp_band
        let opening = Opening {
            name: "x",
            alpha: self.alpha,
            c: [0.0, -1.0, 0.0],
            p_set: -self.p_set,
            band: self.dp_band,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.pressure_reducing_valve",
            &["P", "A"],
            vec![opening],
            self.g_leak,
            self.p_tr,
            None,
        )
    }
}

/// Kind `hydraulics.pressure_reducing_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.pressure_reducing_valve",
    "pressure-reducing valve P → A: x = ramp((p_set − P_A)/dp_band), Q = α·x·regRoot(P_P − P_A)",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_set", "Pa", "outlet pressure at which it shuts").positive(),
        ParamDecl::number(
            "dp_band",
            "Pa",
            "outlet pressure band from fully open to shut",
        )
        .positive()
        .optional("0.1·p_set"),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
    ],
    |p| {
        let mut v = PressureReducingValve::new(orifice::alpha_of(p)?, p.number("p_set")?);
        if let Some(d) = p.optional("dp_band")? {
            v.dp_band = d;
        }
        v.smoothing = p.number("smoothing")?;
        v.g_leak = p.number("g_leak")?;
        v.p_tr = p.number("p_tr")?;
        Ok(Box::new(v.build()?))
    },
)
.example("alpha = 1e-6, p_set = 5e6");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reg_root;

    #[test]
    fn throttles_as_the_outlet_nears_the_setting() {
        let v = PressureReducingValve::new(1e-6, 5e6).build().unwrap();
        let q = |p_a: f64| v.flow(&[20e6, p_a, 0.0]);
        // fully open well below the setting
        let e = 1e-6 * reg_root(16e6, 1e5) + 1e-15 * 16e6;
        assert!((q(4e6) - e).abs() <= 1e-12 * e);
        // x = (p_set − P_A)/Δp_band on the band
        let e = 1e-6 * 0.25 * reg_root(15.125e6, 1e5) + 1e-15 * 15.125e6;
        assert!(
            (q(4.875e6) - e).abs() <= 1e-12 * e,
            "{:e} {e:e}",
            q(4.875e6)
        );
        // shut above it
        assert!((q(5.1e6) - 1e-15 * 14.9e6).abs() <= 1e-20);
    }

    /// Feeding a consumer that draws Q through a laminar restriction to tank, the outlet
    /// settles inside the band whatever the supply.
    #[test]
    fn holds_the_outlet_in_the_band_for_any_supply() {
        let v = PressureReducingValve::new(1e-6, 5e6).build().unwrap();
        for p_s in [8e6, 15e6, 30e6] {
            // consumer: Q = P_A/R, R = 1e10 Pa·s/m³ → 0.5 l/s at 5 MPa; solve valve = consumer
            let f = |p_a: f64| v.flow(&[p_s, p_a, 0.0]) - p_a / 1e10;
            let (mut lo, mut hi) = (0.0, p_s);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if f(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let p_a = 0.5 * (lo + hi);
            assert!(p_a > 4.5e6 && p_a < 5e6, "{p_s}: {p_a}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(PressureReducingValve::new(1e-6, -5e6).build().is_err());
        let mut r = PressureReducingValve::new(1e-6, 5e6);
        r.dp_band = 0.0;
        assert!(r.build().is_err());
    }
}
