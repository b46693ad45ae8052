//! [`StateEquations`]: the evaluation plan computing dx/dt = f(t, x) from a [`CausalGraph`].
//!
//! Every element splits its work into stages ([`Stage`](crate::Stage)); a stage writes some variables
//! (efforts, flows, signals) from others. The stages are ordered topologically over their
//! data dependencies (petgraph's `toposort`); a cycle is an algebraic loop, reported with the
//! elements and bonds on it. Evaluating the plan fills every effort, flow and signal; then
//! each storage element and signal block writes its state derivatives.

use std::cell::RefCell;
use std::collections::HashMap;

use petgraph::algo::{tarjan_scc, toposort};
use petgraph::graph::DiGraph;

use crate::bond::{BondId, ElementId, PortCausality};
use crate::causality::CausalGraph;
use crate::element::{Element, Io, Layout, PortLayout, Ports, Slot, Source};
use crate::error::{CausalityError, GraphError};
use crate::graph::{check_same_shape, BondGraph};

mod inputs;
mod lengths;
pub use lengths::{LengthMismatch, LENGTH_TOLERANCE_ABS, LENGTH_TOLERANCE_REL};
mod jacobian;

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

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Var {
    Effort(BondId),
    Flow(BondId),
    Signal(ElementId, usize),
}

impl StateEquations {
    /// Build the evaluation plan.
    ///
    /// # Returns
    /// The equations, or an error: a signal that does not resolve, an element whose stages
    /// break its contract, or an algebraic loop (naming its elements and bonds).
    ///
    /// # Complexity
    /// O(S + D) for S stages and D data dependencies.
    pub fn new(causal: CausalGraph) -> Result<Self, crate::Error> {
        let CausalGraph {
            graph,
            effort_setter,
        } = causal;
        let n_el = graph.n_elements();
        // Bond storage.
        let mut bond_offset = Vec::with_capacity(graph.n_bonds());
        let mut n_bond_values = 0;
        for b in graph.bonds() {
            bond_offset.push(n_bond_values);
            n_bond_values += b.dim;
        }
        // States and signal outputs.
        let mut states = Vec::new();
        let mut signal_names = Vec::new();
        let mut n_signals = 0;
        let mut layouts = Vec::with_capacity(n_el);
        for id in 0..n_el {
            let node = graph.node(id);
            let specs = node.element.states();
            let mut layout = Layout {
                state_offset: states.len(),
                n_states: specs.len(),
                ..Layout::default()
            };
            for s in specs {
                states.push(StateInfo {
                    name: format!("{}.{}", node.name, s.name),
                    element: id,
                    initial: s.initial,
                    nominal: s.nominal,
                });
            }
            for s in node.element.signal_outputs() {
                layout.outputs.push((n_signals, s.dim));
                // an input publishes its one signal under its bare name (`F`)
                let name = if node.element.as_input().is_some() {
                    node.name.clone()
                } else {
                    format!("{}.{}", node.name, s.name)
                };
                signal_names.push((name, n_signals, s.dim));
                n_signals += s.dim;
            }
            for (port, b) in graph.ports_of(id).iter().enumerate() {
                let b = b.unwrap_or(0);
                let bond = graph.bond(b);
                let sign = if bond.to.element == id && bond.to.port == port {
                    1.0
                } else {
                    -1.0
                };
                let causality = if effort_setter[b] == id {
                    PortCausality::EffortOut
                } else {
                    PortCausality::FlowOut
                };
                layout.ports.push(PortLayout {
                    offset: bond_offset[b],
                    dim: bond.dim,
                    sign,
                    causality,
                });
            }
            layouts.push(layout);
        }
        let mut eqs = Self {
            graph,
            effort_setter,
            layouts,
            order: Vec::new(),
            rhs_order: Vec::new(),
            writes: Vec::new(),
            states,
            bond_offset,
            n_bond_values,
            signal_names,
            ws: RefCell::new(Workspace::default()),
            jac: RefCell::new(jacobian::JacobianState::default()),
            inputs: Vec::new(),
            stop_at_breakpoints: true,
        };
        eqs.inputs = (0..n_el)
            .filter(|&id| eqs.graph.node(id).element.as_input().is_some())
            .collect();
        eqs.resolve_inputs()?;
        eqs.plan()?;
        *eqs.ws.borrow_mut() = Workspace {
            effort: vec![0.0; n_bond_values],
            flow: vec![0.0; n_bond_values],
            signals: vec![0.0; n_signals],
            dx: vec![0.0; eqs.states.len()],
        };
        Ok(eqs)
    }

