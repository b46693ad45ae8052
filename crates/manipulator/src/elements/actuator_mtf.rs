//! The MTF from the generalized coordinates to the linear actuators (eq. 66):
//! `e₁ = τ_b e₂`, `f_in₂ = −τ_bᵀ f_in₁`, with `τ_b = ∂l/∂q` (n × n_act) from the deformed
//! pin positions (eqs. 52–69, exact distances, docs/knuckle-boom.md).
//!
//! Drawn with port 1 from the MTF into the arm's 1-junction and the cylinder bonds into
//! port 2, e₂ is the cylinder forces F_c (positive pushing the pins apart), the MTF delivers
//! the generalized forces `τ = τ_b F_c` (eq. 69), and f_in₂ is the length rates `l̇ = τ_bᵀu`.
//! The configuration is read from the I-field's `<arm>.q`. Publishes, per actuator c (numbered
//! from 1, or from [`numbered_from`](ActuatorTransformer::numbered_from)): `l{c}` (m) and
//! `ldot{c}` (m/s, computed from the flow on port 1 whatever the bond's direction), each in a
//! stage of its own (the right-hand side skips `ldot{c}` unless an element reads it).
//!
//! Partials: besides the MTF law's (`τ_b`, `−τ_bᵀ`), the modulation's through q, with the
//! Hessian `∇²l_c` of each length ([`hessians`](crate::hessians)):
//! `∂e₁/∂q = Σ_c e₂_c ∇²l_c`, `∂f_in₂_c/∂q = −∇²l_c f_in₁`, `∂l_c/∂q = τ_b[:, c]`.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, SignalSpec,
    Slot, Stage,
};
use nalgebra::{DMatrix, Vector2};

use super::at_last_q::AtLastQ;
use super::mtf_law;
use crate::actuator::LinearActuator;
use crate::arm::{Frames, PlanarArm};
use crate::pin::PinPoint;

/// The actuator MTF of a [`PlanarArm`].
#[derive(Debug)]
pub struct ActuatorTransformer {
    arm: Arc<PlanarArm>,
    /// Per actuator, its pins (a, b) resolved on the arm.
    pins: Vec<(PinPoint, PinPoint)>,
    q_signal: String,
    first: usize,
    ws: RefCell<Modulus>,
}

/// τ_b and the lengths at the last configuration q, `∇²l_c` at the configuration of the
/// last partials, and the frames and scratch they are computed in.
#[derive(Debug)]
struct Modulus {
    frames: Frames,
    lengths: AtLastQ<Lengths>,
    hessians: AtLastQ<Vec<DMatrix<f64>>>,
    jd: Vec<Vector2<f64>>,
    /// The MTF law's running sums (length max(n, n_act)).
    acc: Vec<f64>,
}

/// `τ_b = ∂l/∂q` (column c for actuator c) and the lengths l.
#[derive(Debug)]
struct Lengths {
    tau: DMatrix<f64>,
    l: Vec<f64>,
}

impl Modulus {
    /// τ_b, the lengths and their Hessians `∇²l_c` at q.
    fn with_hessians(
        &mut self,
        arm: &PlanarArm,
        pins: &[(PinPoint, PinPoint)],
        q: &[f64],
    ) -> (&Lengths, &[DMatrix<f64>], &mut [f64]) {
        let Self {
            frames,
            lengths,
            hessians,
            jd,
            acc,
        } = self;
        let lengths = lengths_at(lengths, frames, arm, pins, q);
        let (_, hessians) = hessians.get_or_update(q, |q, hessians| {
            let pose = arm.pose_in(q, frames);
            for ((a, b), h) in pins.iter().zip(hessians) {
                pose.actuator_length_hessian(a, b, jd, h);
            }
        });
        (lengths, hessians, acc)
    }
}

fn lengths_at<'a>(
    lengths: &'a mut AtLastQ<Lengths>,
    frames: &mut Frames,
    arm: &PlanarArm,
    pins: &[(PinPoint, PinPoint)],
    q: &[f64],
) -> &'a Lengths {
    let n = arm.n();
    let (_, lengths) = lengths.get_or_update(q, |q, Lengths { tau, l }| {
        let pose = arm.pose_in(q, frames);
        for (c, (a, b)) in pins.iter().enumerate() {
            let column = &mut tau.as_mut_slice()[c * n..(c + 1) * n];
            l[c] = pose.actuator_length(a, b, column);
        }
    });
    lengths
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
        let mut pins = Vec::with_capacity(acts.len());
        for a in &acts {
            arm.check_actuator(a, q0)?;
            pins.push((arm.resolve_pin(&a.a)?, arm.resolve_pin(&a.b)?));
        }
        let n = arm.n();
        Ok(Self {
            ws: RefCell::new(Modulus {
                frames: arm.frames(),
                lengths: AtLastQ::new(
                    n,
                    Lengths {
                        tau: DMatrix::zeros(n, acts.len()),
                        l: vec![0.0; acts.len()],
                    },
                ),
                hessians: AtLastQ::new(n, vec![DMatrix::zeros(n, n); acts.len()]),
                jd: vec![Vector2::zeros(); n],
                acc: vec![0.0; n.max(acts.len())],
            }),
            arm,
            pins,
            q_signal: q_signal.to_owned(),
            first: 1,
        })
    }

    /// Number the published signals from `first` (`l{first}`, …).
    #[must_use]
    pub fn numbered_from(mut self, first: usize) -> Self {
        self.first = first;
        self
    }
}

