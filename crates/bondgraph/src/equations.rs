//! [`StateEquations`]: the evaluation plan computing dx/dt = f(t, x) from a [`CausalGraph`].
//!
//! Every element splits its work into stages ([`Stage`](crate::Stage)); a stage writes some variables
//! (efforts, flows, signals) from others. The stages are ordered topologically over their
//! data dependencies (petgraph's `toposort`); a cycle is an algebraic loop, reported with the
//! elements and bonds on it. Evaluating the plan fills every effort, flow and signal; then
//! each storage element and signal block writes its state derivatives.
//!
//! - `plan`: building the plan (storage, stages, their order, algebraic loops).
//! - `names`: signal names an element reads, probe names a run outputs.
//! - `evaluate`: `rhs`, evaluation at a point, powers, energies, the first non-finite value.
//! - `subset`: the stages a set of probes needs, and evaluating only those.
//! - `inputs`: external inputs set from outside.
//! - `jacobian`: the exact Jacobian (dense or sparse), compiled from the plan.
//! - `lengths`: port lengths that must agree.

use std::cell::RefCell;

use crate::bond::{BondId, ElementId, PortCausality};
use crate::element::{Element, Layout};
use crate::error::GraphError;
use crate::graph::{check_same_shape, BondGraph};

mod evaluate;
mod inputs;
mod jacobian;
mod lengths;
mod names;
mod plan;
mod subset;
pub use lengths::{LengthMismatch, LENGTH_TOLERANCE_ABS, LENGTH_TOLERANCE_REL};
pub use subset::Subset;

/// A named state of the assembled system.
#[derive(Clone, Debug)]
pub struct StateInfo {
    /// `<element>.<state>`, e.g. `mass.p`.
    pub name: String,
    /// Owning element.
    pub element: ElementId,
    /// Initial value.
    pub initial: f64,
    /// Nominal magnitude (absolute tolerance scale).
    pub nominal: f64,
}

/// A quantity that can be read after an evaluation: a column of the results.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Probe {
    /// Simulation time.
    Time,
    /// State `i`.
    State(usize),
    /// Derivative of state `i`.
    Derivative(usize),
    /// Effort component at an offset of the effort array.
    Effort(usize),
    /// Flow component at an offset of the flow array.
    Flow(usize),
    /// Signal component at an offset of the signal array.
    Signal(usize),
    /// Power e·f on a bond (summed over components), in the half-arrow's direction.
    Power(BondId),
}

#[derive(Debug, Default)]
struct Workspace {
    effort: Vec<f64>,
    flow: Vec<f64>,
    signals: Vec<f64>,
    dx: Vec<f64>,
}

/// The assembled system: states, evaluation order and all variables by name.
#[derive(Debug)]
pub struct StateEquations {
    graph: BondGraph,
    effort_setter: Vec<ElementId>,
    layouts: Vec<Layout>,
    order: Vec<(ElementId, usize)>,
    /// `order` without the stages whose results only outputs read, directly or through other
    /// such stages (skipped by `rhs`).
    rhs_order: Vec<(ElementId, usize)>,
    /// `order` and `rhs_order` as flat [`Step`]s, run by `evaluate` and `rhs`.
    steps: Vec<Step>,
    rhs_steps: Vec<Step>,
    /// The elements with states, in element order (their derivatives fill dx).
    owners: Vec<Step>,
    /// Per element, per stage: the variables it writes (for diagnostics).
    writes: Vec<Vec<Vec<Var>>>,
    states: Vec<StateInfo>,
    bond_offset: Vec<usize>,
    n_bond_values: usize,
    signal_names: Vec<(String, usize, usize)>,
    ws: RefCell<Workspace>,
    /// The Jacobian compiled for `rhs_order` and its buffers, made by its first call.
    jac: RefCell<jacobian::JacobianState>,
    /// The external inputs ([`Input`](crate::Input) elements), in element order.
    inputs: Vec<ElementId>,
    /// Whether a run stops and restarts at the inputs' breakpoints (default: yes).
    stop_at_breakpoints: bool,
}

