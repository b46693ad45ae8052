//! [`BondGraph`]: elements (nodes) and bonds (edges with a power direction) over a petgraph
//! `DiGraph`. Building the graph checks names and ports; [`BondGraph::validate`] checks that
//! every port is bonded and every dimension agrees.

use petgraph::graph::{DiGraph, EdgeIndex, NodeIndex};

use crate::bond::{Bond, BondId, ElementId, Endpoint};
use crate::element::{Element, Ports};
use crate::error::GraphError;

/// A named element in the graph.
#[derive(Debug)]
pub struct Node {
    /// Unique name.
    pub name: String,
    /// The element.
    pub element: Box<dyn Element>,
}

/// A bond graph: named elements connected by bonds.
#[derive(Debug, Default)]
pub struct BondGraph {
    pub(crate) graph: DiGraph<Node, Bond>,
    /// Bonds attached to each element, by port index (junction ports grow as bonds attach).
    pub(crate) ports: Vec<Vec<Option<BondId>>>,
    /// Element ids by name: looking a name up is O(1), so building a graph of n elements is
    /// linear in n (issue 37, item 8).
    names: std::collections::HashMap<String, ElementId>,
}

impl BondGraph {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Add an element under a unique `name`.
    pub fn add(
        &mut self,
        name: &str,
        element: impl Element + 'static,
    ) -> Result<ElementId, GraphError> {
        self.add_boxed(name, Box::new(element))
    }

    /// Add a boxed element under a unique `name`.
    pub fn add_boxed(
        &mut self,
        name: &str,
        element: Box<dyn Element>,
    ) -> Result<ElementId, GraphError> {
        if self.find(name).is_some() {
            return Err(GraphError::DuplicateName {
                name: name.to_owned(),
            });
        }
        let n_ports = match element.ports() {
            Ports::Fixed(p) => p.len(),
            Ports::Any => 0,
        };
        let id = self
            .graph
            .add_node(Node {
                name: name.to_owned(),
                element,
            })
            .index();
        self.ports.push(vec![None; n_ports]);
        self.names.insert(name.to_owned(), id);
        Ok(id)
    }

