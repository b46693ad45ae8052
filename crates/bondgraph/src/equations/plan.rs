//! Building the evaluation plan: storage for every bond and signal, the stages each element
//! computes, ordered topologically over their data dependencies (a cycle is an algebraic
//! loop, reported with its elements and bonds).

use std::cell::RefCell;
use std::collections::HashMap;

use petgraph::algo::{tarjan_scc, toposort};
use petgraph::graph::DiGraph;

use super::{StateEquations, StateInfo, Var, Workspace};
use crate::bond::{ElementId, PortCausality};
use crate::causality::CausalGraph;
use crate::element::{Layout, PortLayout, Slot, Source};
use crate::error::{CausalityError, GraphError};

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
            steps: Vec::new(),
            rhs_steps: Vec::new(),
            owners: Vec::new(),
            writes: Vec::new(),
            states,
            bond_offset,
            n_bond_values,
            signal_names,
            ws: RefCell::new(Workspace::default()),
            jac: RefCell::new(super::jacobian::JacobianState::default()),
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

    pub(super) fn var_of(&self, id: ElementId, slot: Slot) -> Option<Var> {
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

    pub(super) fn signal_owner(&self, offset: usize) -> Option<Var> {
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
                self.steps = self.steps_of(&self.order);
                self.rhs_steps = self.steps_of(&self.rhs_order);
                let owners = (0..n_el).filter(|&id| self.layouts[id].n_states > 0);
                self.owners = self.owners_of(owners);
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
}
