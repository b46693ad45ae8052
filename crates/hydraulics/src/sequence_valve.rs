//! Sequence valve `hydraulics.sequence_valve`: passes oil from `P` to the secondary circuit
//! `A` only once the inlet pressure has reached its setting (the first actuator has done its
//! work), whatever the pressure downstream.
//!
//! ```text
//! x = ramp((P_P − p_crack)/Δp_override)
//! Q = α·x·regRoot(P_P − P_A) + g_leak·(P_P − P_A)       from P to A
//! ```
//!
//! It is the relief valve's poppet, but its spring chamber is drained separately (to tank,
//! gauge 0), so it senses the inlet pressure itself, not the drop to `A`: a loaded secondary
//! circuit neither opens nor shuts it (Manring, *Hydraulic Control Systems*, 2005; the orifice
//! law of Merritt, *Hydraulic Control Systems*, 1967). Corners rounded ([`crate::ramp`]).
//!
//! Causality: conductance at both ports. Dissipates Q·(P_P − P_A) ≥ 0. Publishes `x`.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, SMOOTHING};

/// Parameters of a sequence valve; [`SequenceValve::build`] makes the element.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceValve {
    /// Orifice coefficient α at full opening, m³/(s·√Pa), > 0 (`alpha`, or `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Inlet pressure at which it opens, Pa, > 0 (`p_crack`).
    pub p_crack: f64,
    /// Pressure rise from cracking to fully open, Pa, > 0 (`dp_override`, default
    /// 0.1·p_crack).
    pub dp_override: f64,
    /// Half-width ε of the rounded corners, fraction of `dp_override`, in [0, 0.5]
    /// (`smoothing`, default 0.05).
    pub smoothing: f64,
    /// Leak conductance when closed, m³/(s·Pa), ≥ 0 (`g_leak`, default 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
}

impl SequenceValve {
    /// A sequence valve with coefficient `alpha` opening at `p_crack`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64, p_crack: f64) -> Self {
        Self {
            alpha,
            p_crack,
            dp_override: 0.1 * p_crack,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
        }
    }

    /// The element (kind `hydraulics.sequence_valve`, ports `P`, `A`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::positive("p_crack", self.p_crack)?;
        ParamError::positive("dp_override", self.dp_override)?;
        let opening = Opening {
            name: "x",
            alpha: self.alpha,
            c: [1.0, 0.0, 0.0],
            p_set: self.p_crack,
            band: self.dp_override,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.sequence_valve",
            &["P", "A"],
            vec![opening],
            self.g_leak,
            self.p_tr,
            None,
        )
    }
}

/// Kind `hydraulics.sequence_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.sequence_valve",
    "sequence valve P → A: x = ramp((P_P − p_crack)/dp_override), Q = α·x·regRoot(P_P − P_A)",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_crack", "Pa", "inlet pressure at which it opens").positive(),
        ParamDecl::number(
            "dp_override",
            "Pa",
            "pressure rise from cracking to fully open",
        )
        .positive()
        .optional("0.1·p_crack"),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
    ],
    |p| {
        let mut v = SequenceValve::new(orifice::alpha_of(p)?, p.number("p_crack")?);
        if let Some(d) = p.optional("dp_override")? {
            v.dp_override = d;
        }
        v.smoothing = p.number("smoothing")?;
        v.g_leak = p.number("g_leak")?;
        v.p_tr = p.number("p_tr")?;
        Ok(Box::new(v.build()?))
    },
)
.example("alpha = 1e-6, p_crack = 8e6");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reg_root;

    #[test]
    fn opens_on_the_inlet_pressure_not_the_drop() {
        let v = SequenceValve::new(1e-6, 10e6).build().unwrap();
        // below the setting: shut, however low the outlet
        let q = v.flow(&[9e6, 0.0, 0.0]);
        assert!((q - 9e-9).abs() <= 1e-20, "{q:e}");
        // above it by ½Δp_override: half open, whatever the outlet
        for p_a in [0.0, 5e6, 10e6] {
            let q = v.flow(&[10.5e6, p_a, 0.0]);
            let dp = 10.5e6 - p_a;
            let e = 1e-6 * 0.5 * reg_root(dp, 1e5) + 1e-15 * dp;
            assert!((q - e).abs() <= 1e-12 * e, "{p_a}: {q:e} {e:e}");
        }
        // whereas a relief valve with the same setting, its outlet at 5 MPa, is shut
        let relief = crate::ReliefValve::new(1e-6, 10e6).build().unwrap();
        assert!(relief.flow(&[10.5e6, 5e6, 0.0]) < 1e-8);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(SequenceValve::new(1e-6, 0.0).build().is_err());
        let mut s = SequenceValve::new(1e-6, 1e6);
        s.g_leak = -1.0;
        assert!(s.build().is_err());
    }
}
