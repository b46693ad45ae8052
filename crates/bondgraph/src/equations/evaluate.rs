//! Evaluating the plan: the right-hand side dx/dt = f(t, x), every variable at a point (for
//! probes, powers and energies), and the first variable that is not finite.

use super::{Probe, StateEquations, Step, Var, Workspace};
use crate::bond::ElementId;
use crate::element::{Io, Layout};

/// The layout a view starts with before its first element.
static EMPTY: Layout = Layout {
    ports: Vec::new(),
    inputs: Vec::new(),
    outputs: Vec::new(),
    state_offset: 0,
    n_states: 0,
};

impl StateEquations {
    /// dx/dt = f(t, x).
    pub fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            effort,
            flow,
            signals,
            ..
        } = &mut *ws;
        self.run(
            &self.rhs_steps,
            &self.owners,
            t,
            x,
            effort,
            flow,
            signals,
            dx,
        );
    }

    /// Evaluate everything at (t, x) and keep it for [`read`](Self::read).
    pub fn evaluate(&self, t: f64, x: &[f64]) {
        self.evaluate_steps(&self.steps, &self.owners, t, x);
    }

    /// Run `steps` and then `owners`' derivatives at (t, x) into the workspace, kept for
    /// [`read`](Self::read) (what `evaluate` and `evaluate_only` share).
    pub(super) fn evaluate_steps(&self, steps: &[Step], owners: &[Step], t: f64, x: &[f64]) {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            effort,
            flow,
            signals,
            dx,
        } = &mut *ws;
        self.run(steps, owners, t, x, effort, flow, signals, dx);
    }

    /// Run the stages `steps` at (t, x), in that order, then the derivatives of `owners`
    /// (elements with states) into their slices of `dx` from the values the stages left.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn run(
        &self,
        steps: &[Step],
        owners: &[Step],
        t: f64,
        x: &[f64],
        effort: &mut [f64],
        flow: &mut [f64],
        signals: &mut [f64],
        dx: &mut [f64],
    ) {
        // one view, re-pointed at each stage's layout
        let mut io = Io {
            t,
            x,
            effort,
            flow,
            signals,
            layout: &EMPTY,
        };
        for step in steps {
            io.layout = &step.layout;
            self.graph.node(step.id).element.eval(step.stage, &mut io);
        }
        for owner in owners {
            let l = &owner.layout;
            io.layout = l;
            self.graph
                .node(owner.id)
                .element
                .derivatives(&io, &mut dx[l.state_offset..l.state_offset + l.n_states]);
        }
    }

    /// Read a probe after [`evaluate`](Self::evaluate) at (t, x).
    #[must_use]
    pub fn read(&self, probe: Probe, t: f64, x: &[f64]) -> f64 {
        let ws = self.ws.borrow();
        match probe {
            Probe::Time => t,
            Probe::State(i) => x[i],
            Probe::Derivative(i) => ws.dx[i],
            Probe::Effort(o) => ws.effort[o],
            Probe::Flow(o) => ws.flow[o],
            Probe::Signal(o) => ws.signals[o],
            Probe::Power(b) => {
                let (o, d) = (self.bond_offset[b], self.graph.bond(b).dim);
                (o..o + d).map(|k| ws.effort[k] * ws.flow[k]).sum()
            }
        }
    }

    /// Power into element `id` (Σ over its ports of e·f_in) after [`evaluate`](Self::evaluate).
    #[must_use]
    pub fn power_into(&self, id: ElementId) -> f64 {
        let ws = self.ws.borrow();
        self.layouts[id]
            .ports
            .iter()
            .map(|p| {
                p.sign
                    * (p.offset..p.offset + p.dim)
                        .map(|k| ws.effort[k] * ws.flow[k])
                        .sum::<f64>()
            })
            .sum()
    }

    /// [`Element::external_power`](crate::element::Element::external_power) of element `id`
    /// after [`evaluate`](Self::evaluate) at (t, x).
    #[must_use]
    pub fn external_power(&self, id: ElementId, t: f64, x: &[f64]) -> Option<f64> {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            effort,
            flow,
            signals,
            ..
        } = &mut *ws;
        let io = Io {
            t,
            x,
            effort,
            flow,
            signals,
            layout: &self.layouts[id],
        };
        self.graph.node(id).element.external_power(&io)
    }

    /// Largest |e·f| on the ports of element `id`, the scale for [`power_into`](Self::power_into).
    #[must_use]
    pub fn power_scale(&self, id: ElementId) -> f64 {
        let ws = self.ws.borrow();
        self.layouts[id]
            .ports
            .iter()
            .map(|p| {
                (p.offset..p.offset + p.dim)
                    .map(|k| (ws.effort[k] * ws.flow[k]).abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// Stored energy of all elements that report one.
    #[must_use]
    pub fn stored_energy(&self, x: &[f64]) -> f64 {
        self.layouts
            .iter()
            .enumerate()
            .filter(|(_, l)| l.n_states > 0)
            .filter_map(|(id, l)| {
                self.graph
                    .node(id)
                    .element
                    .stored_energy(&x[l.state_offset..l.state_offset + l.n_states])
            })
            .sum()
    }

    /// Name of the first variable that is not finite after an evaluation at (t, x), in plan
    /// order, with the element that computed it; `None` if all are finite.
    #[must_use]
    pub fn first_non_finite(&self, t: f64, x: &[f64]) -> Option<String> {
        let mut effort = vec![0.0; self.n_bond_values];
        let mut flow = vec![0.0; self.n_bond_values];
        let mut signals = vec![
            0.0;
            self.signal_names
                .iter()
                .map(|(_, o, d)| o + d)
                .max()
                .unwrap_or(0)
        ];
        for &(id, stage) in &self.order {
            let mut io = Io {
                t,
                x,
                effort: &mut effort,
                flow: &mut flow,
                signals: &mut signals,
                layout: &self.layouts[id],
            };
            let node = self.graph.node(id);
            node.element.eval(stage, &mut io);
            for var in &self.writes[id][stage] {
                let (what, vals) = match *var {
                    Var::Effort(b) => (
                        format!("effort of bond {}", self.graph.bond(b).name),
                        &effort[self.bond_offset[b]..self.bond_offset[b] + self.graph.bond(b).dim],
                    ),
                    Var::Flow(b) => (
                        format!("flow of bond {}", self.graph.bond(b).name),
                        &flow[self.bond_offset[b]..self.bond_offset[b] + self.graph.bond(b).dim],
                    ),
                    Var::Signal(e, i) => {
                        let (o, d) = self.layouts[e].outputs[i];
                        (
                            format!(
                                "signal {}",
                                self.signal_names
                                    .iter()
                                    .find(|s| s.1 == o)
                                    .map_or("?", |s| s.0.as_str())
                            ),
                            &signals[o..o + d],
                        )
                    }
                };
                if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
                    return Some(format!(
                        "{what} = {v}, computed by `{}` ({})",
                        node.name,
                        node.element.kind()
                    ));
                }
            }
        }
        let mut dx = vec![0.0; self.states.len()];
        for (id, l) in self.layouts.iter().enumerate() {
            if l.n_states > 0 {
                let io = Io {
                    t,
                    x,
                    effort: &mut effort,
                    flow: &mut flow,
                    signals: &mut signals,
                    layout: l,
                };
                self.graph
                    .node(id)
                    .element
                    .derivatives(&io, &mut dx[l.state_offset..l.state_offset + l.n_states]);
            }
        }
        dx.iter()
            .position(|v| !v.is_finite())
            .map(|i| format!("derivative of state {} = {}", self.states[i].name, dx[i]))
    }
}