/// One call of a plan, made flat at plan time: the element, which of its stages (0 for a
/// call of its derivatives) and a copy of its layout, so the loops read no other table.
#[derive(Clone, Debug)]
struct Step {
    id: ElementId,
    stage: usize,
    layout: Layout,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Var {
    Effort(BondId),
    Flow(BondId),
    Signal(ElementId, usize),
}

impl StateEquations {
    /// The graph behind the equations.
    #[must_use]
    pub fn graph(&self) -> &BondGraph {
        &self.graph
    }

    /// The element that sets the effort of each bond.
    #[must_use]
    pub fn effort_setter(&self) -> &[ElementId] {
        &self.effort_setter
    }

    /// Number of states.
    #[must_use]
    pub fn n_states(&self) -> usize {
        self.states.len()
    }

    /// The states, in the order of the state vector.
    #[must_use]
    pub fn states(&self) -> &[StateInfo] {
        &self.states
    }

    /// Index in the state vector of element `id`'s local state `local`.
    #[must_use]
    pub fn state_index(&self, id: ElementId, local: usize) -> Option<usize> {
        let l = self.layouts.get(id)?;
        (local < l.n_states).then_some(l.state_offset + local)
    }

    /// Initial state vector.
    #[must_use]
    pub fn initial_state(&self) -> Vec<f64> {
        self.states.iter().map(|s| s.initial).collect()
    }

    /// Set the initial value of a state by name.
    pub fn set_initial(&mut self, name: &str, value: f64) -> Result<(), GraphError> {
        let s = self
            .states
            .iter_mut()
            .find(|s| s.name == name)
            .ok_or_else(|| GraphError::UnknownElement {
                name: name.to_owned(),
            })?;
        s.initial = value;
        Ok(())
    }

    /// `order` as [`Step`]s.
    fn steps_of(&self, order: &[(ElementId, usize)]) -> Vec<Step> {
        order
            .iter()
            .map(|&(id, stage)| Step {
                id,
                stage,
                layout: self.layouts[id].clone(),
            })
            .collect()
    }

    /// The elements `ids` as [`Step`]s of their derivatives.
    fn owners_of(&self, ids: impl Iterator<Item = ElementId>) -> Vec<Step> {
        ids.map(|id| Step {
            id,
            stage: 0,
            layout: self.layouts[id].clone(),
        })
        .collect()
    }

    /// Number of signal scalars.
    fn n_signal_values(&self) -> usize {
        self.signal_names
            .iter()
            .map(|(_, o, d)| o + d)
            .max()
            .unwrap_or(0)
    }

    /// Evaluation order: (element, stage) pairs.
    #[must_use]
    pub fn order(&self) -> Vec<(String, usize)> {
        self.order
            .iter()
            .map(|&(id, s)| (self.graph.node(id).name.clone(), s))
            .collect()
    }

    /// Replace element `id` by one of identical shape that accepts the assigned causality
    /// (used by scheduled events).
    pub fn replace(
        &mut self,
        id: ElementId,
        element: Box<dyn Element>,
    ) -> Result<Box<dyn Element>, GraphError> {
        self.check_replacement(id, element.as_ref())?;
        self.graph.replace(id, element)
    }

    /// Check a replacement would be accepted, without doing it: same kind, ports, states and
    /// signals, a causal rule that admits the causality already assigned, and the same
    /// stages (so the evaluation plan stays valid).
    pub fn check_replacement(
        &self,
        id: ElementId,
        element: &dyn Element,
    ) -> Result<(), GraphError> {
        let n = self.graph.node(id);
        check_same_shape(&n.name, n.element.as_ref(), element)?;
        let causality: Vec<PortCausality> =
            self.layouts[id].ports.iter().map(|p| p.causality).collect();
        let err = |message: String, hint: Option<&str>| {
            Err(GraphError::Replacement {
                element: n.name.clone(),
                message,
                hint: hint.map(str::to_owned),
            })
        };
        if !element.causal_rule(causality.len()).admits(&causality) {
            return err(
                format!(
                    "the new {} does not accept the causality assigned to it ({causality:?})",
                    element.kind()
                ),
                Some("a resistance switched to 0 cannot stay in conductance causality, use a small value instead"),
            );
        }
        if element.stages(&causality) != n.element.stages(&causality) {
            return err("the new element computes in different stages".into(), None);
        }
        Ok(())
    }
}