impl Element for ActuatorTransformer {
    fn kind(&self) -> &str {
        "manipulator.actuator_mtf"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("1", self.arm.n()),
            PortSpec::new("2", self.pins.len()),
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
        let c = self.first..self.first + self.pins.len();
        c.clone()
            .map(|c| SignalSpec::scalar(&format!("l{c}")))
            .chain(c.map(|c| SignalSpec::scalar(&format!("ldot{c}"))))
            .collect()
    }
    fn port_lengths(&self) -> Vec<(usize, usize)> {
        // port 2 of a single pin pair: the pin distance l (signal `l{c}`), its flow dl/dt
        if self.pins.len() == 1 {
            vec![(1, 0)]
        } else {
            Vec::new()
        }
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let n = self.pins.len();
        let mut stages = mtf_law::stages();
        stages.push(Stage {
            writes: (0..n).map(Slot::Output).collect(),
            reads: vec![Slot::Input(0)],
        });
        stages.push(Stage {
            writes: (n..2 * n).map(Slot::Output).collect(),
            reads: vec![Slot::Flow(0), Slot::Input(0)],
        });
        stages
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let mut ws = self.ws.borrow_mut();
        let Modulus {
            frames,
            lengths,
            acc,
            ..
        } = &mut *ws;
        let Lengths { tau, l } = lengths_at(lengths, frames, &self.arm, &self.pins, io.input(0));
        let n = self.pins.len();
        match stage {
            0 => mtf_law::set_effort(io, tau, acc),
            1 => mtf_law::set_flow(io, tau, acc),
            2 => {
                for (c, lc) in l.iter().enumerate() {
                    io.set_y(c, 0, *lc);
                }
            }
            _ => {
                for c in 0..n {
                    let column = tau.column(c);
                    let ldot: f64 = column.iter().zip(io.flow(0)).map(|(t, f)| t * f).sum();
                    io.set_y(n + c, 0, ldot);
                }
            }
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let mut ws = self.ws.borrow_mut();
        let (Lengths { tau, .. }, hessians, acc) =
            ws.with_hessians(&self.arm, &self.pins, io.input(0));
        let (n, n_act) = (self.arm.n(), self.pins.len());
        let q0 = jac.input_col(0, 0); // the columns of q, contiguous
        match stage {
            0 => {
                mtf_law::effort_partials(jac, tau);
                // (e₂ read once into acc)
                let e2 = &mut acc[..n_act];
                for (c, e) in e2.iter_mut().enumerate() {
                    *e = io.e(1, c);
                }
                for k in 0..n {
                    let row = jac.row(Slot::Effort(0), k);
                    for l in 0..n {
                        let v: f64 = (0..n_act).map(|c| e2[c] * hessians[c][(k, l)]).sum();
                        jac.set(row, q0 + l, v);
                    }
                }
            }
            1 => {
                mtf_law::flow_partials(jac, tau);
                // (f_in₁ read once into acc; column l of ∇²l_c is contiguous)
                let f1 = &mut acc[..n];
                for (k, f) in f1.iter_mut().enumerate() {
                    *f = io.f_in(0, k);
                }
                for (c, h) in hessians.iter().enumerate() {
                    let row = jac.row(Slot::Flow(1), c);
                    for l in 0..n {
                        let v: f64 = h.column(l).iter().zip(&*f1).map(|(h, f)| h * f).sum();
                        jac.set(row, q0 + l, -v);
                    }
                }
            }
            2 => {
                for c in 0..n_act {
                    let row = jac.row(Slot::Output(c), 0);
                    for l in 0..n {
                        jac.set(row, q0 + l, tau[(l, c)]);
                    }
                }
            }
            _ => {
                // ldot_c = Σ_k τ_b[k, c] · (bond flow)_k, bond flow = sign · f_in
                let sign = io.sign(0);
                for (c, h) in hessians.iter().enumerate() {
                    let row = jac.row(Slot::Output(n_act + c), 0);
                    for k in 0..n {
                        jac.set(row, jac.flow_col(0, k), sign * tau[(k, c)]);
                    }
                    for l in 0..n {
                        let v: f64 = h.column(l).iter().zip(io.flow(0)).map(|(h, f)| h * f).sum();
                        jac.set(row, q0 + l, v);
                    }
                }
            }
        }
        true
    }
}
