//! Causality assignment: the sequential causality assignment procedure (SCAP; Karnopp,
//! Margolis & Rosenberg, *System Dynamics*, ch. 5), generalised to multiport fields.
//!
//! 1. Elements with fixed causality (sources, one-way MTFs) are assigned, and each choice is
//!    propagated through junctions, TF, GY and MTF as far as it forces other bonds.
//! 2. Storage elements are given integral causality one by one, each propagated. A storage
//!    that propagation has already forced the other way is in *derivative causality*: refused.
//! 3. Resistive elements take their first admissible causality, propagated.
//! 4. Bonds still open (junction-only structures) are oriented arbitrarily, propagated.
//!
//! Every decision remembers which element made it and which bond triggered it, so that an
//! error can name the chain of elements that led to the conflict.

use std::collections::VecDeque;

use crate::bond::{BondId, ElementId, PortCausality};
use crate::element::CausalRule;
use crate::error::CausalityError;
use crate::graph::BondGraph;

/// A bond graph with a causal stroke on every bond.
#[derive(Debug)]
pub struct CausalGraph {
    /// The graph (validated, with dimensions inferred).
    pub graph: BondGraph,
    /// For each bond, the element that sets its effort (the stroke is at the other end).
    pub effort_setter: Vec<ElementId>,
}

impl CausalGraph {
    /// Causality of port `port` of element `id`.
    #[must_use]
    pub fn port_causality(&self, id: ElementId, port: usize) -> PortCausality {
        let b = self.graph.ports_of(id)[port].unwrap_or(0);
        if self.effort_setter[b] == id {
            PortCausality::EffortOut
        } else {
            PortCausality::FlowOut
        }
    }

    /// Causality of every port of element `id`.
    #[must_use]
    pub fn element_causality(&self, id: ElementId) -> Vec<PortCausality> {
        (0..self.graph.ports_of(id).len())
            .map(|p| self.port_causality(id, p))
            .collect()
    }