    fn resolve_inputs(&mut self) -> Result<(), GraphError> {
        for id in 0..self.graph.n_elements() {
            let inputs = self.graph.node(id).element.signal_inputs();
            let mut resolved = Vec::with_capacity(inputs.len());
            for spec in inputs {
                let (src, dim) =
                    self.resolve(&spec.name)
                        .ok_or_else(|| GraphError::UnknownSignal {
                            element: self.graph.node(id).name.clone(),
                            signal: spec.name.clone(),
                            hint: self.suggest(&spec.name),
                        })?;
                if dim != spec.dim {
                    return Err(GraphError::SignalDimension {
                        element: self.graph.node(id).name.clone(),
                        signal: spec.name,
                        expected: spec.dim,
                        found: dim,
                    });
                }
                resolved.push((src, dim));
            }
            self.layouts[id].inputs = resolved;
        }
        Ok(())
    }

    /// Resolve a signal name: `t`, `<element>.<state>`, `<element>.<signal>`,
    /// `<element>.e` / `.f` (one-port), `<element>.<port>.e` / `.f`, `<bond>.e` / `.f`.
    fn resolve(&self, name: &str) -> Option<(Source, usize)> {
        if name == "t" || name == "time" {
            return Some((Source::Time, 1));
        }
        if let Some(i) = self.states.iter().position(|s| s.name == name) {
            return Some((Source::State(i), 1));
        }
        // A vector state `x.q` names all components `x.q[0]..`.
        let comps: Vec<usize> = (0..self.states.len())
            .filter(|&i| self.states[i].name.starts_with(&format!("{name}[")))
            .collect();
        if !comps.is_empty() && comps.windows(2).all(|w| w[1] == w[0] + 1) {
            return Some((Source::State(comps[0]), comps.len()));
        }
        if let Some((_, off, dim)) = self.signal_names.iter().find(|(n, _, _)| n == name) {
            return Some((Source::Signal(*off), *dim));
        }
        let (head, var) = name.rsplit_once('.')?;
        let bond = self.bond_of(head)?;
        let (off, dim) = (self.bond_offset[bond], self.graph.bond(bond).dim);
        match var {
            "e" => Some((Source::Effort(off), dim)),
            "f" => Some((Source::Flow(off), dim)),
            _ => None,
        }
    }

    /// The bond named `head`: a bond name, a one-port element, or `<element>.<port>`.
    fn bond_of(&self, head: &str) -> Option<BondId> {
        if let Some(b) = self.graph.bonds().position(|b| b.name == head) {
            return Some(b);
        }
        if let Some(id) = self.graph.find(head) {
            let ports = self.graph.ports_of(id);
            return if ports.len() == 1 { ports[0] } else { None };
        }
        let (el, port) = head.rsplit_once('.')?;
        let id = self.graph.find(el)?;
        let p = match self.graph.node(id).element.ports() {
            Ports::Fixed(_) => self.graph.port_index(id, port).ok()?,
            Ports::Any => port.parse().ok()?,
        };
        *self.graph.ports_of(id).get(p)?
    }

    fn suggest(&self, name: &str) -> String {
        let el = name.split('.').next().unwrap_or(name);
        let mut names: Vec<String> = self
            .probe_names()
            .into_iter()
            .filter(|n| n.starts_with(&format!("{el}.")))
            .collect();
        names.truncate(12);
        if names.is_empty() {
            format!("no element `{el}`; signals are written `<element>.<state or signal>`, `<element>.e`, `<element>.f` or `t`")
        } else {
            format!("`{el}` offers: {}", names.join(", "))
        }
    }

