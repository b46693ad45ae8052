//! The inertial loads of a moving base on the arm, as a field on the arm's 1-junction:
//! `e = −G(q; f − f₀)` with f the apparent gravity in the base's axes (read from the base
//! element) and `f₀ = (0, −g)` the gravity the C-field already applies
//! ([`base`](crate::base)). Like the C-field it has fixed effort-out causality and no
//! states; its port power is the work of the fictitious field. The partials are left to the
//! core's local differences (the element exists only with a moving base).

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{CausalRule, Element, Io, PortCausality, PortSpec, Ports, SignalSpec, Slot, Stage};
use nalgebra::Vector2;

use crate::arm::{Frames, PlanarArm};
use crate::kinematics::ArmKinematics;

/// The base loads of a [`PlanarArm`].
#[derive(Debug)]
pub struct BaseLoads {
    arm: Arc<PlanarArm>,
    q_signal: String,
    field: [String; 2],
    ws: RefCell<(Frames, Vec<f64>)>,
}

impl BaseLoads {
    /// The loads on `arm` at the configuration `q_signal`, in the apparent gravity
    /// (`field[0]`, `field[1]`: signals, m/s², base axes).
    #[must_use]
    pub fn new(arm: Arc<PlanarArm>, q_signal: &str, field: [String; 2]) -> Self {
        Self {
            ws: RefCell::new((arm.frames(), vec![0.0; arm.n()])),
            arm,
            q_signal: q_signal.to_owned(),
            field,
        }
    }
}

impl Element for BaseLoads {
    fn kind(&self) -> &str {
        "manipulator.base_loads"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.arm.n())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![
            SignalSpec {
                name: self.q_signal.clone(),
                dim: self.arm.n(),
            },
            SignalSpec::scalar(&self.field[0]),
            SignalSpec::scalar(&self.field[1]),
        ]
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: vec![Slot::Effort(0)],
            reads: vec![Slot::Input(0), Slot::Input(1), Slot::Input(2)],
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let mut ws = self.ws.borrow_mut();
        let (frames, forces) = &mut *ws;
        let df = Vector2::new(io.u(1), io.u(2) + self.arm.gravity());
        let kin = ArmKinematics::new(self.arm.pose_in(io.input(0), frames));
        kin.field_forces_into(&df, forces);
        drop(kin);
        for (k, f) in forces.iter().enumerate() {
            io.set_e(0, k, -f);
        }
    }
}
