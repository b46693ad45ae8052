//! What `bg-sim kinds NAME` prints: a kind's declaration, and the ports, states and published
//! signals of a working instance built from the kind's example.

use std::cell::RefCell;
use std::collections::HashSet;
use std::fmt::Write as _;

use bondgraph::kind::{Build, KindDecl, ParamDecl, ParamType};
use bondgraph::{Element, Ports};
use indexmap::IndexMap;

use crate::error::{ErrorKind, ModelError};
use crate::reader::{ElementSpec, RawValue};
use crate::registry::Registry;

/// One member of a built instance: name, kind, ports, states, signals read and published.
#[derive(Clone, Debug, Default)]
pub struct MemberReport {
    /// Global name (`example` for a one-element kind, `example_piston` for a member).
    pub name: String,
    /// Kind of the member element.
    pub kind: String,
    /// Ports with their dimension (`None`: adapts; a junction has any number).
    pub ports: Vec<(String, Option<usize>)>,
    /// States.
    pub states: Vec<String>,
    /// Signals read.
    pub inputs: Vec<String>,
    /// Signals published.
    pub outputs: Vec<String>,
}

/// A kind described: its declaration and what its example builds into.
#[derive(Clone, Debug)]
pub struct KindReport {
    /// The declaration.
    pub decl: KindDecl,
    /// The exposed ports of a composite (name, member port).
    pub exposed: Vec<(String, String)>,
    /// The members (one for a one-element kind).
    pub members: Vec<MemberReport>,
}

fn member(name: String, e: &dyn Element) -> MemberReport {
    MemberReport {
        name,
        kind: e.kind().to_owned(),
        ports: match e.ports() {
            Ports::Fixed(p) => p.into_iter().map(|p| (p.name, p.dim)).collect(),
            Ports::Any => vec![("(any number)".to_owned(), None)],
        },
        states: e.states().into_iter().map(|s| s.name).collect(),
        inputs: e.signal_inputs().into_iter().map(|s| s.name).collect(),
        outputs: e.signal_outputs().into_iter().map(|s| s.name).collect(),
    }
}

/// Build `kind`'s example as an instance called `example` and describe it.
pub fn describe(registry: &Registry, kind: &str) -> Result<KindReport, ModelError> {
    let file = "<kinds>";
    let Some(decl) = registry.get(kind).copied() else {
        let names: Vec<&str> = registry.kinds().map(|k| k.name).collect();
        let hint = match bondgraph::kind::suggest(kind, names.iter().copied()) {
            Some(s) => format!("did you mean `{s}`? `bg-sim kinds` lists them all"),
            None => "`bg-sim kinds` lists them all".to_owned(),
        };
        return Err(ModelError::new(
            ErrorKind::UnknownKind,
            file,
            format!("unknown element kind `{}`", crate::error::clip(kind)),
        )
        .hint(hint));
    };
    let text = format!("example = {{ {} }}\n", decl.example);
    let table: toml::Table = toml::from_str(&text).map_err(|e| {
        ModelError::new(
            ErrorKind::Syntax,
            file,
            format!("the example of `{kind}` does not parse: {e}"),
        )
    })?;
    let params: IndexMap<String, RawValue> = match table.get("example") {
        Some(toml::Value::Table(t)) => t
            .iter()
            .map(|(k, v)| {
                (
                    k.clone(),
                    RawValue {
                        value: v.clone(),
                        span: 0..0,
                    },
                )
            })
            .collect(),
        _ => IndexMap::new(),
    };
    let constants = IndexMap::new();
    let used = RefCell::new(HashSet::new());
    let spec = ElementSpec::new(
        "example",
        decl.name,
        decl.params,
        params,
        &constants,
        file,
        &text,
        0..0,
        &used,
    );
    spec.validate().map_err(|e| spec.locate(e))?;
    let (exposed, members) = match decl.build {
        Build::Element(f) => {
            let e = f(&spec).map_err(|e| spec.locate(e))?;
            (Vec::new(), vec![member("example".into(), e.as_ref())])
        }
        Build::Composite(f) => {
            let x = f(&spec).map_err(|e| spec.locate(e))?.expand("example");
            let members = x
                .elements
                .iter()
                .map(|(n, e)| member(n.clone(), e.as_ref()))
                .collect();
            (x.ports, members)
        }
    };
    Ok(KindReport {
        decl,
        exposed,
        members,
    })
}

/// The parameter table of a kind, in Markdown: `| parameter | unit | default | range | meaning |`.
/// Nested tables follow, one per table parameter.
#[must_use]
pub fn parameter_table(decl: &KindDecl) -> String {
    let mut out = String::new();
    table_of(&mut out, "", decl.params);
    out
}

fn table_of(out: &mut String, prefix: &str, params: &[ParamDecl]) {
    out.push_str("| parameter | unit | default | range | meaning |\n|---|---|---|---|---|\n");
    for d in params {
        let range = match d.ty {
            ParamType::Number | ParamType::Modulated | ParamType::Count | ParamType::Vector
                if !d.range.is_any() =>
            {
                d.range.to_string()
            }
            ParamType::Choice(c) => c
                .iter()
                .map(|w| format!("\"{w}\""))
                .collect::<Vec<_>>()
                .join(", "),
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "| `{prefix}{}` | {} | {} | {range} | {} |",
            d.name, d.unit, d.default, d.doc
        );
    }
    for d in params {
        if let Some(f) = d.fields() {
            let _ = writeln!(out, "\n`{prefix}{}` entries:\n", d.name);
            table_of(out, &format!("{prefix}{}.", d.name), f);
        }
    }
}