    fn var_of(&self, id: ElementId, slot: Slot) -> Option<Var> {
        let bond = |p: usize| self.graph.ports_of(id).get(p).copied().flatten();
        match slot {
            Slot::Effort(p) => bond(p).map(Var::Effort),
            Slot::Flow(p) => bond(p).map(Var::Flow),
            Slot::Output(i) => Some(Var::Signal(id, i)),
            Slot::Input(i) => match self.layouts[id].inputs.get(i)?.0 {
                Source::Time | Source::State(_) => None,
                Source::Effort(o) => self
                    .bond_offset
                    .iter()
                    .rposition(|&b| b <= o)
                    .map(Var::Effort),
                Source::Flow(o) => self
                    .bond_offset
                    .iter()
                    .rposition(|&b| b <= o)
                    .map(Var::Flow),
                Source::Signal(o) => self.signal_owner(o),
            },
        }
    }

    fn signal_owner(&self, offset: usize) -> Option<Var> {
        self.layouts.iter().enumerate().find_map(|(id, l)| {
            l.outputs
                .iter()
                .position(|&(o, d)| offset >= o && offset < o + d)
                .map(|i| Var::Signal(id, i))
        })
    }

    fn plan(&mut self) -> Result<(), crate::Error> {
        let n_el = self.graph.n_elements();
        let mut dep: DiGraph<(ElementId, usize), ()> = DiGraph::new();
        let mut writer: HashMap<Var, petgraph::graph::NodeIndex> = HashMap::new();
        let mut reads: Vec<(petgraph::graph::NodeIndex, Vec<Var>)> = Vec::new();
        self.writes = Vec::with_capacity(n_el);
        for id in 0..n_el {
            let node = self.graph.node(id);
            let causality: Vec<PortCausality> =
                self.layouts[id].ports.iter().map(|p| p.causality).collect();
            let stages = node.element.stages(&causality);
            let contract = |message: String| GraphError::Contract {
                element: node.name.clone(),
                kind: node.element.kind().to_owned(),
                message,
            };
            let mut el_writes = Vec::with_capacity(stages.len());
            for (s, stage) in stages.iter().enumerate() {
                let ix = dep.add_node((id, s));
                let mut w = Vec::new();
                for &slot in &stage.writes {
                    let ok = match slot {
                        Slot::Effort(p) => causality.get(p) == Some(&PortCausality::EffortOut),
                        Slot::Flow(p) => causality.get(p) == Some(&PortCausality::FlowOut),
                        Slot::Output(i) => i < self.layouts[id].outputs.len(),
                        Slot::Input(_) => false,
                    };
                    let var = self.var_of(id, slot).filter(|_| ok).ok_or_else(|| {
                        contract(format!(
                            "stage {s} writes {slot:?}, which its causality does not allow"
                        ))
                    })?;
                    if writer.insert(var, ix).is_some() {
                        return Err(contract(format!("{slot:?} is written by two stages")).into());
                    }
                    w.push(var);
                }
                let r: Vec<Var> = stage
                    .reads
                    .iter()
                    .filter_map(|&slot| self.var_of(id, slot))
                    .collect();
                reads.push((ix, r));
                el_writes.push(w);
            }
            self.writes.push(el_writes);
        }
        // Every variable must have exactly one writer.
        for (b, bond) in self.graph.bonds().enumerate() {
            for var in [Var::Effort(b), Var::Flow(b)] {
                if !writer.contains_key(&var) {
                    let setter = if matches!(var, Var::Effort(_)) {
                        self.effort_setter[b]
                    } else if self.effort_setter[b] == bond.from.element {
                        bond.to.element
                    } else {
                        bond.from.element
                    };
                    let n = self.graph.node(setter);
                    return Err(GraphError::Contract {
                        element: n.name.clone(),
                        kind: n.element.kind().to_owned(),
                        message: format!(
                            "no stage computes the {} of bond {}",
                            if matches!(var, Var::Effort(_)) {
                                "effort"
                            } else {
                                "flow"
                            },
                            bond.name
                        ),
                    }
                    .into());
                }
            }
        }
        for (id, l) in self.layouts.iter().enumerate() {
            for i in 0..l.outputs.len() {
                if !writer.contains_key(&Var::Signal(id, i)) {
                    let n = self.graph.node(id);
                    return Err(GraphError::Contract {
                        element: n.name.clone(),
                        kind: n.element.kind().to_owned(),
                        message: format!("no stage computes signal output {i}"),
                    }
                    .into());
                }
            }
        }
        for (ix, r) in &reads {
            for var in r {
                if let Some(&w) = writer.get(var) {
                    dep.add_edge(w, *ix, ());
                }
            }
        }
        match toposort(&dep, None) {
            Ok(order) => {
                self.order = order.into_iter().map(|ix| dep[ix]).collect();
                self.rhs_order = self.rhs_stages();
                Ok(())
            }
            Err(_) => Err(self.loop_error(&dep, &reads, &writer).into()),
        }
    }

