//! Capacitor `C`: dq/dt = f_in, e = q/c. Stores q²/(2c).
//!
//! Causality: integral (effort out); derivative causality is refused. The compliance `c`
//! may be modulated (a chamber whose volume follows a stroke); then the stored energy is
//! not conserved, since the modulation does work. On a multibond the law applies
//! component-wise with one displacement per component. The displacement's nominal magnitude
//! (its absolute-tolerance scale) is `c`: the displacement at one unit of effort.

use crate::bond::PortCausality;
use crate::element::{
    CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage, StateSpec,
};
use crate::elements::component_names;
use crate::error::ParamError;
use crate::kind::{BuildError, KindDecl, ParamDecl, Params};
use crate::local_jacobian::LocalJacobian;

/// Capacitor (spring, compliance). Compliance `c` in flow·time/effort (F, m/N, m³/Pa).
#[derive(Debug)]
pub struct Capacitor {
    c: Param,
    q0: Vec<f64>,
}

impl Capacitor {
    /// A scalar capacitor with compliance `c` (> 0 if constant) and initial displacement `q0`.
    pub fn new(c: impl Into<Param>, q0: f64) -> Result<Self, ParamError> {
        Self::multi(c, vec![q0])
    }
    /// A capacitor on a multibond of dimension `q0.len()`.
    pub fn multi(c: impl Into<Param>, q0: Vec<f64>) -> Result<Self, ParamError> {
        let c = c.into();
        if let Some(v) = c.constant() {
            ParamError::positive("c", v)?;
        }
        if q0.is_empty() {
            return Err(ParamError::Shape {
                param: "q0".into(),
                message: "needs at least one component".into(),
            });
        }
        for &q in &q0 {
            ParamError::finite("q0", q)?;
        }
        Ok(Self { c, q0 })
    }
}

impl Element for Capacitor {
    fn kind(&self) -> &str {
        "C"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.q0.len())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::EffortOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        component_names("q", self.q0.len())
            .iter()
            .zip(&self.q0)
            .map(|(n, &q)| StateSpec::new(n, q).nominal(self.c.constant().unwrap_or(1.0)))
            .collect()
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.c.signal_inputs()
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, self.c.n_inputs(), 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let c = self.c.value(io, 0);
        for k in 0..self.q0.len() {
            let q = io.states()[k];
            io.set_e(0, k, q / c);
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        for (k, d) in dx.iter_mut().enumerate() {
            *d = io.f_in(0, k);
        }
    }
    fn partials_are_constant(&self) -> bool {
        self.c.constant().is_some()
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        // e = q/c(u)
        let c = self.c.value(io, 0);
        for k in 0..self.q0.len() {
            let row = jac.row(Slot::Effort(0), k);
            jac.set(row, jac.state_col(k), 1.0 / c);
            let de_dc = -io.states()[k] / (c * c);
            self.c
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), de_dc * d));
        }
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        for k in 0..self.q0.len() {
            jac.set(jac.derivative_row(k), jac.flow_col(0, k), 1.0);
        }
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        let c = self.c.constant()?;
        Some(x.iter().map(|q| q * q / (2.0 * c)).sum())
    }
}

/// Kind `C`: `dq/dt = f`, `e = q/c`.
pub const KIND: KindDecl = KindDecl::element(
    "C",
    "capacitor: dq/dt = f, e = q/c (or k·q)",
    &[
        ParamDecl::modulated("c", "", "compliance q/e (may read signals)")
            .positive()
            .optional("give `c` or `k`"),
        ParamDecl::modulated("k", "", "stiffness e/q = 1/c (may read signals)")
            .positive()
            .optional("give `c` or `k`"),
        ParamDecl::vector("q0", "", "initial displacement (a list for a multibond)").default(0.0),
    ],
    build,
)
.example("k = 100.0, q0 = 0.01");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let c = match (p.has("c"), p.has("k")) {
        (true, false) => p.modulated("c")?,
        (false, true) => match p.modulated("k")? {
            Param::Const(k) => Param::Const(1.0 / k),
            Param::Modulated {
                inputs,
                law,
                gradient: None,
            } => Param::modulated(inputs, move |t, u| 1.0 / law(t, u)),
            // c = 1/k: ∂c/∂u = −(∂k/∂u)/k²
            Param::Modulated {
                inputs,
                law,
                gradient: Some(grad),
            } => Param::modulated_exact(
                inputs,
                move |t, u| 1.0 / law(t, u),
                move |t, u, g| {
                    let k = grad(t, u, g);
                    g.iter_mut().for_each(|d| *d = -*d / (k * k));
                    1.0 / k
                },
            ),
        },
        (true, true) => {
            return Err(BuildError::conflict(
                "k",
                "give either `c` (compliance) or `k` (stiffness), not both",
            ))
        }
        (false, false) => {
            return Err(
                BuildError::missing("c", "needs `c` (compliance) or `k` (stiffness)")
                    .hint(format!("add `c = …` or `k = …` to element `{}`", p.name())),
            )
        }
    };
    Ok(Box::new(Capacitor::multi(c, p.vector("q0")?)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences() {
        let c = Capacitor::multi(
            Param::modulated(vec!["u".into()], |_, u| 0.5 + u[0]),
            vec![0.0; 2],
        )
        .unwrap();
        let port = [(2, -1.0, PortCausality::EffortOut)];
        // e[2], f_in[2], u, q[2]
        let point = [0.0, 0.0, 0.3, -0.2, 0.25, 1.2, -0.8];
        assert_eq!(check_partials(&c, &port, &point), Ok(2));
    }

    #[test]
    fn rejects_non_positive_compliance() {
        assert!(Capacitor::new(0.0, 0.0).is_err());
        assert!(Capacitor::new(-1e-3, 0.0).is_err());
        assert!(Capacitor::new(f64::INFINITY, 0.0).is_err());
        assert!(Capacitor::new(1e-3, f64::NAN).is_err());
    }

    #[test]
    fn energy_is_q_squared_over_2c() {
        let c = Capacitor::new(0.5, 0.0).unwrap();
        assert_eq!(c.stored_energy(&[2.0]), Some(4.0));
    }
}
