//! Laminar restriction `hydraulics.laminar`: `Q = (P_a − P_b)/R` from port `a` to port `b`,
//! with the resistance of a round pipe, `R = 128·μ·L/(π·d⁴)` (Hagen–Poiseuille; Merritt,
//! *Hydraulic Control Systems*, 1967, §2.6; valid for Re = ρ·v·d/μ below about 2 000).
//!
//! Causality: conductance — both ports receive their pressure (attach each to a 0-junction,
//! a chamber or a pressure source) and set their flow. Power `Q·(P_a − P_b) = (P_a − P_b)²/R`
//! is dissipated, ≥ 0.
//!
//! This kind is the worked example of `docs/adding-an-element.md`.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
};

/// Hagen–Poiseuille resistance of a round pipe, Pa·s/m³: `128·μ·L/(π·d⁴)`.
#[must_use]
pub fn pipe_resistance(mu: f64, length: f64, d: f64) -> f64 {
    128.0 * mu * length / (std::f64::consts::PI * d.powi(4))
}

/// A laminar restriction of resistance `r` (Pa·s/m³).
#[derive(Debug)]
pub struct Laminar {
    r: f64,
}

impl Laminar {
    /// A restriction of resistance `r` (Pa·s/m³, finite and > 0).
    pub fn new(r: f64) -> Result<Self, ParamError> {
        Ok(Self {
            r: ParamError::positive("r", r)?,
        })
    }
}

impl Element for Laminar {
    fn kind(&self) -> &str {
        "hydraulics.laminar"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("a", 1), PortSpec::new("b", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        use PortCausality::FlowOut;
        CausalRule::Resistive(vec![vec![FlowOut, FlowOut]])
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let q = (io.e(0, 0) - io.e(1, 0)) / self.r;
        io.set_f_in(0, 0, q); // flows in at a …
        io.set_f_in(1, 0, -q); // … and out at b
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let g = 1.0 / self.r;
        for (p, s) in [(0, 1.0), (1, -1.0)] {
            let row = jac.row(Slot::Flow(p), 0);
            jac.set(row, jac.effort_col(0, 0), s * g);
            jac.set(row, jac.effort_col(1, 0), -s * g);
        }
        true
    }
}

/// Kind `hydraulics.laminar`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.laminar",
    "laminar restriction a → b: Q = (P_a − P_b)/R, R = 128·μ·L/(π·d⁴)",
    &[
        ParamDecl::number("length", "m", "pipe length").positive(),
        ParamDecl::number("d", "m", "inner diameter").positive(),
        ParamDecl::number("mu", "Pa·s", "dynamic viscosity of the oil")
            .positive()
            .default(0.03),
    ],
    build,
)
.example("length = 2.0, d = 0.012");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let r = pipe_resistance(p.number("mu")?, p.number("length")?, p.number("d")?);
    Ok(Box::new(Laminar::new(r)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resistance_is_hagen_poiseuille() {
        // 2 m of 12 mm bore, μ = 0.03 Pa·s: R = 128·0.03·2/(π·0.012⁴) = 1.1789e8 Pa·s/m³
        let r = pipe_resistance(0.03, 2.0, 0.012);
        assert!((r - 1.178_9e8).abs() <= 1e-4 * r, "{r}");
        // halving the bore multiplies R by 16
        assert!((pipe_resistance(0.03, 2.0, 0.006) / r - 16.0).abs() < 1e-12);
    }

    #[test]
    fn flow_conserves_volume_and_dissipates() {
        use bondgraph::check_partials;
        use PortCausality::FlowOut;
        let l = Laminar::new(1.2e8).unwrap();
        let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut)];
        // P_a, Q_a, P_b, Q_b at three states, including a reversed drop
        for (pa, pb) in [(5e6, 1e6), (1e6, 1e6 + 10.0), (0.0, 2e7)] {
            assert_eq!(check_partials(&l, &ports, &[pa, 0.0, pb, 0.0]), Ok(1));
            let q = (pa - pb) / 1.2e8;
            // volume: what enters at a leaves at b; power in = (P_a − P_b)·Q ≥ 0
            let power = pa * q + pb * (-q);
            assert!(
                power >= 0.0 && (power - (pa - pb).powi(2) / 1.2e8).abs() <= 1e-9 * power.max(1.0)
            );
        }
        assert!(Laminar::new(0.0).is_err() && Laminar::new(f64::NAN).is_err());
    }
}
