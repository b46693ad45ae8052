//! The structure of a model file for drawing it (`bg-sim graph`): the bond graph as built,
//! its causal strokes when they can be assigned, and what each model-file entry became.

use std::path::Path;

use bondgraph::{assign_causality, BondGraph, ElementId};

use super::parse::{parse, read_model};
use super::wire::{build_graph, core_error};
use crate::error::ModelError;
use crate::registry::Registry;

/// One `[elements]` entry of a model file and what it became.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The entry's name in the file.
    pub name: String,
    /// Its kind (`R`, `hydraulics.cylinder`, …).
    pub kind: String,
    /// Global names of the elements it became: itself, or a composite's members
    /// (`<entry>_<member>`).
    pub members: Vec<String>,
    /// A composite's exposed ports: name → `member` or `member.port` (global names); empty
    /// for a single element.
    pub ports: Vec<(String, String)>,
}

/// A model's bond graph as the loader builds it, for drawing.
pub struct Structure {
    /// Title from the file.
    pub title: Option<String>,
    /// The elements and bonds, composites expanded into their members.
    pub graph: BondGraph,
    /// For each bond the element that sets its effort ([`bondgraph::CausalGraph`]), or the
    /// error that kept causality from being assigned (derivative causality, a conflict).
    pub causality: Result<Vec<ElementId>, ModelError>,
    /// The file's entries in file order.
    pub entries: Vec<Entry>,
}

/// Read a model file as far as its bond graph and causality (with `--set` overrides); the
/// equations are not assembled, so a model refused for an algebraic loop is drawn too.
pub fn structure(
    path: &Path,
    registry: &Registry,
    overrides: &[String],
) -> Result<Structure, ModelError> {
    let file = path.display().to_string();
    let text = read_model(path, &file)?;
    let mut p = parse(&file, &text, registry, overrides)?;
    let g = build_graph(&mut p);
    p.first_problem()?;
    let (graph, causality) = match assign_causality(g) {
        Ok(cg) => (cg.graph, Ok(cg.effort_setter)),
        // the graph went into the failed assignment: build it once more
        Err(e) => (build_graph(&mut p), Err(core_error(&p.source, e))),
    };
    let entries = p
        .source
        .elements
        .iter()
        .map(|d| Entry {
            name: d.name.clone(),
            kind: d.kind.clone(),
            members: d.members.clone(),
            ports: d.ports.clone(),
        })
        .collect();
    Ok(Structure {
        title: p.spec.title.clone(),
        graph,
        causality,
        entries,
    })
}
