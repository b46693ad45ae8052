//! [`inspect`]: a model file read as far as it goes, reporting every problem found on the
//! way (`bg-sim check`): each entry, bond, signal, plot, initial value, setting, output,
//! check and event on its own; causality and the equations once the graph is complete.

use std::path::Path;

use bondgraph::StateEquations;

use super::model::finish;
use super::parse::{parse, read_model};
use super::wire::{build_graph, causal, core_error};
use crate::error::ModelError;
use crate::registry::Registry;
use crate::scene::Scene;

/// How far [`inspect`] got, for `bg-sim check`.
#[derive(Default)]
pub struct Inspection {
    /// Elements: name, kind, line.
    pub elements: Vec<(String, String, usize)>,
    /// Bonds drawn with their causal strokes (or without, if causality failed).
    pub bonds: Vec<String>,
    /// States with initial values.
    pub states: Vec<(String, f64)>,
    /// Evaluation order.
    pub order: Vec<(String, usize)>,
    /// Every problem found, in file order within each stage.
    pub problems: Vec<ModelError>,
    /// Notes: what loads but was likely meant otherwise ([`super::Model::notes`]).
    pub notes: Vec<ModelError>,
    /// The scene switches (`[scene]`).
    pub scene: Scene,
    /// The external inputs (`[inputs]`), each with where its data come from (`""`: its
    /// default, unless a run gives data).
    pub inputs: Vec<(bondgraph::InputSpec, String)>,
}

/// Read a model file for `bg-sim check`: elements, bonds with causality, states, and every
/// problem found, going as far as the model allows.
#[must_use]
pub fn inspect(path: &Path, registry: &Registry, overrides: &[String]) -> Inspection {
    let mut out = Inspection::default();
    let file = path.display().to_string();
    let text = match read_model(path, &file) {
        Ok(t) => t,
        Err(e) => {
            out.problems.push(e);
            return out;
        }
    };
    let mut p = match parse(&file, &text, registry, overrides) {
        Ok(p) => p,
        Err(e) => {
            out.problems.push(e);
            return out;
        }
    };
    out.inputs = p
        .source
        .inputs
        .iter()
        .map(|d| {
            let from = d.data.as_ref().map_or_else(String::new, |r| {
                format!("{}, column {} ({})", r.file, r.column, r.interp.name())
            });
            (d.spec.clone(), from)
        })
        .collect();
    let g = build_graph(&mut p);
    out.elements = (0..g.n_elements())
        .map(|i| {
            let n = g.node(i);
            (
                n.name.clone(),
                n.element.kind().to_owned(),
                p.source.element_pos(&n.name).map_or(0, |x| x.0),
            )
        })
        .collect();
    let plain: Vec<String> = g
        .bonds()
        .map(|b| {
            format!(
                "{}: {} -> {}   (causality not assigned)",
                b.name,
                g.node(b.from.element).name,
                g.node(b.to.element).name
            )
        })
        .collect();
    out.scene = p.scene.clone();
    if !p.problems.is_empty() {
        out.bonds = plain;
        out.problems = std::mem::take(&mut p.problems);
        return out;
    }
    let cg = match causal(&p.source, g) {
        Ok(c) => c,
        Err(e) => {
            out.bonds = plain;
            out.problems.push(e);
            return out;
        }
    };
    out.bonds = (0..cg.graph.n_bonds())
        .map(|b| cg.describe_bond(b))
        .collect();
    match StateEquations::new(cg) {
        Ok(eqs) => {
            out.states = eqs
                .states()
                .iter()
                .map(|s| (s.name.clone(), s.initial))
                .collect();
            out.order = eqs.order();
            match finish(p, eqs) {
                Ok(m) => {
                    // the start as the model runs it: `[initial]` and a solved steady start
                    for (s, v) in out.states.iter_mut().zip(&m.x0) {
                        s.1 = *v;
                    }
                    out.notes = m.notes();
                    out.scene = m.scene;
                }
                Err(problems) => out.problems = problems,
            }
        }
        Err(e) => out.problems.push(core_error(&p.source, e)),
    }
    out
}
