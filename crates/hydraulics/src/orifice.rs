//! Orifice `hydraulics.orifice`: turbulent flow through a (possibly modulated) opening,
//! `Q = α·opening·regRoot(P_a − P_b)` from port `a` to port `b` (paper eqs. 29–31, where
//! the opening is x).
//!
//! The square root of the orifice law has an infinite slope at Δp = 0, which a stiff solver
//! sees as an infinite Jacobian entry. It is regularised as in Modelica.Fluid's `regRoot`:
//!
//! ```text
//! regRoot(Δp) = Δp / (Δp² + p_tr²)^(1/4)
//! ```
//!
//! which equals `sign(Δp)·√|Δp|` up to a relative `¼(p_tr/Δp)²` for |Δp| ≫ p_tr, is linear
//! with slope `1/√p_tr` near zero, and is C^∞ for p_tr > 0. `p_tr = 0` gives the paper's law
//! exactly.
//!
//! Causality: both ports receive their pressure and set their flow (conductance causality);
//! attach each to a 0-junction, a chamber or a pressure source. Power `Q·(P_a − P_b)` is
//! dissipated (≥ 0 for x ≥ 0).

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

/// The regularised square root `Δp / (Δp² + p_tr²)^(1/4)`; `sign(Δp)·√|Δp|` when `p_tr = 0`.
#[must_use]
pub fn reg_root(dp: f64, p_tr: f64) -> f64 {
    if p_tr == 0.0 {
        return dp.signum() * dp.abs().sqrt();
    }
    dp / (dp * dp + p_tr * p_tr).sqrt().sqrt()
}

/// The slope of [`reg_root`]: `(Δp²/2 + p_tr²)/(Δp² + p_tr²)^(5/4)`, which is `1/√p_tr` at
/// Δp = 0; `1/(2√|Δp|)` (infinite at 0) when `p_tr = 0`.
#[must_use]
pub fn reg_root_derivative(dp: f64, p_tr: f64) -> f64 {
    if p_tr == 0.0 {
        return 0.5 / dp.abs().sqrt();
    }
    let s = dp * dp + p_tr * p_tr;
    (0.5 * dp * dp + p_tr * p_tr) / (s * s.sqrt().sqrt())
}

/// Orifice coefficient `α = C_d·w·√(2/ρ)` (eq. 31): discharge coefficient `cd`, opening area
/// `w` (m²) at full opening, oil density `rho` (kg/m³). Units of α: m³/(s·√Pa).
pub fn alpha(cd: f64, w: f64, rho: f64) -> Result<f64, ParamError> {
    ParamError::positive("cd", cd)?;
    ParamError::positive("w", w)?;
    ParamError::positive("rho", rho)?;
    Ok(cd * w * (2.0 / rho).sqrt())
}

/// Two-port orifice: `Q = α·opening·regRoot(P_a − P_b)` flows from `a` to `b`.
///
/// * `alpha` — orifice coefficient α, m³/(s·√Pa), > 0 (see [`alpha`]).
/// * `opening` — relative opening x (dimensionless, may be modulated); not clamped.
/// * `p_tr` — transition pressure of the regularisation, Pa, ≥ 0.
#[derive(Debug)]
pub struct Orifice {
    alpha: f64,
    opening: Param,
    p_tr: f64,
}

impl Orifice {
    /// An orifice with coefficient `alpha`, opening `opening` and transition pressure `p_tr`.
    pub fn new(alpha: f64, opening: impl Into<Param>, p_tr: f64) -> Result<Self, ParamError> {
        ParamError::positive("alpha", alpha)?;
        ParamError::non_negative("p_tr", p_tr)?;
        let opening = opening.into();
        if let Some(x) = opening.constant() {
            ParamError::finite("opening", x)?;
        }
        Ok(Self {
            alpha,
            opening,
            p_tr,
        })
    }

    /// Flow from `a` to `b` at pressures `p_a`, `p_b` and opening `x`.
    #[must_use]
    pub fn flow(&self, x: f64, p_a: f64, p_b: f64) -> f64 {
        self.alpha * x * reg_root(p_a - p_b, self.p_tr)
    }
}