    /// `order` without the stages whose results dx/dt does not need: a stage that writes only
    /// signals (reaction forces, energy reports) is skipped by `rhs` unless an element that
    /// takes part in dx/dt reads one of them — an element with states (its derivatives may
    /// read any input) or one with a stage that is not skipped. Found as a fixed point, so a
    /// signal read only by skipped stages (the accelerations the reaction forces read) is
    /// skipped too.
    fn rhs_stages(&self) -> Vec<(ElementId, usize)> {
        let signals_only = |id: ElementId, s: usize| {
            let w = &self.writes[id][s];
            !w.is_empty() && w.iter().all(|v| matches!(v, Var::Signal(..)))
        };
        let mut skipped: std::collections::HashSet<(ElementId, usize)> = self
            .order
            .iter()
            .copied()
            .filter(|&(id, s)| signals_only(id, s))
            .collect();
        loop {
            let needed: std::collections::HashSet<usize> = self
                .layouts
                .iter()
                .enumerate()
                .filter(|&(id, l)| {
                    l.n_states > 0
                        || (0..self.writes[id].len()).any(|s| !skipped.contains(&(id, s)))
                })
                .flat_map(|(_, l)| l.inputs.iter())
                .filter_map(|&(src, dim)| match src {
                    Source::Signal(o) => Some(o..o + dim),
                    _ => None,
                })
                .flatten()
                .collect();
            let before = skipped.len();
            skipped.retain(|&(id, s)| {
                self.writes[id][s].iter().all(|v| match *v {
                    Var::Signal(e, i) => {
                        let (o, d) = self.layouts[e].outputs[i];
                        !(o..o + d).any(|k| needed.contains(&k))
                    }
                    _ => false,
                })
            });
            if skipped.len() == before {
                break;
            }
        }
        self.order
            .iter()
            .copied()
            .filter(|st| !skipped.contains(st))
            .collect()
    }

    fn loop_error(
        &self,
        dep: &DiGraph<(ElementId, usize), ()>,
        reads: &[(petgraph::graph::NodeIndex, Vec<Var>)],
        writer: &HashMap<Var, petgraph::graph::NodeIndex>,
    ) -> CausalityError {
        let scc = tarjan_scc(dep)
            .into_iter()
            .find(|c| c.len() > 1 || dep.contains_edge(c[0], c[0]))
            .unwrap_or_default();
        let mut elements: Vec<String> = Vec::new();
        let mut bonds: Vec<String> = Vec::new();
        for &ix in &scc {
            let name = self.graph.node(dep[ix].0).name.clone();
            if !elements.contains(&name) {
                elements.push(name);
            }
            if let Some((_, r)) = reads.iter().find(|(i, _)| *i == ix) {
                for var in r {
                    if let (Var::Effort(b) | Var::Flow(b), Some(w)) = (var, writer.get(var)) {
                        let name = self.graph.bond(*b).name.clone();
                        if scc.contains(w) && !bonds.contains(&name) {
                            bonds.push(name);
                        }
                    }
                }
            }
        }
        CausalityError::AlgebraicLoop {
            elements,
            bonds,
            hint: "resistive elements form a loop that needs an implicit solve: add a small inertia (I) or compliance (C) in the loop, or merge the resistors into one".into(),
        }
    }

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