    /// The element called `name`.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<ElementId> {
        self.names.get(name).copied()
    }

    /// Element by id.
    #[must_use]
    pub fn node(&self, id: ElementId) -> &Node {
        &self.graph[NodeIndex::new(id)]
    }

    /// Number of elements.
    #[must_use]
    pub fn n_elements(&self) -> usize {
        self.graph.node_count()
    }

    /// Number of bonds.
    #[must_use]
    pub fn n_bonds(&self) -> usize {
        self.graph.edge_count()
    }

    /// Bond by id.
    #[must_use]
    pub fn bond(&self, id: BondId) -> &Bond {
        &self.graph[EdgeIndex::new(id)]
    }

    /// All bonds in id order.
    pub fn bonds(&self) -> impl Iterator<Item = &Bond> {
        self.graph.edge_weights()
    }

    /// Bonds of element `id`, by port.
    #[must_use]
    pub fn ports_of(&self, id: ElementId) -> &[Option<BondId>] {
        &self.ports[id]
    }

    /// Name of a port of an element (its spec name, or its index for junctions).
    #[must_use]
    pub fn port_name(&self, id: ElementId, port: usize) -> String {
        match self.node(id).element.ports() {
            Ports::Fixed(p) => p
                .get(port)
                .map_or_else(|| port.to_string(), |s| s.name.clone()),
            Ports::Any => port.to_string(),
        }
    }

    /// Index of the port called `port` on element `id`.
    pub fn port_index(&self, id: ElementId, port: &str) -> Result<usize, GraphError> {
        let node = self.node(id);
        match node.element.ports() {
            Ports::Fixed(p) => {
                p.iter()
                    .position(|s| s.name == port)
                    .ok_or_else(|| GraphError::NoSuchPort {
                        element: node.name.clone(),
                        kind: node.element.kind().to_owned(),
                        port: port.to_owned(),
                        available: if p.is_empty() {
                            "(none: it is a signal block)".into()
                        } else {
                            p.iter()
                                .map(|s| s.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        },
                    })
            }
            Ports::Any => Err(GraphError::NoSuchPort {
                element: node.name.clone(),
                kind: node.element.kind().to_owned(),
                port: port.to_owned(),
                available: "(junction ports are not named: bond to the junction itself)".into(),
            }),
        }
    }

    fn claim(
        &mut self,
        id: ElementId,
        port: Option<usize>,
        bond: BondId,
    ) -> Result<usize, GraphError> {
        let node = self.node(id);
        let (name, kind) = (node.name.clone(), node.element.kind().to_owned());
        let fixed = matches!(node.element.ports(), Ports::Fixed(_));
        let slots = &mut self.ports[id];
        let port = match (port, fixed) {
            (Some(p), true) => p,
            (None, true) => {
                slots
                    .iter()
                    .position(Option::is_none)
                    .ok_or(GraphError::NoFreePort {
                        element: name.clone(),
                        kind: kind.clone(),
                        n_ports: slots.len(),
                    })?
            }
            (_, false) => {
                slots.push(None);
                slots.len() - 1
            }
        };
        match slots.get_mut(port) {
            None => Err(GraphError::NoSuchPort {
                element: name,
                kind,
                port: port.to_string(),
                available: format!("0..{}", slots.len()),
            }),
            Some(Some(_)) => Err(GraphError::PortInUse {
                element: name,
                kind,
                port: self.port_name(id, port),
            }),
            Some(slot) => {
                *slot = Some(bond);
                Ok(port)
            }
        }
    }

    /// Connect `from` to `to` with a bond whose half-arrow points at `to`. `None` as a port
    /// takes the element's next free port (junctions always get a new one).
    pub fn connect(
        &mut self,
        from: (ElementId, Option<usize>),
        to: (ElementId, Option<usize>),
    ) -> Result<BondId, GraphError> {
        let id = self.graph.edge_count();
        let name = format!("b{}", id + 1);
        self.connect_named(&name, from, to)
    }

    /// [`connect`](Self::connect) with a bond name of your choice.
    pub fn connect_named(
        &mut self,
        name: &str,
        from: (ElementId, Option<usize>),
        to: (ElementId, Option<usize>),
    ) -> Result<BondId, GraphError> {
        let id = self.graph.edge_count();
        let before = (self.ports[from.0].clone(), self.ports[to.0].clone());
        let fp = self.claim(from.0, from.1, id)?;
        let tp = match self.claim(to.0, to.1, id) {
            Ok(p) => p,
            Err(e) => {
                self.ports[from.0] = before.0;
                return Err(e);
            }
        };
        let bond = Bond {
            name: name.to_owned(),
            from: Endpoint {
                element: from.0,
                port: fp,
            },
            to: Endpoint {
                element: to.0,
                port: tp,
            },
            dim: 0,
        };
        self.graph
            .add_edge(NodeIndex::new(from.0), NodeIndex::new(to.0), bond);
        Ok(id)
    }

    /// Connect by element names: `connect_names("src", "j")` is the model file's `"src -> j"`.
    pub fn connect_names(&mut self, from: &str, to: &str) -> Result<BondId, GraphError> {
        let f = self.find(from).ok_or_else(|| GraphError::UnknownElement {
            name: from.to_owned(),
        })?;
        let t = self.find(to).ok_or_else(|| GraphError::UnknownElement {
            name: to.to_owned(),
        })?;
        self.connect((f, None), (t, None))
    }

    /// Connect ends written as `element` or `element.port` (a model file's `"a.p -> b"`)
    /// with a bond called `name`.
    pub fn connect_ends(&mut self, name: &str, from: &str, to: &str) -> Result<BondId, GraphError> {
        let f = self.end(from)?;
        let t = self.end(to)?;
        self.connect_named(name, f, t)
    }

    /// An end `element` or `element.port` as (element id, port index).
    fn end(&self, s: &str) -> Result<(ElementId, Option<usize>), GraphError> {
        let (el, port) = s.split_once('.').map_or((s, None), |(e, p)| (e, Some(p)));
        let id = self.find(el).ok_or_else(|| GraphError::UnknownElement {
            name: el.to_owned(),
        })?;
        let port = port.map(|p| self.port_index(id, p)).transpose()?;
        Ok((id, port))
    }

    /// Replace element `id` by one of the same kind, ports and states (a parameter switch).
    pub fn replace(
        &mut self,
        id: ElementId,
        element: Box<dyn Element>,
    ) -> Result<Box<dyn Element>, GraphError> {
        let node = &mut self.graph[NodeIndex::new(id)];
        check_same_shape(&node.name, node.element.as_ref(), element.as_ref())?;
        Ok(std::mem::replace(&mut node.element, element))
    }

    /// Check every port is bonded and infer every bond's dimension.
    ///
    /// Dimensions come from fixed-dimension ports and spread through junctions and
    /// adaptive ports; a bond whose dimension nothing fixes is scalar.
    pub fn validate(&mut self) -> Result<(), GraphError> {
        for id in 0..self.n_elements() {
            let node = self.node(id);
            if matches!(node.element.ports(), Ports::Any) && self.ports[id].is_empty() {
                return Err(GraphError::EmptyJunction {
                    element: node.name.clone(),
                });
            }
            if let Some(p) = self.ports[id].iter().position(Option::is_none) {
                return Err(GraphError::Unconnected {
                    element: node.name.clone(),
                    kind: node.element.kind().to_owned(),
                    port: self.port_name(id, p),
                });
            }
        }
        self.infer_dims()
    }

    fn fixed_dim(&self, end: Endpoint) -> Option<usize> {
        match self.node(end.element).element.ports() {
            Ports::Fixed(p) => p.get(end.port).and_then(|s| s.dim),
            Ports::Any => None,
        }
    }

    fn infer_dims(&mut self) -> Result<(), GraphError> {
        let n = self.n_bonds();
        let mut dims: Vec<Option<usize>> = vec![None; n];
        for (b, dim) in dims.iter_mut().enumerate() {
            let bond = self.bond(b).clone();
            let (df, dt) = (self.fixed_dim(bond.from), self.fixed_dim(bond.to));
            match (df, dt) {
                (Some(a), Some(c)) if a != c => {
                    return Err(GraphError::DimensionMismatch {
                        element: self.node(bond.to.element).name.clone(),
                        message: format!(
                            "bond {} joins port `{}` of `{}` (dimension {a}) to port `{}` of `{}` (dimension {c})",
                            bond.name,
                            self.port_name(bond.from.element, bond.from.port),
                            self.node(bond.from.element).name,
                            self.port_name(bond.to.element, bond.to.port),
                            self.node(bond.to.element).name,
                        ),
                    });
                }
                (a, c) => *dim = a.or(c),
            }
        }
        // Spread through junctions and adaptive two-ports until nothing changes.
        loop {
            let mut changed = false;
            for id in 0..self.n_elements() {
                let adaptive: Vec<BondId> = match self.node(id).element.ports() {
                    Ports::Any => self.ports[id].iter().flatten().copied().collect(),
                    Ports::Fixed(p) => p
                        .iter()
                        .zip(&self.ports[id])
                        .filter(|(s, _)| s.dim.is_none())
                        .filter_map(|(_, b)| *b)
                        .collect(),
                };
                if adaptive.len() < 2 {
                    continue;
                }
                let mut known: Option<(usize, BondId)> = None;
                for &b in &adaptive {
                    if let Some(d) = dims[b] {
                        match known {
                            Some((k, kb)) if k != d => {
                                return Err(GraphError::DimensionMismatch {
                                    element: self.node(id).name.clone(),
                                    message: format!(
                                        "its bonds must share one dimension, but {} has {k} and {} has {d}",
                                        self.bond(kb).name,
                                        self.bond(b).name
                                    ),
                                });
                            }
                            _ => known = Some((d, b)),
                        }
                    }
                }
                if let Some((d, _)) = known {
                    for &b in &adaptive {
                        if dims[b].is_none() {
                            dims[b] = Some(d);
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
        for (b, d) in dims.into_iter().enumerate() {
            self.graph[EdgeIndex::new(b)].dim = d.unwrap_or(1);
        }
        Ok(())
    }
}

pub(crate) fn check_same_shape(
    name: &str,
    old: &dyn Element,
    new: &dyn Element,
) -> Result<(), GraphError> {
    let err = |message: String| {
        Err(GraphError::Replacement {
            element: name.to_owned(),
            message,
            hint: None,
        })
    };
    if old.kind() != new.kind() {
        return err(format!("kind {} differs from {}", new.kind(), old.kind()));
    }
    if old.ports() != new.ports() {
        return err("its ports differ".into());
    }
    if old.states().len() != new.states().len() {
        return err("its number of states differs".into());
    }
    if old.signal_inputs() != new.signal_inputs() || old.signal_outputs() != new.signal_outputs() {
        return err("its signals differ".into());
    }
    Ok(())
}