impl Element for Orifice {
    fn kind(&self) -> &str {
        "hydraulics.orifice"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("a", 1), PortSpec::new("b", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut, PortCausality::FlowOut]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.opening.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Effort(0), Slot::Effort(1)];
        reads.extend((0..self.opening.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: vec![Slot::Flow(0), Slot::Flow(1)],
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let q = self.flow(self.opening.value(io, 0), io.e(0, 0), io.e(1, 0));
        io.set_f_in(0, 0, q);
        io.set_f_in(1, 0, -q);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let x = self.opening.value(io, 0);
        let dp = io.e(0, 0) - io.e(1, 0);
        // q = α·x·regRoot(Δp): ∂q/∂P_a = −∂q/∂P_b = α·x·regRoot′(Δp)
        let dq_dp = self.alpha * x * reg_root_derivative(dp, self.p_tr);
        let dq_dx = self.alpha * reg_root(dp, self.p_tr);
        for (p, s) in [(0, 1.0), (1, -1.0)] {
            let row = jac.row(Slot::Flow(p), 0);
            jac.set(row, jac.effort_col(0, 0), s * dq_dp);
            jac.set(row, jac.effort_col(1, 0), -s * dq_dp);
            self.opening.partials(io, 0, |i, d| {
                jac.set(row, jac.input_col(i, 0), s * dq_dx * d)
            });
        }
        true
    }
}

/// `alpha`: the orifice coefficient, or …
pub const ALPHA: ParamDecl = ParamDecl::number(
    "alpha",
    "m³/(s·√Pa)",
    "orifice coefficient α at full opening",
)
.positive()
.optional("from `cd`, `w`, `rho` (eq. 31)");
/// … `cd`, `w`, `rho` for eq. 31.
pub const CD: ParamDecl = ParamDecl::number("cd", "1", "discharge coefficient")
    .positive()
    .optional("give `alpha` instead");
/// Opening area at full opening.
pub const W: ParamDecl = ParamDecl::number("w", "m²", "orifice area at full opening")
    .positive()
    .optional("give `alpha` instead");
/// Oil density.
pub const RHO: ParamDecl = ParamDecl::number("rho", "kg/m³", "oil density")
    .positive()
    .optional("give `alpha` instead");
/// Transition pressure of the regularised square root.
pub const P_TR: ParamDecl = ParamDecl::number(
    "p_tr",
    "Pa",
    "transition pressure of regRoot (0: the paper's law)",
)
.non_negative()
.default(1e5);

/// α from `alpha`, or from `cd`, `w` and `rho` (eq. 31).
pub fn alpha_of(p: &dyn Params) -> Result<f64, BuildError> {
    if p.has("alpha") {
        if let Some(k) = ["cd", "w", "rho"].into_iter().find(|k| p.has(k)) {
            return Err(BuildError::conflict(
                k,
                "give either `alpha` or `cd`, `w`, `rho`, not both",
            ));
        }
        return p.number("alpha");
    }
    if !(p.has("cd") || p.has("w") || p.has("rho")) {
        return Err(BuildError::missing(
            "alpha",
            "needs the orifice coefficient: `alpha`, or `cd`, `w` and `rho`",
        )
        .hint(format!(
            "add e.g. `cd = 0.6, w = 0.0007, rho = 880.0` to `{}` (α = cd·w·√(2/rho))",
            p.name()
        )));
    }
    Ok(alpha(p.number("cd")?, p.number("w")?, p.number("rho")?)?)
}

/// Kind `hydraulics.orifice`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.orifice",
    "orifice a → b: Q = α·opening·regRoot(P_a − P_b)",
    &[
        ALPHA,
        CD,
        W,
        RHO,
        ParamDecl::modulated("opening", "1", "relative opening x (not clamped)").default(1.0),
        P_TR,
    ],
    |p| {
        Ok(Box::new(Orifice::new(
            alpha_of(p)?,
            p.modulated("opening")?,
            p.number("p_tr")?,
        )?))
    },
)
.example("cd = 0.6, w = 1e-5, rho = 880");

#[cfg(test)]
mod tests {
    use super::*;

    fn paper(dp: f64) -> f64 {
        dp.signum() * dp.abs().sqrt()
    }

    #[test]
    fn zero_transition_pressure_is_the_paper_law_exactly() {
        for dp in [-2.5e7, -3.0, -1e-12, 0.0, 1e-12, 7.0, 1e5, 2.5e7] {
            assert_eq!(reg_root(dp, 0.0).to_bits(), paper(dp).to_bits(), "{dp}");
        }
    }

