//! Stage 4, wire: the bonds (a composite's internal ones, then `[bonds]`) into the
//! [`BondGraph`], the signals the elements read checked against it, then causality
//! ([`assign_causality`]). Each bond is wired on its own, so every bad bond is reported; a
//! bond to an entry that was not built is left out (that entry's problem is reported).

use std::ops::Range;

use bondgraph::{assign_causality, BondGraph, CausalGraph, CausalityError, GraphError};

use super::parse::{valid_name, Parsed};
use super::source::Source;
use crate::error::{clip, ErrorKind, ModelError};

/// An end of a bond: element and port (the first free one if `None`).
type End = (usize, Option<usize>);

/// The graph of `p`: every entry built ([`super::build`]) and every bond wired; problems go
/// to `p.problems`.
pub(super) fn build_graph(p: &mut Parsed) -> BondGraph {
    let mut g = BondGraph::new();
    let internal = super::build::build_elements(p, &mut g);
    for (i, (name, from, to)) in internal {
        if let Err(e) = internal_bond(&p.source, &mut g, i, &name, &from, &to) {
            p.problems.push(e);
        }
    }
    for (name, text) in &p.spec.bonds {
        let ends = text
            .get_ref()
            .split("->")
            .map(|s| s.trim().split('.').next().unwrap_or(""));
        if ends.into_iter().any(|el| p.failed.elements.contains(el)) {
            continue;
        }
        if let Err(e) = bond(
            &p.source,
            &mut g,
            name.get_ref(),
            text.get_ref(),
            text.span(),
        ) {
            p.problems.push(e);
        }
    }
    if p.problems.is_empty() {
        p.problems.extend(unknown_signals(&p.source, &g));
    }
    g
}

/// A bond inside composite entry `i`.
fn internal_bond(
    source: &Source,
    g: &mut BondGraph,
    i: usize,
    name: &str,
    from: &str,
    to: &str,
) -> Result<(), ModelError> {
    let def = &source.elements[i];
    let err = |m: String, hint: Option<String>| {
        source
            .err(
                ErrorKind::Graph,
                Some(&def.name_span),
                format!("inside {} `{}`: bond {name}: {m}", def.kind, def.name),
            )
            .or_hint(hint)
            .element(&def.name)
    };
    let end = |s: &str| -> Result<End, ModelError> {
        let (el, port) = s.split_once('.').map_or((s, None), |(e, p)| (e, Some(p)));
        let id = g
            .find(el)
            .ok_or_else(|| err(format!("no member `{el}`"), None))?;
        let port = port
            .map(|p| g.port_index(id, p))
            .transpose()
            .map_err(|e| err(e.message(), e.hint()).with_source(e))?;
        Ok((id, port))
    };
    let (f, t) = (end(from)?, end(to)?);
    g.connect_named(name, f, t)
        .map_err(|e| err(e.message(), e.hint()).with_source(e))?;
    Ok(())
}

/// A `[bonds]` entry: `name = "from -> to"`.
fn bond(
    src: &Source,
    g: &mut BondGraph,
    name: &str,
    text: &str,
    span: Range<usize>,
) -> Result<(), ModelError> {
    let err = |kind, m: String| src.err(kind, Some(&span), format!("bond `{name}`: {m}"));
    if !valid_name(name) {
        return Err(err(
            ErrorKind::Syntax,
            "bond names are letters, digits and _".into(),
        ));
    }
    let (a, b) = text.split_once("->").ok_or_else(|| {
        err(
            ErrorKind::Syntax,
            format!("`{}` is not of the form \"from -> to\"", clip(text)),
        )
        .hint("the arrow points in the direction of positive power: \"source -> junction\"")
    })?;
    let end = |s: &str| -> Result<End, ModelError> {
        let s = s.trim();
        let (mut el, mut port) = match s.split_once('.') {
            Some((e, p)) => (e, Some(p)),
            None => (s, None),
        };
        // A composite stands for the member port it exposes.
        let inner: String;
        if let Some(def) = src
            .entry_of(el)
            .filter(|d| d.name == el && !d.ports.is_empty())
        {
            let exposed: Vec<&str> = def.ports.iter().map(|(n, _)| n.as_str()).collect();
            let pick = match port {
                Some(p) => def.ports.iter().find(|(n, _)| n == p),
                None if def.ports.len() == 1 => def.ports.first(),
                None => None,
            };
            let (_, target) = pick.ok_or_else(|| {
                err(
                    ErrorKind::Graph,
                    format!("{} `{el}` has no port `{}`", def.kind, port.unwrap_or("")),
                )
                .element(el)
                .hint(format!(
                    "its ports are: {} (write `{el}.<port>`)",
                    exposed.join(", ")
                ))
            })?;
            inner = target.clone();
            (el, port) = match inner.split_once('.') {
                Some((e, p)) => (e, Some(p)),
                None => (inner.as_str(), None),
            };
        }
        let id = g.find(el).ok_or_else(|| {
            let mut known: Vec<&str> = src.elements.iter().map(|e| e.name.as_str()).collect();
            known.sort_unstable();
            err(ErrorKind::UnknownElement, format!("no element `{el}`"))
                .hint(format!("elements are: {}", known.join(", ")))
        })?;
        let port = match port {
            None => None,
            Some(p) => Some(g.port_index(id, p).map_err(|e| {
                err(ErrorKind::Graph, e.message())
                    .or_hint(e.hint())
                    .element(el)
                    .with_source(e)
            })?),
        };
        Ok((id, port))
    };
    let (from, to) = (end(a)?, end(b)?);
    g.connect_named(name, from, to).map_err(|e| {
        let ours = match &e {
            GraphError::NoFreePort { element, .. } => format!(
                "name the port: `{element}.<port>`, and check `{element}` is not bonded twice"
            ),
            _ => "each port takes exactly one bond".into(),
        };
        let hint = match e.hint() {
            Some(core) => format!("{core}; {ours}"),
            None => ours,
        };
        let m = err(ErrorKind::Graph, e.message()).hint(hint);
        let m = match graph_element(&e) {
            Some(el) => m.element(el),
            None => m,
        };
        m.with_source(e)
    })?;
    Ok(())
}

