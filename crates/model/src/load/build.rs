//! Stage 3, build: each entry through its kind's declaration ([`ElementSpec`],
//! [`bondgraph::kind`]) into an element, or a composite expanded into its members
//! ([`bondgraph::Composite::expand`]). Every entry is built on its own, so every entry's
//! problem is reported; an entry whose failure comes from a parameter already reported is
//! not reported again. Events rebuild single entries the same way ([`Source::rebuild`]).

use std::cell::RefCell;
use std::collections::HashSet;
use std::ops::Range;

use bondgraph::{BondGraph, Element, ElementId, StateEquations};
use indexmap::IndexMap;

use super::parse::Parsed;
use super::source::{ElementDef, Source};
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::Expr;
use crate::reader::ElementSpec;

/// Rebuilt elements by id.
pub(super) type Replacements = Vec<(ElementId, Box<dyn Element>)>;

/// What one model-file entry builds into.
enum Built {
    One(Box<dyn Element>),
    Many(bondgraph::Composite),
}

/// An entry's members in global names.
pub(super) struct Members {
    /// Its elements (itself, or a composite's members).
    pub(super) elements: Vec<(String, Box<dyn Element>)>,
    /// A composite's internal bonds: (name, from, to).
    pub(super) bonds: Vec<(String, String, String)>,
    /// A composite's exposed ports: (name, member port).
    pub(super) ports: Vec<(String, String)>,
    /// The `[parameters]` it used.
    pub(super) used: HashSet<String>,
}

impl Source {
    /// The unknown-kind error of `def`, with the kinds that come close.
    fn unknown_kind(&self, def: &ElementDef) -> ModelError {
        let mut kinds: Vec<&str> = self.registry.kinds().map(|k| k.name).collect();
        kinds.sort_unstable();
        let mut close: Vec<&str> = kinds
            .iter()
            .copied()
            .filter(|k| k.eq_ignore_ascii_case(&def.kind) || k.ends_with(&format!(".{}", def.kind)))
            .collect();
        if close.is_empty() {
            close = kinds
                .iter()
                .copied()
                .filter(|k| bondgraph::kind::similar(&def.kind, k))
                .collect();
        }
        let hint = if close.is_empty() {
            format!("known kinds: {}", kinds.join(", "))
        } else {
            format!(
                "did you mean {}? known kinds: {}",
                close.join(" or "),
                kinds.join(", ")
            )
        };
        self.err(
            ErrorKind::UnknownKind,
            Some(&def.name_span),
            format!("unknown element kind `{}`", clip(&def.kind)),
        )
        .element(&def.name)
        .hint(hint)
    }

    /// Build `def` with `constants` from its kind's declaration.
    fn build_entry(
        &self,
        def: &ElementDef,
        constants: &IndexMap<String, f64>,
    ) -> Result<(Built, HashSet<String>), ModelError> {
        let info = self
            .registry
            .get(&def.kind)
            .ok_or_else(|| self.unknown_kind(def))?;
        let used = RefCell::new(HashSet::new());
        let input_names = self.input_names();
        let mut spec = ElementSpec::new(
            &def.name,
            &def.kind,
            info.params,
            def.params.clone(),
            constants,
            &self.file,
            &self.text,
            def.name_span.clone(),
            &used,
        );
        spec.inputs = &input_names;
        spec.tables = std::sync::Arc::clone(&self.tables);
        spec.motions = std::sync::Arc::new(super::inputs::motions(&self.inputs));
        spec.validate().map_err(|e| spec.locate(e))?;
        let built = match info.build {
            bondgraph::kind::Build::Element(f) => Built::One(f(&spec).map_err(|e| spec.locate(e))?),
            bondgraph::kind::Build::Composite(f) => {
                Built::Many(f(&spec).map_err(|e| spec.locate(e))?)
            }
        };
        drop(spec);
        Ok((built, used.into_inner()))
    }