    #[test]
    fn equals_the_square_root_far_from_zero() {
        // relative deviation (1 + (p_tr/Δp)²)^(-1/4) − 1 ≈ −¼(p_tr/Δp)² ≤ 2.5e-5 at |Δp| ≥ 100 p_tr
        let p_tr = 1e5;
        for dp in [1e7, 2.5e7, -1e7, -3e7, 5e7] {
            let rel = (reg_root(dp, p_tr) - paper(dp)).abs() / paper(dp).abs();
            assert!(rel <= 2.5e-5, "Δp = {dp}: relative deviation {rel:e}");
            let expected = 0.25 * (p_tr / dp).powi(2);
            assert!(
                (rel - expected).abs() <= 1e-3 * expected,
                "{rel:e} vs {expected:e}"
            );
        }
    }

    #[test]
    fn is_c1_at_zero() {
        // Slope 1/√p_tr from both sides, by one-sided finite differences (error O(h²/p_tr²)).
        let p_tr: f64 = 1e5;
        let slope = 1.0 / p_tr.sqrt();
        for h in [1.0, 10.0, 100.0] {
            let right = (reg_root(h, p_tr) - reg_root(0.0, p_tr)) / h;
            let left = (reg_root(0.0, p_tr) - reg_root(-h, p_tr)) / h;
            assert!((right - slope).abs() <= 1e-6 * slope, "h = {h}: {right:e}");
            assert!((left - slope).abs() <= 1e-6 * slope, "h = {h}: {left:e}");
        }
        // the derivative is continuous: central differences just left and right of 0 agree
        let d = |p: f64| (reg_root(p + 1e-3, p_tr) - reg_root(p - 1e-3, p_tr)) / 2e-3;
        assert!((d(1e-2) - d(-1e-2)).abs() <= 1e-9 * slope);
        // whereas the paper's law has no finite slope there
        assert!((paper(1e-6) - paper(0.0)) / 1e-6 > 900.0);
    }

    #[test]
    fn reg_root_derivative_is_exact() {
        for p_tr in [0.0, 1e5] {
            for dp in [-3e7_f64, -2e5, -1e3, 1e-2, 5e4, 1e5, 2.5e7] {
                let h = 1e-5 * dp.abs();
                let fd = (reg_root(dp + h, p_tr) - reg_root(dp - h, p_tr)) / (2.0 * h);
                let d = reg_root_derivative(dp, p_tr);
                assert!(
                    (d - fd).abs() <= 1e-8 * d.abs(),
                    "{p_tr} {dp}: {d:e} {fd:e}"
                );
            }
        }
        assert!((reg_root_derivative(0.0, 1e4) - 1e-2).abs() < 1e-15);
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        let o = Orifice::new(2e-6, Param::modulated(vec!["x".into()], |_, u| u[0]), 1e5).unwrap();
        let ports = [
            (1, 1.0, PortCausality::FlowOut),
            (1, -1.0, PortCausality::FlowOut),
        ];
        // P_a, Q_a, P_b, Q_b, x
        for (pa, pb) in [(4e6, 1e6), (1e6, 1.02e6), (2e5, 9e6)] {
            let point = [pa, 1e-3, pb, 1e-3, 0.6];
            assert_eq!(check_partials(&o, &ports, &point), Ok(1), "{pa} {pb}");
        }
    }

    #[test]
    fn alpha_is_eq_31() {
        let a = alpha(0.6, 0.0007, 880.0).unwrap();
        assert!((a - 0.6 * 0.0007 * (2.0f64 / 880.0).sqrt()).abs() < 1e-18);
        assert!(alpha(0.0, 0.0007, 880.0).is_err());
        assert!(alpha(0.6, 0.0007, -1.0).is_err());
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Orifice::new(0.0, 1.0, 1e5).is_err());
        assert!(Orifice::new(1e-6, 1.0, -1.0).is_err());
        assert!(Orifice::new(1e-6, f64::NAN, 1e5).is_err());
        let o = Orifice::new(2e-6, 0.5, 0.0).unwrap();
        assert!((o.flow(0.5, 4e6, 0.0) - 2e-6 * 0.5 * 2000.0).abs() < 1e-15);
        assert!((o.flow(0.5, 0.0, 4e6) + 2e-6 * 0.5 * 2000.0).abs() < 1e-15);
    }
}
