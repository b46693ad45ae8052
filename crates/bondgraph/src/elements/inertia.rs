//! Inertia `I`: dp/dt = e, f_in = p/m. Stores p²/(2m).
//!
//! Causality: integral (flow out); derivative causality is refused. On a multibond the law
//! applies component-wise with one momentum per component (a point mass in the plane is an
//! `I` on a 2-bond). The momentum's nominal magnitude (its absolute-tolerance scale) is `m`:
//! the momentum at one unit of flow.

use crate::bond::PortCausality;
use crate::element::{
    CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage, StateSpec,
};
use crate::elements::component_names;
use crate::error::ParamError;
use crate::kind::{BuildError, KindDecl, ParamDecl, Params};
use crate::local_jacobian::LocalJacobian;

/// Inertia (mass, inductance). Inertance `m` in effort·time/flow (kg, H, kg/m⁴).
#[derive(Debug)]
pub struct Inertia {
    m: Param,
    /// Per-component factors of `m` (all 1 unless built by [`Inertia::diagonal`]).
    weights: Vec<f64>,
    p0: Vec<f64>,
}

impl Inertia {
    /// A scalar inertia with mass `m` (> 0 if constant) and initial momentum `p0`.
    pub fn new(m: impl Into<Param>, p0: f64) -> Result<Self, ParamError> {
        Self::multi(m, vec![p0])
    }
    /// An inertia on a multibond of dimension `p0.len()`.
    pub fn multi(m: impl Into<Param>, p0: Vec<f64>) -> Result<Self, ParamError> {
        let m = m.into();
        if let Some(v) = m.constant() {
            ParamError::positive("m", v)?;
        }
        if p0.is_empty() {
            return Err(ParamError::Shape {
                param: "p0".into(),
                message: "needs at least one component".into(),
            });
        }
        for &p in &p0 {
            ParamError::finite("p0", p)?;
        }
        Ok(Self {
            m,
            weights: vec![1.0; p0.len()],
            p0,
        })
    }

    /// An inertia with one mass per component (M = diag(masses), each > 0): point masses in
    /// the plane, `masses = [m₁, m₁, m₂, m₂, …]`.
    pub fn diagonal(masses: Vec<f64>, p0: Vec<f64>) -> Result<Self, ParamError> {
        if masses.len() != p0.len() {
            return Err(ParamError::Shape {
                param: "masses".into(),
                message: format!("{} masses for {} momenta", masses.len(), p0.len()),
            });
        }
        for &w in &masses {
            ParamError::positive("m", w)?;
        }
        let mut i = Self::multi(1.0, p0)?;
        i.weights = masses;
        Ok(i)
    }
}

impl Element for Inertia {
    fn kind(&self) -> &str {
        "I"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.p0.len())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::FlowOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        component_names("p", self.p0.len())
            .iter()
            .zip(self.p0.iter().zip(&self.weights))
            .map(|(n, (&p, &w))| StateSpec::new(n, p).nominal(self.m.constant().unwrap_or(1.0) * w))
            .collect()
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.m.signal_inputs()
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, self.m.n_inputs(), 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let m = self.m.value(io, 0);
        for (k, w) in self.weights.iter().enumerate() {
            let p = io.states()[k];
            io.set_f_in(0, k, p / (m * w));
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        for (k, d) in dx.iter_mut().enumerate() {
            *d = io.e(0, k);
        }
    }
    fn partials_are_constant(&self) -> bool {
        self.m.constant().is_some()
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        // f_in = p/(m(u)·w)
        let m = self.m.value(io, 0);
        for (k, w) in self.weights.iter().enumerate() {
            let row = jac.row(Slot::Flow(0), k);
            jac.set(row, jac.state_col(k), 1.0 / (m * w));
            let df_dm = -io.states()[k] / (m * m * w);
            self.m
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), df_dm * d));
        }
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        for k in 0..self.p0.len() {
            jac.set(jac.derivative_row(k), jac.effort_col(0, k), 1.0);
        }
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        let m = self.m.constant()?;
        Some(
            x.iter()
                .zip(&self.weights)
                .map(|(p, w)| p * p / (2.0 * m * w))
                .sum(),
        )
    }
}

/// Kind `I`: `dp/dt = e`, `f = p/m`.
pub const KIND: KindDecl = KindDecl::element(
    "I",
    "inertia: dp/dt = e, f = p/m",
    &[
        ParamDecl::modulated("m", "", "inertance (mass) p/f (may read signals)").positive(),
        ParamDecl::vector("p0", "", "initial momentum (a list for a multibond)")
            .optional("0, or from `v0`"),
        ParamDecl::vector(
            "v0",
            "",
            "initial flow, instead of `p0` (needs a constant `m`)",
        )
        .optional("0"),
    ],
    build,
)
.example("m = 2.0, v0 = 0.5");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let m = p.modulated("m")?;
    let p0 = if p.has("v0") {
        if p.has("p0") {
            return Err(BuildError::conflict(
                "v0",
                "give either `p0` (momentum) or `v0` (flow), not both",
            ));
        }
        let Some(mass) = m.constant() else {
            return Err(BuildError::conflict(
                "v0",
                "`v0` needs a constant `m`; give `p0` instead",
            ));
        };
        p.vector("v0")?.into_iter().map(|v| mass * v).collect()
    } else if p.has("p0") {
        p.vector("p0")?
    } else {
        vec![0.0]
    };
    Ok(Box::new(Inertia::multi(m, p0)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences() {
        let port = [(2, 1.0, PortCausality::FlowOut)];
        let i = Inertia::diagonal(vec![2.0, 5.0], vec![0.0; 2]).unwrap();
        // e[2], f_in[2], p[2]
        let point = [0.4, -1.0, 0.0, 0.0, 3.0, -2.0];
        assert_eq!(check_partials(&i, &port, &point), Ok(2));
        let law = Param::modulated(vec!["u".into()], |_, u| 1.0 + u[0].exp());
        let i = Inertia::multi(law, vec![0.0; 2]).unwrap();
        let point = [0.4, -1.0, 0.0, 0.0, 0.3, 3.0, -2.0];
        assert_eq!(check_partials(&i, &port, &point), Ok(2));
    }

    #[test]
    fn rejects_non_positive_mass() {
        assert!(Inertia::new(0.0, 0.0).is_err());
        assert!(Inertia::new(-2.0, 0.0).is_err());
        assert!(Inertia::new(f64::NAN, 0.0).is_err());
        assert!(Inertia::multi(1.0, vec![]).is_err());
    }

    #[test]
    fn diagonal_masses_act_per_component() {
        let i = Inertia::diagonal(vec![2.0, 4.0], vec![2.0, 2.0]).unwrap();
        assert_eq!(i.stored_energy(&[2.0, 2.0]), Some(1.0 + 0.5));
        let nominal: Vec<f64> = i.states().iter().map(|s| s.nominal).collect();
        assert_eq!(nominal, [2.0, 4.0]);
        assert!(Inertia::diagonal(vec![1.0], vec![0.0, 0.0]).is_err());
        assert!(Inertia::diagonal(vec![1.0, 0.0], vec![0.0, 0.0]).is_err());
    }

    #[test]
    fn multibond_has_one_momentum_per_component() {
        let i = Inertia::multi(2.0, vec![0.0, 1.0]).unwrap();
        let names: Vec<_> = i.states().into_iter().map(|s| s.name).collect();
        assert_eq!(names, ["p[0]", "p[1]"]);
        assert_eq!(i.stored_energy(&[0.0, 2.0]), Some(1.0));
    }
}