    /// dx/dt = f(t, x).
    pub fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            effort,
            flow,
            signals,
            ..
        } = &mut *ws;
        self.eval_into(&self.rhs_order, t, x, effort, flow, signals, dx);
    }

    #[allow(clippy::too_many_arguments)]
    fn eval_into(
        &self,
        order: &[(ElementId, usize)],
        t: f64,
        x: &[f64],
        effort: &mut [f64],
        flow: &mut [f64],
        signals: &mut [f64],
        dx: &mut [f64],
    ) {
        for &(id, stage) in order {
            let mut io = Io {
                t,
                x,
                effort,
                flow,
                signals,
                layout: &self.layouts[id],
            };
            self.graph.node(id).element.eval(stage, &mut io);
        }
        for (id, l) in self.layouts.iter().enumerate() {
            if l.n_states > 0 {
                let io = Io {
                    t,
                    x,
                    effort,
                    flow,
                    signals,
                    layout: l,
                };
                self.graph
                    .node(id)
                    .element
                    .derivatives(&io, &mut dx[l.state_offset..l.state_offset + l.n_states]);
            }
        }
    }

    /// Evaluate everything at (t, x) and keep it for [`read`](Self::read).
    pub fn evaluate(&self, t: f64, x: &[f64]) {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            effort,
            flow,
            signals,
            dx,
        } = &mut *ws;
        self.eval_into(&self.order, t, x, effort, flow, signals, dx);
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

    /// Every name [`probe`](Self::probe) accepts.
    #[must_use]
    pub fn probe_names(&self) -> Vec<String> {
        let mut names = vec!["t".to_owned()];
        names.extend(self.states.iter().map(|s| s.name.clone()));
        names.extend(self.states.iter().map(|s| format!("{}.dot", s.name)));
        for (n, _, d) in &self.signal_names {
            if *d == 1 {
                names.push(n.clone());
            } else {
                names.extend((0..*d).map(|k| format!("{n}[{k}]")));
            }
        }
        for id in 0..self.graph.n_elements() {
            let node = self.graph.node(id);
            let ports = self.graph.ports_of(id);
            for p in 0..ports.len() {
                let head = if ports.len() == 1 {
                    node.name.clone()
                } else {
                    format!("{}.{}", node.name, self.graph.port_name(id, p))
                };
                names.extend(["e", "f", "P"].iter().map(|v| format!("{head}.{v}")));
            }
        }
        for b in self.graph.bonds() {
            names.extend(["e", "f", "P"].iter().map(|v| format!("{}.{v}", b.name)));
        }
        names
    }

    /// Resolve an output name: `t`, a state (`mass.p`), its derivative (`mass.p.dot`), a
    /// signal (`ctrl.out`), or a bond variable `.e`, `.f`, `.P` (power) named by bond
    /// (`b3.e`), one-port element (`mass.f`) or element port (`lever.2.e`). Vector variables
    /// take a component index: `arm.q[1]`, `b4.e[2]`.
    #[must_use]
    pub fn probe(&self, name: &str) -> Option<Probe> {
        if name == "t" || name == "time" {
            return Some(Probe::Time);
        }
        if let Some(i) = self.states.iter().position(|s| s.name == name) {
            return Some(Probe::State(i));
        }
        if let Some(base) = name.strip_suffix(".dot") {
            if let Some(i) = self.states.iter().position(|s| s.name == base) {
                return Some(Probe::Derivative(i));
            }
        }
        let (base, k) = split_index(name);
        if let Some((_, off, dim)) = self.signal_names.iter().find(|(n, _, _)| n == base) {
            return (k < *dim).then_some(Probe::Signal(off + k));
        }
        let (head, var) = base.rsplit_once('.')?;
        let b = self.bond_of(head)?;
        let (off, dim) = (self.bond_offset[b], self.graph.bond(b).dim);
        match var {
            "e" if k < dim => Some(Probe::Effort(off + k)),
            "f" if k < dim => Some(Probe::Flow(off + k)),
            "P" => Some(Probe::Power(b)),
            _ => None,
        }
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

fn split_index(name: &str) -> (&str, usize) {
    if let Some(stripped) = name.strip_suffix(']') {
        if let Some((base, idx)) = stripped.rsplit_once('[') {
            if let Ok(k) = idx.parse() {
                return (base, k);
            }
        }
    }
    (name, 0)
}