    /// A one-line drawing of bond `b`: `from ⇀| to` style in ASCII, e.g. `se --|> j1`
    /// (`|` marks the causal stroke, the end that receives the effort).
    #[must_use]
    pub fn describe_bond(&self, b: BondId) -> String {
        let bond = self.graph.bond(b);
        let from = &self.graph.node(bond.from.element).name;
        let to = &self.graph.node(bond.to.element).name;
        let dim = if bond.dim > 1 {
            format!(" [dim {}]", bond.dim)
        } else {
            String::new()
        };
        if self.effort_setter[b] == bond.from.element {
            format!(
                "{}: {from} ---|> {to}{dim}   (effort {from} -> {to}, flow {to} -> {from})",
                bond.name
            )
        } else {
            format!(
                "{}: {from} |---> {to}{dim}   (effort {to} -> {from}, flow {from} -> {to})",
                bond.name
            )
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Decision {
    setter: ElementId,
    by: ElementId,
    cause: Option<BondId>,
}

struct Scap<'g> {
    g: &'g BondGraph,
    rules: Vec<CausalRule>,
    decided: Vec<Option<Decision>>,
    queue: VecDeque<(ElementId, Option<BondId>)>,
}

enum Failure {
    /// Element `at`'s rule cannot be met on bond `bond`.
    Conflict { at: ElementId, bond: BondId },
}

/// Assign a causal stroke to every bond of `graph`.
///
/// # Returns
/// The [`CausalGraph`], or the first conflict: derivative causality on a storage element, or
/// two elements imposing the same variable, naming the elements and bonds involved.
///
/// # Complexity
/// O(B·P) for B bonds and P the largest number of ports on one element.
pub fn assign_causality(mut graph: BondGraph) -> Result<CausalGraph, crate::Error> {
    graph.validate()?;
    let setter = {
        let rules = (0..graph.n_elements())
            .map(|id| graph.node(id).element.causal_rule(graph.ports_of(id).len()))
            .collect();
        let mut s = Scap {
            g: &graph,
            rules,
            decided: vec![None; graph.n_bonds()],
            queue: VecDeque::new(),
        };
        s.run()?;
        s.decided
            .iter()
            .map(|d| d.map_or(0, |d| d.setter))
            .collect()
    };
    Ok(CausalGraph {
        graph,
        effort_setter: setter,
    })
}

impl Scap<'_> {
    fn run(&mut self) -> Result<(), CausalityError> {
        let n = self.g.n_elements();
        // 1. fixed causality
        for id in 0..n {
            if matches!(self.rules[id], CausalRule::Fixed(_)) {
                self.apply_and_propagate(id, None)?;
            }
        }
        // 2. storage in integral causality
        for id in 0..n {
            if matches!(self.rules[id], CausalRule::Integral(_)) && self.open_ports(id) > 0 {
                self.apply_and_propagate(id, None)?;
            }
        }
        // 3. resistive: first admissible pattern
        for id in 0..n {
            if let CausalRule::Resistive(patterns) = &self.rules[id] {
                if self.open_ports(id) == 0 {
                    continue;
                }
                let current = self.current(id);
                let choice = patterns.iter().find(|p| consistent(p, &current)).cloned();
                match choice {
                    Some(p) => {
                        self.assign_pattern(id, &p, None)?;
                        self.propagate()?;
                    }
                    None => {
                        let bond = self
                            .g
                            .ports_of(id)
                            .iter()
                            .flatten()
                            .copied()
                            .next()
                            .unwrap_or(0);
                        return Err(self.explain(Failure::Conflict { at: id, bond }));
                    }
                }
            }
        }
        // 4. anything left: orient arbitrarily
        for b in 0..self.g.n_bonds() {
            if self.decided[b].is_none() {
                let from = self.g.bond(b).from.element;
                self.decide(b, from, from, None)?;
                // `from`'s own rule must see the choice too, not only the other end's.
                self.queue.push_front((from, Some(b)));
                self.propagate()?;
            }
        }
        Ok(())
    }

    fn open_ports(&self, id: ElementId) -> usize {
        self.g
            .ports_of(id)
            .iter()
            .flatten()
            .filter(|&&b| self.decided[b].is_none())
            .count()
    }

    fn current(&self, id: ElementId) -> Vec<Option<PortCausality>> {
        self.g
            .ports_of(id)
            .iter()
            .map(|b| {
                b.and_then(|b| self.decided[b]).map(|d| {
                    if d.setter == id {
                        PortCausality::EffortOut
                    } else {
                        PortCausality::FlowOut
                    }
                })
            })
            .collect()
    }

    fn decide(
        &mut self,
        bond: BondId,
        setter: ElementId,
        by: ElementId,
        cause: Option<BondId>,
    ) -> Result<(), CausalityError> {
        match self.decided[bond] {
            Some(d) if d.setter != setter => Err(self.explain(Failure::Conflict { at: by, bond })),
            Some(_) => Ok(()),
            None => {
                self.decided[bond] = Some(Decision { setter, by, cause });
                let b = self.g.bond(bond);
                for end in [b.from.element, b.to.element] {
                    if end != by {
                        self.queue.push_back((end, Some(bond)));
                    }
                }
                Ok(())
            }
        }
    }

    fn assign_pattern(
        &mut self,
        id: ElementId,
        pattern: &[PortCausality],
        cause: Option<BondId>,
    ) -> Result<(), CausalityError> {
        for (port, &c) in pattern.iter().enumerate() {
            let Some(b) = self.g.ports_of(id)[port] else {
                continue;
            };
            let setter = if c == PortCausality::EffortOut {
                id
            } else {
                self.other_end(b, id)
            };
            self.decide(b, setter, id, cause)?;
        }
        Ok(())
    }

    fn other_end(&self, b: BondId, id: ElementId) -> ElementId {
        let bond = self.g.bond(b);
        if bond.from.element == id {
            bond.to.element
        } else {
            bond.from.element
        }
    }

    fn apply_and_propagate(
        &mut self,
        id: ElementId,
        cause: Option<BondId>,
    ) -> Result<(), CausalityError> {
        self.apply(id, cause)?;
        self.propagate()
    }

    fn propagate(&mut self) -> Result<(), CausalityError> {
        while let Some((id, cause)) = self.queue.pop_front() {
            self.apply(id, cause)?;
        }
        Ok(())
    }

    /// Apply element `id`'s rule to what is decided, deciding whatever it forces.
    fn apply(&mut self, id: ElementId, cause: Option<BondId>) -> Result<(), CausalityError> {
        let current = self.current(id);
        let ports: Vec<Option<BondId>> = self.g.ports_of(id).to_vec();
        let conflict = |this: &Self| {
            this.explain(Failure::Conflict {
                at: id,
                bond: cause
                    .or_else(|| ports.iter().flatten().copied().next())
                    .unwrap_or(0),
            })
        };
        match self.rules[id].clone() {
            CausalRule::None => Ok(()),
            CausalRule::Fixed(p) | CausalRule::Integral(p) => {
                if !consistent(&p, &current) {
                    return Err(conflict(self));
                }
                self.assign_pattern(id, &p, cause)
            }
            CausalRule::Resistive(patterns) => {
                let ok: Vec<&Vec<PortCausality>> = patterns
                    .iter()
                    .filter(|p| consistent(p, &current))
                    .collect();
                if ok.is_empty() {
                    return Err(conflict(self));
                }
                for (port, c) in current.iter().enumerate() {
                    if c.is_none() && ok.iter().all(|p| p[port] == ok[0][port]) {
                        let mut forced = vec![None; current.len()];
                        forced[port] = Some(ok[0][port]);
                        self.assign_partial(id, &forced, cause)?;
                    }
                }
                Ok(())
            }
            CausalRule::ExactlyOne(c) => {
                let with_c = current.iter().filter(|&&x| x == Some(c)).count();
                let open = current.iter().filter(|x| x.is_none()).count();
                if with_c > 1 || (with_c == 0 && open == 0) {
                    return Err(conflict(self));
                }
                let fill = if with_c == 1 {
                    Some(c.opposite())
                } else if open == 1 {
                    Some(c)
                } else {
                    None
                };
                if let Some(f) = fill {
                    let forced: Vec<Option<PortCausality>> = current
                        .iter()
                        .map(|x| if x.is_none() { Some(f) } else { None })
                        .collect();
                    self.assign_partial(id, &forced, cause)?;
                }
                Ok(())
            }
            CausalRule::AllEqual => {
                let known: Vec<PortCausality> = current.iter().flatten().copied().collect();
                if let Some(&first) = known.first() {
                    if known.iter().any(|&k| k != first) {
                        return Err(conflict(self));
                    }
                    let forced: Vec<Option<PortCausality>> = current
                        .iter()
                        .map(|x| if x.is_none() { Some(first) } else { None })
                        .collect();
                    self.assign_partial(id, &forced, cause)?;
                }
                Ok(())
            }
        }
    }

    fn assign_partial(
        &mut self,
        id: ElementId,
        forced: &[Option<PortCausality>],
        cause: Option<BondId>,
    ) -> Result<(), CausalityError> {
        for (port, c) in forced.iter().enumerate() {
            let (Some(c), Some(b)) = (c, self.g.ports_of(id)[port]) else {
                continue;
            };
            let setter = if *c == PortCausality::EffortOut {
                id
            } else {
                self.other_end(b, id)
            };
            self.decide(b, setter, id, cause)?;
        }
        Ok(())
    }

    /// Turn a failure into an error naming the chain of decisions that led to it.
    fn explain(&self, failure: Failure) -> CausalityError {
        let Failure::Conflict { at, bond } = failure;
        let node = self.g.node(at);
        let bond_name = self.g.bond(bond).name.clone();
        // Walk back from the bond to the element whose own rule started the chain.
        let mut chain = Vec::new();
        let mut next = self.decided[bond];
        let mut origin = None;
        let mut guard = 0;
        while let Some(d) = next {
            let by = self.g.node(d.by);
            let b = d.cause.map_or_else(String::new, |c| {
                format!(" (because of {})", self.g.bond(c).name)
            });
            chain.push(format!("{} ({}){b}", by.name, by.element.kind()));
            origin = Some(d.by);
            next = d.cause.and_then(|c| self.decided[c]);
            guard += 1;
            if guard > self.g.n_bonds() {
                break;
            }
        }
        let chain = if chain.is_empty() {
            "no other element decided it".to_owned()
        } else {
            format!("its causality was set by {}", chain.join(" <- "))
        };
        let origin_name = origin.map_or_else(
            || "the rest of the graph".to_owned(),
            |o| format!("`{}`", self.g.node(o).name),
        );
        let origin_kind = origin.map(|o| self.rules[o].clone());
        match &self.rules[at] {
            CausalRule::Integral(p) => {
                let hint = match (p.first(), origin_kind) {
                    (Some(PortCausality::FlowOut), Some(CausalRule::Integral(_))) => format!(
                        "`{}` and {origin_name} are rigidly coupled inertias: add a compliance (C) between them, or merge them into one inertia",
                        node.name
                    ),
                    (Some(PortCausality::FlowOut), _) => format!(
                        "`{}` has its velocity imposed by {origin_name}: add a compliance (C) between them, or remove the inertia",
                        node.name
                    ),
                    (_, Some(CausalRule::Integral(_))) => format!(
                        "`{}` and {origin_name} are compliances in parallel: add a resistance (R) or an inertia (I) between them, or merge them",
                        node.name
                    ),
                    _ => format!(
                        "`{}` has its effort imposed by {origin_name}: add a resistance (R) or an inertia (I) between them",
                        node.name
                    ),
                };
                CausalityError::Derivative { element: node.name.clone(), kind: node.element.kind().to_owned(), bond: bond_name, chain, hint }
            }
            _ => CausalityError::Conflict {
                element: node.name.clone(),
                kind: node.element.kind().to_owned(),
                bond: bond_name,
                chain,
                hint: format!(
                    "two elements impose the same variable at `{}` (e.g. two effort sources on one 0-junction, two flow sources on one 1-junction): remove one or put an R, C or I between them",
                    node.name
                ),
            },
        }
    }
}

fn consistent(pattern: &[PortCausality], current: &[Option<PortCausality>]) -> bool {
    pattern.len() == current.len()
        && pattern
            .iter()
            .zip(current)
            .all(|(p, c)| c.is_none_or(|c| c == *p))
}
