//! Piston `hydraulics.piston`: the transformer pair A_p, A_r between the chamber pressures
//! and the cylinder's force and length rate (paper eqs. 80–81), with the stroke as its state.
//!
//! Ports `p` (piston-side line), `r` (rod-side line), `mech` (the rod). With v = ṡ = dl/dt
//! the extension rate (the flow *out of* `mech`), power in positive:
//!
//! ```text
//! e_mech = F_c = A_p·P_p − A_r·P_r        (positive pushes the pins apart)
//! f_in,p = A_p·v      f_in,r = −A_r·v     (the piston sweeps A_p·v out of the piston side
//!                                          and pushes A_r·v into the rod side)
//! ds/dt  = v
//! ```
//!
//! Power is conserved exactly: P_p·A_p·v − P_r·A_r·v − F_c·v = 0.
//!
//! Causality is fixed: the mechanism sets the velocity, the chambers set the pressures
//! (`p`, `r` receive effort; `mech` sets it). The piston publishes `l = l⁰ + s` (the cylinder
//! length, m) for controllers.
//!
//! **Leaving the stroke range.** A piston *without* an end stop (`guard = true`) declares its
//! stroke's bounds `[0, s_max]` as a [`Limit`]: the solver locates the crossing exactly (root
//! finding) and the run stops there with `SimulationError::LimitReached`, naming the piston,
//! its state `s`, the bound and the time. The rows before are kept. With an end stop
//! (`guard = false`) the piston goes on past the ends and the stop pushes it back.

use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, Limit, LocalJacobian, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage, StateSpec,
};

/// Piston with areas `a_p` (piston side) and `a_r` (rod side, annulus), m², and its stroke.
///
/// * `l0` — cylinder length at s = 0 (fully retracted), m; only for the published `l`.
/// * `s0` — initial stroke, m; `s_max` — usable stroke, m, > 0.
/// * `guard` — stop the run when the stroke leaves `[0, s_max]` (no end stop in the model).
#[derive(Debug)]
pub struct Piston {
    a_p: f64,
    a_r: f64,
    l0: f64,
    s0: f64,
    s_max: f64,
    guard: bool,
}

impl Piston {
    /// A piston; `0 ≤ s0 ≤ s_max` is required when `guard` is on.
    pub fn new(
        a_p: f64,
        a_r: f64,
        l0: f64,
        s0: f64,
        s_max: f64,
        guard: bool,
    ) -> Result<Self, ParamError> {
        ParamError::positive("a_p", a_p)?;
        ParamError::positive("a_r", a_r)?;
        ParamError::finite("l0", l0)?;
        ParamError::finite("s0", s0)?;
        ParamError::positive("s_max", s_max)?;
        if guard && !(0.0..=s_max).contains(&s0) {
            return Err(ParamError::Shape {
                param: "s0".into(),
                message: format!("initial stroke {s0} m is outside the stroke [0, {s_max}] m"),
            });
        }
        Ok(Self {
            a_p,
            a_r,
            l0,
            s0,
            s_max,
            guard,
        })
    }

    /// Cylinder force `F_c = A_p·P_p − A_r·P_r` (N).
    #[must_use]
    pub fn force(&self, p_p: f64, p_r: f64) -> f64 {
        self.a_p * p_p - self.a_r * p_r
    }

    fn v(io: &Io<'_>) -> f64 {
        -io.f_in(2, 0)
    }
}

