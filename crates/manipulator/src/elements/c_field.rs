//! The manipulator C-field (eq. 65): `e = −G(q) + K q`.
//!
//! Gravity (eqs. 45–48) and the strain of the flexible links (eqs. 50–51) act on the
//! generalized coordinates. The displacement q is the I-field's state, read as the signal
//! `<arm>.q`, so the field stores the potential energy `V(q) = V_g(q) + ½ qᵀK q` without
//! states of its own: the power on its port, `eᵀ u = (−G + K q)ᵀ q̇ = dV/dt`, is exactly the
//! rate of V. Causality is fixed (effort out). Publishes `V` (J) in a stage of its own, which
//! the right-hand side skips unless another element reads it. Partials: `∂e/∂q = K + ∂²V_g/∂q²`
//! ([`hessians`](crate::hessians)), `∂V/∂q = e`.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, PortCausality, PortSpec, Ports, SignalSpec, Slot, Stage,
};
use nalgebra::{DMatrix, DVector};

use super::at_last_q::AtLastQ;
use crate::arm::{Frames, PlanarArm};
use crate::kinematics::ArmKinematics;

/// The C-field of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmCompliance {
    arm: Arc<PlanarArm>,
    k: DMatrix<f64>,
    /// K row by row (`K[(k, l)]` at `k n + l`), for the effort's `K q`.
    k_rows: Vec<f64>,
    q_signal: String,
    ws: RefCell<Workspace>,
}

/// G(q) and V_g(q) at the last configuration, `∂²V_g/∂q²` at the configuration of the last
/// partials, and the frames both are computed in.
#[derive(Debug)]
struct Workspace {
    frames: Frames,
    gravity: AtLastQ<Gravity>,
    gravity_hessian: AtLastQ<DMatrix<f64>>,
}

/// The generalized gravity forces G and the potential V_g.
#[derive(Debug)]
struct Gravity {
    g: Vec<f64>,
    v_g: f64,
}

impl Workspace {
    /// G and V_g at q, and q.
    fn gravity(&mut self, arm: &PlanarArm, q: &[f64]) -> (&[f64], &Gravity) {
        let Self {
            frames, gravity, ..
        } = self;
        gravity.get_or_update(q, |q, gr| {
            let kin = ArmKinematics::new(arm.pose_in(q, frames));
            gr.v_g = kin.gravity_into(&mut gr.g);
        })
    }

    /// `∂²V_g/∂q²` at q.
    fn gravity_hessian(&mut self, arm: &PlanarArm, q: &[f64]) -> &DMatrix<f64> {
        let Self {
            frames,
            gravity_hessian,
            ..
        } = self;
        let (_, h) = gravity_hessian.get_or_update(q, |q, h| {
            ArmKinematics::new(arm.pose_in(q, frames)).gravity_hessian_into(h);
        });
        h
    }
}

impl ArmCompliance {
    /// The C-field of `arm`, reading the configuration from the signal `q_signal` (`arm.q`).
    #[must_use]
    pub fn new(arm: Arc<PlanarArm>, q_signal: &str) -> Self {
        let n = arm.n();
        let k = arm.stiffness_matrix();
        Self {
            k_rows: k.transpose().as_slice().to_vec(),
            k,
            ws: RefCell::new(Workspace {
                frames: arm.frames(),
                gravity: AtLastQ::new(
                    n,
                    Gravity {
                        g: vec![0.0; n],
                        v_g: 0.0,
                    },
                ),
                gravity_hessian: AtLastQ::new(n, DMatrix::zeros(n, n)),
            }),
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
    fn energy_role(&self, _: usize) -> bondgraph::EnergyRole {
        // Stores V(q) = V_g(q) + ½qᵀKq; q is the I-field's state, so the audit integrates
        // the port power, which is exactly dV/dt.
        bondgraph::EnergyRole::Storage
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
        vec![
            Stage {
                writes: vec![Slot::Effort(0)],
                reads: vec![Slot::Input(0)],
            },
            Stage {
                writes: vec![Slot::Output(0)],
                reads: vec![Slot::Input(0)],
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let mut ws = self.ws.borrow_mut();
        let (q, gravity) = ws.gravity(&self.arm, io.input(0));
        if stage == 0 {
            for (k, gk) in gravity.g.iter().enumerate() {
                let kq: f64 = self.k_rows[k * q.len()..(k + 1) * q.len()]
                    .iter()
                    .zip(q)
                    .map(|(kl, ql)| kl * ql)
                    .sum();
                io.set_e(0, k, kq - gk);
            }
        } else {
            io.set_y(0, 0, gravity.v_g + PlanarArm::strain_energy(&self.k, q));
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let n = self.arm.n();
        let mut ws = self.ws.borrow_mut();
        if stage == 0 {
            let gravity_hessian = ws.gravity_hessian(&self.arm, io.input(0));
            for k in 0..n {
                let row = jac.row(Slot::Effort(0), k);
                for l in 0..n {
                    let v = self.k[(k, l)] + gravity_hessian[(k, l)];
                    jac.set(row, jac.input_col(0, l), v);
                }
            }
        } else {
            let row = jac.row(Slot::Output(0), 0);
            let (q, gravity) = ws.gravity(&self.arm, io.input(0));
            for (l, gl) in gravity.g.iter().enumerate() {
                let kq: f64 = q
                    .iter()
                    .enumerate()
                    .map(|(m, qm)| self.k[(l, m)] * qm)
                    .sum();
                jac.set(row, jac.input_col(0, l), kq - gl);
            }
        }
        true
    }
}
