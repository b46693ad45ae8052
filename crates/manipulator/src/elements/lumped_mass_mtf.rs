//! The MTF from the generalized coordinates to the lumped cylinder masses' pins (eq. 70):
//! `e₁ = J_cᵀ e₂`, `f_in₂ = −J_c f_in₁`, with the pin-velocity Jacobian `J_c` (2m × n,
//! eqs. 71–74) from the deformed pin positions.
//!
//! Drawn with port 1 from the MTF into the arm's 1-junction, e₂ is the forces (frame 0,
//! x then y per pin) applied *to the mechanism* at the pins — the spring–damper forces of
//! the lumped masses — and f_in₂ the pin velocities. The paper writes the same relation with
//! the ports named the other way round (`f_01 = J_c f_5`, `e_5 = J_cᵀ e_01`).
//!
//! Partials: besides the MTF law's (`J_cᵀ`, `−J_c`), the modulation's through q, with the
//! second derivatives of the pin positions ([`hessians`](crate::hessians)):
//! `∂e₁/∂q = Σ_pins e₂_pin · ∂²r_pin/∂q²`, `∂f_in₂/∂q = −(∂²r_pin/∂q²) f_in₁`.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, SignalSpec,
    Slot, Stage,
};
use nalgebra::{DMatrix, Vector2};

use super::at_last_q::AtLastQ;
use super::mtf_law;
use crate::arm::{Frames, PlanarArm, Station};
use crate::pin::{Pin, PinPoint};

/// The lumped-mass MTF of a [`PlanarArm`].
#[derive(Debug)]
pub struct LumpedMassTransformer {
    arm: Arc<PlanarArm>,
    stations: Vec<Station>,
    q_signal: String,
    ws: RefCell<Modulus>,
}

/// `J_cᵀ` at the last configuration q, and the frames it is computed in.
#[derive(Debug)]
struct Modulus {
    frames: Frames,
    jt: AtLastQ<DMatrix<f64>>,
    /// The MTF law's running sums (length max(n, 2m)).
    acc: Vec<f64>,
}

impl LumpedMassTransformer {
    /// The MTF to the pins `pins` (each on a link) of `arm`, reading q from `q_signal`.
    pub fn new(arm: Arc<PlanarArm>, pins: Vec<Pin>, q_signal: &str) -> Result<Self, ParamError> {
        if pins.is_empty() {
            return Err(ParamError::Shape {
                param: "lumped_masses".into(),
                message: "needs at least one pin".into(),
            });
        }
        let mut stations = Vec::with_capacity(pins.len());
        for pin in &pins {
            match arm.resolve_pin(pin)? {
                PinPoint::Station(s) => stations.push(s),
                PinPoint::Ground(_) => {
                    return Err(ParamError::Shape {
                        param: "lumped_masses".into(),
                        message: "a lumped mass must sit on a link".into(),
                    })
                }
            }
        }
        let n = arm.n();
        Ok(Self {
            ws: RefCell::new(Modulus {
                frames: arm.frames(),
                jt: AtLastQ::new(n, DMatrix::zeros(n, 2 * pins.len())),
                acc: vec![0.0; n.max(2 * pins.len())],
            }),
            arm,
            stations,
            q_signal: q_signal.to_owned(),
        })
    }
}

/// `J_cᵀ` (n × 2m, eq. 71) at q: column 2k, 2k+1 the x, y velocity Jacobian of pin k;
/// and q.
fn jt_at<'a>(
    jt: &'a mut AtLastQ<DMatrix<f64>>,
    frames: &mut Frames,
    arm: &PlanarArm,
    stations: &[Station],
    q: &[f64],
) -> (&'a [f64], &'a DMatrix<f64>) {
    jt.get_or_update(q, |q, jt| {
        let pose = arm.pose_in(q, frames);
        jt.as_mut_slice().fill(0.0);
        for (k, s) in stations.iter().enumerate() {
            pose.point_jacobian(s, |i, col| {
                jt[(i, 2 * k)] = col.x;
                jt[(i, 2 * k + 1)] = col.y;
            });
        }
    })
}

impl Element for LumpedMassTransformer {
    fn kind(&self) -> &str {
        "manipulator.lumped_mass_mtf"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("1", self.arm.n()),
            PortSpec::new("2", 2 * self.stations.len()),
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
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        mtf_law::stages()
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let mut ws = self.ws.borrow_mut();
        let Modulus { frames, jt, acc } = &mut *ws;
        let (_, jt) = jt_at(jt, frames, &self.arm, &self.stations, io.input(0));
        if stage == 0 {
            mtf_law::set_effort(io, jt, acc);
        } else {
            mtf_law::set_flow(io, jt, acc);
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let mut ws = self.ws.borrow_mut();
        let Modulus { frames, jt, .. } = &mut *ws;
        let (q, jt) = jt_at(jt, frames, &self.arm, &self.stations, io.input(0));
        let pose = self.arm.pose_in(q, frames);
        if stage == 0 {
            mtf_law::effort_partials(jac, jt);
            for (p, s) in self.stations.iter().enumerate() {
                let f = Vector2::new(io.e(1, 2 * p), io.e(1, 2 * p + 1));
                pose.point_hessian(s, |a, b, v| {
                    jac.add(jac.row(Slot::Effort(0), a), jac.input_col(0, b), f.dot(&v));
                });
            }
        } else {
            mtf_law::flow_partials(jac, jt);
            for (p, s) in self.stations.iter().enumerate() {
                let (rx, ry) = (
                    jac.row(Slot::Flow(1), 2 * p),
                    jac.row(Slot::Flow(1), 2 * p + 1),
                );
                pose.point_hessian(s, |a, b, v| {
                    let f = io.f_in(0, a);
                    jac.add(rx, jac.input_col(0, b), -v.x * f);
                    jac.add(ry, jac.input_col(0, b), -v.y * f);
                });
            }
        }
        true
    }
}