impl Element for Piston {
    fn kind(&self) -> &str {
        "hydraulics.piston"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("p", 1),
            PortSpec::new("r", 1),
            PortSpec::new("mech", 1),
        ])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        use PortCausality::{EffortOut, FlowOut};
        CausalRule::Fixed(vec![FlowOut, FlowOut, EffortOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("s", self.s0).nominal(self.s_max)]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("l")]
    }
    fn port_lengths(&self) -> Vec<(usize, usize)> {
        vec![(2, 0)] // port mech: the cylinder length l = l0 + s (its flow is ds/dt)
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![
            Stage {
                writes: vec![Slot::Output(0)],
                reads: Vec::new(),
            },
            Stage {
                writes: vec![Slot::Effort(2)],
                reads: vec![Slot::Effort(0), Slot::Effort(1)],
            },
            Stage {
                writes: vec![Slot::Flow(0), Slot::Flow(1)],
                reads: vec![Slot::Flow(2)],
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        match stage {
            0 => {
                let s = io.states()[0];
                io.set_y(0, 0, self.l0 + s);
            }
            1 => {
                let f = self.force(io.e(0, 0), io.e(1, 0));
                io.set_e(2, 0, f);
            }
            _ => {
                let v = Self::v(io);
                io.set_f_in(0, 0, self.a_p * v);
                io.set_f_in(1, 0, -self.a_r * v);
            }
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = Self::v(io);
    }
    fn stage_partials(&self, stage: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        match stage {
            0 => jac.set(jac.row(Slot::Output(0), 0), jac.state_col(0), 1.0),
            1 => {
                let row = jac.row(Slot::Effort(2), 0);
                jac.set(row, jac.effort_col(0, 0), self.a_p);
                jac.set(row, jac.effort_col(1, 0), -self.a_r);
            }
            _ => {
                // v = −f_in,mech
                let col = jac.flow_col(2, 0);
                jac.set(jac.row(Slot::Flow(0), 0), col, -self.a_p);
                jac.set(jac.row(Slot::Flow(1), 0), col, self.a_r);
            }
        }
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        jac.set(jac.derivative_row(0), jac.flow_col(2, 0), -1.0);
        true
    }
    fn limits(&self) -> Vec<Limit> {
        if !self.guard {
            return Vec::new();
        }
        vec![Limit {
            state: 0,
            lower: 0.0,
            upper: self.s_max,
            message: format!(
                "the piston left its stroke [0, {}] m and the cylinder has no end stop",
                self.s_max
            ),
            hint: Some(
                "add an end stop (k_stop, c_stop) or keep the set-point inside the stroke".into(),
            ),
        }]
    }
}

/// Kind `hydraulics.piston`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.piston",
    "cylinder piston, TF pair: F = A_p·P_p − A_r·P_r, Q_p = A_p·ṡ, Q_r = −A_r·ṡ; state s, publishes l",
    &[
        ParamDecl::number("a_p", "m²", "piston area").positive(),
        ParamDecl::number("a_r", "m²", "annulus area").positive(),
        ParamDecl::number("l0", "m", "length at s = 0; publishes l = l0 + s").default(0.0),
        ParamDecl::number("s0", "m", "initial stroke").default(0.0),
        ParamDecl::number("s_max", "m", "usable stroke").positive(),
        ParamDecl::flag("guard", true, "stop the run outside [0, s_max] (false with an end stop)"),
    ],
    |p| {
        Ok(Box::new(Piston::new(
            p.number("a_p")?,
            p.number("a_r")?,
            p.number("l0")?,
            p.number("s0")?,
            p.number("s_max")?,
            p.flag("guard")?,
        )?))
    },
)
.example("a_p = 0.0045, a_r = 0.0025, s_max = 0.5");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_is_a_p_p_p_minus_a_r_p_r() {
        let p = Piston::new(0.0452389, 0.0424115, 3.5, 0.1, 2.7, true).unwrap();
        let f = p.force(11.3e6, 1e6);
        assert!((f - (0.0452389 * 11.3e6 - 0.0424115 * 1e6)).abs() < 1e-6);
    }

    #[test]
    fn guard_limits_exactly_the_stroke() {
        let p = Piston::new(0.04, 0.03, 3.5, 0.0, 2.7, true).unwrap();
        let l = p.limits();
        assert_eq!(l.len(), 1);
        assert_eq!((l[0].state, l[0].lower, l[0].upper), (0, 0.0, 2.7));
        assert!(l[0].message.contains("end stop"));
        let q = Piston::new(0.04, 0.03, 3.5, 0.0, 2.7, false).unwrap();
        assert!(q.limits().is_empty());
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        use PortCausality::{EffortOut, FlowOut};
        let p = Piston::new(0.045, 0.042, 3.5, 0.1, 2.7, true).unwrap();
        let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut), (1, -1.0, EffortOut)];
        // P_p, Q_p, P_r, Q_r, F, v_in, s
        let point = [11e6, 1e-3, 1e6, -1e-3, 4e5, -0.05, 1.2];
        assert_eq!(check_partials(&p, &ports, &point), Ok(4));
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Piston::new(0.0, 0.03, 3.5, 0.0, 2.7, true).is_err());
        assert!(Piston::new(0.04, -0.03, 3.5, 0.0, 2.7, true).is_err());
        assert!(Piston::new(0.04, 0.03, 3.5, 0.0, 0.0, true).is_err());
        assert!(Piston::new(0.04, 0.03, 3.5, 3.0, 2.7, true).is_err());
        assert!(Piston::new(0.04, 0.03, 3.5, 3.0, 2.7, false).is_ok());
    }
}