    /// Build `def` with `constants` into its members, in global names.
    pub(super) fn build_members(
        &self,
        def: &ElementDef,
        constants: &IndexMap<String, f64>,
    ) -> Result<Members, ModelError> {
        let (built, used) = self.build_entry(def, constants)?;
        Ok(match built {
            Built::One(e) => Members {
                elements: vec![(def.name.clone(), e)],
                bonds: Vec::new(),
                ports: Vec::new(),
                used,
            },
            Built::Many(c) => {
                let x = c.expand(&def.name);
                Members {
                    elements: x.elements,
                    bonds: x.bonds,
                    ports: x.ports,
                    used,
                }
            }
        })
    }

    /// Entries `entries` (indices into `elements`) rebuilt alone with `constants`, as
    /// (element id, element), each checked against the element it is to replace.
    pub(super) fn rebuild(
        &self,
        eqs: &StateEquations,
        constants: &IndexMap<String, f64>,
        entries: &[usize],
        span: Option<&Range<usize>>,
    ) -> Result<Replacements, ModelError> {
        let mut out = Vec::new();
        for def in entries.iter().filter_map(|&i| self.elements.get(i)) {
            for (name, el) in self.build_members(def, constants)?.elements {
                let id = eqs.graph().find(&name).ok_or_else(|| {
                    self.err(
                        ErrorKind::Settings,
                        span,
                        format!(
                            "rebuilding `{}` gave a member `{name}` the model does not have",
                            def.name
                        ),
                    )
                    .element(&def.name)
                })?;
                eqs.check_replacement(id, el.as_ref()).map_err(|e| {
                    self.err(ErrorKind::Settings, span, e.message())
                        .or_hint(e.hint())
                        .element(&def.name)
                        .with_source(e)
                })?;
                out.push((id, el));
            }
        }
        Ok(out)
    }
}

/// Build every entry into `g`; a composite's internal bonds are returned with the index of
/// their entry, for the wiring stage.
pub(super) fn build_elements(
    p: &mut Parsed,
    g: &mut BondGraph,
) -> Vec<(usize, (String, String, String))> {
    let mut internal = Vec::new();
    for (name, el) in super::inputs::elements(&p.source.inputs, &p.source) {
        let added = el.and_then(|el| {
            g.add(&name, el).map(drop).map_err(|e| {
                p.source
                    .err(ErrorKind::Input, None, e.message())
                    .or_hint(e.hint())
                    .element(&name)
            })
        });
        if let Err(e) = added {
            p.problems.push(e);
        }
    }
    for i in 0..p.source.elements.len() {
        let def = &p.source.elements[i];
        let m = match p.source.build_members(def, &p.parameters) {
            Ok(m) => m,
            Err(e) => {
                if !uses_any(def, &p.failed.params) {
                    p.problems.push(e);
                }
                p.failed.elements.insert(def.name.clone());
                continue;
            }
        };
        let mut names = Vec::new();
        for (name, element) in m.elements {
            if let Err(e) = g.add_boxed(&name, element) {
                p.problems.push(
                    p.source
                        .err(ErrorKind::Graph, Some(&def.name_span), e.message())
                        .or_hint(e.hint())
                        .element(&def.name)
                        .with_source(e),
                );
                p.failed.elements.insert(def.name.clone());
            }
            names.push(name);
        }
        internal.extend(m.bonds.into_iter().map(|b| (i, b)));
        let d = &mut p.source.elements[i];
        d.used = m.used;
        d.members = names;
        d.ports = m.ports;
    }
    internal
}

/// Whether an entry's values use one of `names` (in an expression, at any depth).
fn uses_any(def: &ElementDef, names: &HashSet<String>) -> bool {
    fn walk(v: &toml::Value, names: &HashSet<String>) -> bool {
        match v {
            toml::Value::String(s) => Expr::parse(s)
                .map(|e| e.names().iter().any(|n| names.contains(n)))
                .unwrap_or(false),
            toml::Value::Array(a) => a.iter().any(|v| walk(v, names)),
            toml::Value::Table(t) => t.values().any(|v| walk(v, names)),
            _ => false,
        }
    }
    !names.is_empty() && def.params.values().any(|r| walk(&r.value, names))
}
