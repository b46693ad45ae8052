//! The MTF from the generalized coordinates to the lumped cylinder masses' pins (eq. 70):
//! `e₁ = J_cᵀ e₂`, `f_in₂ = −J_c f_in₁`, with the pin-velocity Jacobian `J_c` (2m × n,
//! eqs. 71–74) from the deformed pin positions.
//!
//! Drawn with port 1 from the MTF into the arm's 1-junction, e₂ is the forces (frame 0,
//! x then y per pin) applied *to the mechanism* at the pins — the spring–damper forces of
//! the lumped masses — and f_in₂ the pin velocities. The paper writes the same relation with
//! the ports named the other way round (`f_01 = J_c f_5`, `e_5 = J_cᵀ e_01`).

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, ParamError, PortCausality, PortSpec, Ports, SignalSpec, Stage,
};
use nalgebra::DMatrix;

use super::mtf_law;
use crate::arm::PlanarArm;
use crate::pin::Pin;

/// The lumped-mass MTF of a [`PlanarArm`].
#[derive(Debug)]
pub struct LumpedMassTransformer {
    arm: Arc<PlanarArm>,
    pins: Vec<Pin>,
    q_signal: String,
    cache: RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
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
        for pin in &pins {
            if matches!(pin, Pin::Ground(_)) {
                return Err(ParamError::Shape {
                    param: "lumped_masses".into(),
                    message: "a lumped mass must sit on a link".into(),
                });
            }
            arm.check_pin(pin)?;
        }
        Ok(Self {
            arm,
            pins,
            q_signal: q_signal.to_owned(),
            cache: RefCell::new(None),
        })
    }

    /// `J_cᵀ` at q.
    fn with_modulus<R>(&self, q: &[f64], f: impl FnOnce(&DMatrix<f64>) -> R) -> R {
        let mut cache = self.cache.borrow_mut();
        if let Some((_, t)) = cache.as_ref().filter(|c| c.0 == q) {
            return f(t);
        }
        let jc = self.arm.lumped_mass_jacobian(&self.arm.pose(q), &self.pins);
        f(&cache.insert((q.to_vec(), jc.transpose())).1)
    }
}

impl Element for LumpedMassTransformer {
    fn kind(&self) -> &str {
        "manipulator.lumped_mass_mtf"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("1", self.arm.n()),
            PortSpec::new("2", 2 * self.pins.len()),
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
        mtf_law::stages(&[])
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let q = io.input(0).to_vec();
        self.with_modulus(&q, |t| {
            if stage == 0 {
                mtf_law::set_effort(io, t);
            } else {
                mtf_law::set_flow(io, t);
            }
        });
    }
}
