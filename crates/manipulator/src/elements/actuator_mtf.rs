//! The MTF from the generalized coordinates to the linear actuators (eq. 66):
//! `e₁ = τ_b e₂`, `f_in₂ = −τ_bᵀ f_in₁`, with `τ_b = ∂l/∂q` (n × n_act) from the deformed
//! pin positions (eqs. 52–69, exact distances per the design page).
//!
//! Drawn with port 1 from the MTF into the arm's 1-junction and the cylinder bonds into
//! port 2, e₂ is the cylinder forces F_c (positive pushing the pins apart), the MTF delivers
//! the generalized forces `τ = τ_b F_c` (eq. 69), and f_in₂ is the length rates `l̇ = τ_bᵀu`.
//! The configuration is read from the I-field's `<arm>.q`. Publishes, per actuator c (numbered
//! from 1, or from [`numbered_from`](ActuatorTransformer::numbered_from)): `l{c}` (m) and
//! `ldot{c}` (m/s, computed from the flow on port 1 whatever the bond's direction).

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, ParamError, PortCausality, PortSpec, Ports, SignalSpec, Slot, Stage,
};
use nalgebra::DMatrix;

use super::mtf_law;
use crate::actuator::LinearActuator;
use crate::arm::PlanarArm;

/// τ_b and the lengths at one configuration q.
type Modulus = (Vec<f64>, DMatrix<f64>, Vec<f64>);

/// The actuator MTF of a [`PlanarArm`].
#[derive(Debug)]
pub struct ActuatorTransformer {
    arm: Arc<PlanarArm>,
    acts: Vec<LinearActuator>,
    q_signal: String,
    first: usize,
    cache: RefCell<Option<Modulus>>,
}

impl ActuatorTransformer {
    /// The MTF of `acts` on `arm`, reading q from `q_signal`; `q0` checks the pins are apart.
    pub fn new(
        arm: Arc<PlanarArm>,
        acts: Vec<LinearActuator>,
        q_signal: &str,
        q0: &[f64],
    ) -> Result<Self, ParamError> {
        if acts.is_empty() {
            return Err(ParamError::Shape {
                param: "actuators".into(),
                message: "needs at least one actuator".into(),
            });
        }
        for a in &acts {
            arm.check_actuator(a, q0)?;
        }
        Ok(Self {
            arm,
            acts,
            q_signal: q_signal.to_owned(),
            first: 1,
            cache: RefCell::new(None),
        })
    }

    /// Number the published signals from `first` (`l{first}`, …).
    #[must_use]
    pub fn numbered_from(mut self, first: usize) -> Self {
        self.first = first;
        self
    }

    /// `(τ_b, lengths)` at q.
    fn with_modulus<R>(&self, q: &[f64], f: impl FnOnce(&DMatrix<f64>, &[f64]) -> R) -> R {
        let mut cache = self.cache.borrow_mut();
        if let Some((_, t, l)) = cache.as_ref().filter(|c| c.0 == q) {
            return f(t, l);
        }
        let pose = self.arm.pose(q);
        let t = self.arm.actuator_jacobian(&pose, &self.acts);
        let l = self.acts.iter().map(|a| a.length(&pose)).collect();
        let (_, t, l) = cache.insert((q.to_vec(), t, l));
        f(t, l)
    }
}

impl Element for ActuatorTransformer {
    fn kind(&self) -> &str {
        "manipulator.actuator_mtf"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("1", self.arm.n()),
            PortSpec::new("2", self.acts.len()),
        ])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut, PortCausality::FlowOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec {
            name: self.q_signal.clone(),
            dim: self.arm.n(),
        }]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let c = self.first..self.first + self.acts.len();
        c.clone()
            .map(|c| SignalSpec::scalar(&format!("l{c}")))
            .chain(c.map(|c| SignalSpec::scalar(&format!("ldot{c}"))))
            .collect()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let n = self.acts.len();
        let mut stages = mtf_law::stages(&(n..2 * n).collect::<Vec<_>>());
        stages.push(Stage {
            writes: (0..n).map(Slot::Output).collect(),
            reads: vec![Slot::Input(0)],
        });
        stages
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let q = io.input(0).to_vec();
        let n = self.acts.len();
        self.with_modulus(&q, |t, l| match stage {
            0 => mtf_law::set_effort(io, t),
            1 => {
                mtf_law::set_flow(io, t);
                for c in 0..n {
                    let ldot: f64 = (0..t.nrows()).map(|i| t[(i, c)] * io.flow(0)[i]).sum();
                    io.set_y(n + c, 0, ldot);
                }
            }
            _ => {
                for (c, lc) in l.iter().enumerate() {
                    io.set_y(c, 0, *lc);
                }
            }
        });
    }
}