/// The signals read that name nothing in the graph: no element, bond or `t` before the
/// first dot. (What such a name reads is resolved with the equations, after causality.)
fn unknown_signals(source: &Source, g: &BondGraph) -> Vec<ModelError> {
    let mut out = Vec::new();
    for id in 0..g.n_elements() {
        let node = g.node(id);
        for spec in node.element.signal_inputs() {
            let head = spec.name.split('.').next().unwrap_or("");
            let known = matches!(spec.name.as_str(), "t" | "time")
                || g.find(head).is_some()
                || g.bonds().any(|b| b.name == head)
                || source.elements.iter().any(|d| d.name == head);
            if !known {
                let e = GraphError::UnknownSignal {
                    element: node.name.clone(),
                    signal: spec.name.clone(),
                    hint: format!("no element `{head}`; signals are written `<element>.<state or signal>`, `<element>.e`, `<element>.f` or `t`"),
                };
                out.push(core_error(source, bondgraph::Error::Graph(e)));
            }
        }
    }
    out
}

/// The element a graph error is about.
fn graph_element(e: &GraphError) -> Option<&str> {
    match e {
        GraphError::NoSuchPort { element, .. }
        | GraphError::PortInUse { element, .. }
        | GraphError::NoFreePort { element, .. }
        | GraphError::Unconnected { element, .. }
        | GraphError::EmptyJunction { element }
        | GraphError::DimensionMismatch { element, .. }
        | GraphError::UnknownSignal { element, .. }
        | GraphError::SignalDimension { element, .. }
        | GraphError::Replacement { element, .. }
        | GraphError::Contract { element, .. } => Some(element),
        GraphError::DuplicateName { name } | GraphError::UnknownElement { name } => Some(name),
        _ => None,
    }
}

/// A core error as a [`ModelError`] at the line of the element it names, its hint apart and
/// the core error as its source.
pub(super) fn core_error(source: &Source, e: bondgraph::Error) -> ModelError {
    let (kind, element) = match &e {
        bondgraph::Error::Graph(g) => (ErrorKind::Graph, graph_element(g).map(str::to_owned)),
        bondgraph::Error::Causality(c) => (
            ErrorKind::Causality,
            match c {
                CausalityError::Derivative { element, .. }
                | CausalityError::Conflict { element, .. } => Some(element.clone()),
                CausalityError::AlgebraicLoop { elements, .. } => elements.first().cloned(),
                _ => None,
            },
        ),
        bondgraph::Error::Param(_) => (ErrorKind::BadParameter, None),
        _ => (ErrorKind::Settings, None),
    };
    let mut m = ModelError::new(kind, &source.file, e.message()).or_hint(e.hint());
    if let Some(el) = element {
        m = m.at(source.element_pos(&el)).element(&el);
    }
    m.with_source(e)
}

/// Causality of a complete graph.
pub(super) fn causal(source: &Source, g: BondGraph) -> Result<CausalGraph, ModelError> {
    assign_causality(g).map_err(|e| core_error(source, e))
}
