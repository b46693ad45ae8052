//! The manipulator C-field (eq. 65): `e = −G(q) + K q`.
//!
//! Gravity (eqs. 45–48) and the strain of the flexible links (eqs. 50–51) act on the
//! generalized coordinates. The displacement q is the I-field's state, read as the signal
//! `<arm>.q`, so the field stores the potential energy `V(q) = V_g(q) + ½ qᵀK q` without
//! states of its own: the power on its port, `eᵀ u = (−G + K q)ᵀ q̇ = dV/dt`, is exactly the
//! rate of V. Causality is fixed (effort out). Publishes `V` (J).

use std::sync::Arc;

use bondgraph::{CausalRule, Element, Io, PortCausality, PortSpec, Ports, SignalSpec, Slot, Stage};
use nalgebra::{DMatrix, DVector};

use crate::arm::PlanarArm;

/// The C-field of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmCompliance {
    arm: Arc<PlanarArm>,
    k: DMatrix<f64>,
    q_signal: String,
}

impl ArmCompliance {
    /// The C-field of `arm`, reading the configuration from the signal `q_signal` (`arm.q`).
    #[must_use]
    pub fn new(arm: Arc<PlanarArm>, q_signal: &str) -> Self {
        Self {
            k: arm.stiffness_matrix(),
            arm,
            q_signal: q_signal.to_owned(),
        }
    }

    /// `(−G(q) + K q, V(q))`.
    #[must_use]
    pub fn effort_and_potential(&self, q: &[f64]) -> (DVector<f64>, f64) {
        let kin = self.arm.kinematics(q);
        let qv = DVector::from_column_slice(q);
        let kq = &self.k * &qv;
        let (g, vg) = kin.gravity_terms(true);
        let v = vg + 0.5 * qv.dot(&kq);
        (kq - g, v)
    }
}

impl Element for ArmCompliance {
    fn kind(&self) -> &str {
        "manipulator.c_field"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.arm.n())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec {
            name: self.q_signal.clone(),
            dim: self.arm.n(),
        }]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("V")]
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: vec![Slot::Effort(0), Slot::Output(0)],
            reads: vec![Slot::Input(0)],
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let q = io.input(0).to_vec();
        let (e, v) = self.effort_and_potential(&q);
        for (k, ek) in e.iter().enumerate() {
            io.set_e(0, k, *ek);
        }
        io.set_y(0, 0, v);
    }
}
