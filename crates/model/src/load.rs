//! Loading a model file: TOML → [`BondGraph`] → [`CausalGraph`] → [`StateEquations`], with
//! settings, initial values, events, outputs and checks. Every error names the file, the line
//! and column, the element and a hint.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::ops::Range;
use std::path::Path;

use bondgraph::{
    assign_causality, BondGraph, CausalGraph, CausalityError, Element, Event, GraphError, Method,
    Output, Settings, StateEquations,
};
use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

use crate::error::{line_col, ErrorKind, ModelError};
use crate::expr::{Expr, RESERVED};
use crate::registry::{ElementSpec, RawValue, Registry};

type SpannedMap<V> = IndexMap<Spanned<String>, Spanned<V>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    title: Option<String>,
    description: Option<String>,
    #[serde(default)]
    parameters: SpannedMap<toml::Value>,
    #[serde(default)]
    elements: SpannedMap<SpannedMap<toml::Value>>,
    #[serde(default)]
    bonds: SpannedMap<String>,
    simulation: Option<SimulationSpec>,
    #[serde(default)]
    initial: SpannedMap<toml::Value>,
    #[serde(default)]
    events: Vec<Spanned<EventSpec>>,
    #[serde(default)]
    outputs: SpannedMap<String>,
    #[serde(default)]
    check: Vec<Spanned<CheckSpec>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SimulationSpec {
    t_start: Option<Spanned<f64>>,
    t_end: Option<Spanned<f64>>,
    dt_out: Option<Spanned<f64>>,
    solver: Option<Spanned<String>>,
    rtol: Option<Spanned<f64>>,
    atol: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EventSpec {
    t: f64,
    set: SpannedMap<toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckSpec {
    value: Spanned<String>,
    expected: Spanned<String>,
    tol: Spanned<f64>,
}

/// A check of the results: at every output row, |value − expected| ≤ tol, where `value` and
/// `expected` are expressions of `t`, parameters and output columns.
#[derive(Clone, Debug)]
pub struct Check {
    /// What is checked (a column name or an expression of columns).
    pub value: String,
    /// Expected value.
    pub expected: String,
    /// Absolute tolerance.
    pub tol: f64,
    value_expr: Expr,
    expected_expr: Expr,
}

/// The result of a [`Check`].
#[derive(Clone, Debug)]
pub struct CheckResult {
    /// What was checked.
    pub value: String,
    /// Largest |value − expected| over the rows.
    pub max_error: f64,
    /// Time of the largest error.
    pub t_worst: f64,
    /// Tolerance.
    pub tol: f64,
    /// `max_error <= tol` (and every value finite).
    pub passed: bool,
}

#[derive(Clone, Debug)]
struct ElementDef {
    name: String,
    kind: String,
    params: IndexMap<String, RawValue>,
    name_span: Range<usize>,
    used: HashSet<String>,
    /// Global names of the elements this entry became (itself, or a composite's members).
    members: Vec<String>,
    /// A composite's exposed ports: name → `member` or `member.port` (global names).
    ports: Vec<(String, String)>,
}

/// An entry's members in global names: elements, internal bonds (name, from, to), exposed
/// ports (name, member port), and the parameters it used.
type Members = (
    Vec<(String, Box<dyn Element>)>,
    Vec<(String, String, String)>,
    Vec<(String, String)>,
    HashSet<String>,
);

/// Rebuilt elements by id.
type Replacements = Vec<(bondgraph::ElementId, Box<dyn Element>)>;

/// What one model-file entry builds into.
enum BuiltDef {
    One(Box<dyn Element>),
    Many(crate::registry::Composite),
}

#[derive(Clone, Debug)]
struct EventDef {
    t: f64,
    set: IndexMap<String, RawValue>,
    span: Range<usize>,
}

/// What the loader keeps to rebuild elements with other parameter values (events).
#[derive(Clone, Debug)]
struct Source {
    file: String,
    text: String,
    registry: Registry,
    param_exprs: IndexMap<String, RawValue>,
    elements: Vec<ElementDef>,
    events: Vec<EventDef>,
}

impl Source {
    fn err(
        &self,
        kind: ErrorKind,
        span: Option<&Range<usize>>,
        message: impl Into<String>,
    ) -> ModelError {
        ModelError::new(kind, &self.file, message).at(span.map(|s| line_col(&self.text, s.start)))
    }

    fn element_pos(&self, name: &str) -> Option<(usize, usize)> {
        self.elements
            .iter()
            .find(|e| e.name == name || e.members.iter().any(|m| m == name))
            .map(|e| line_col(&self.text, e.name_span.start))
    }

    /// Evaluate every named parameter, with `set` overriding some expressions.
    fn evaluate_parameters(
        &self,
        set: &IndexMap<String, RawValue>,
    ) -> Result<IndexMap<String, f64>, ModelError> {
        let mut exprs: IndexMap<String, RawValue> = self.param_exprs.clone();
        for (k, v) in set {
            exprs.insert(k.clone(), v.clone());
        }
        let mut values: IndexMap<String, f64> = IndexMap::new();
        let mut visiting: Vec<String> = Vec::new();
        for name in exprs.keys() {
            self.eval_param(name, &exprs, &mut values, &mut visiting)?;
        }
        // keep file order
        let mut ordered = IndexMap::new();
        for name in exprs.keys() {
            if let Some(v) = values.get(name) {
                ordered.insert(name.clone(), *v);
            }
        }
        Ok(ordered)
    }

    fn eval_param(
        &self,
        name: &str,
        exprs: &IndexMap<String, RawValue>,
        values: &mut IndexMap<String, f64>,
        visiting: &mut Vec<String>,
    ) -> Result<f64, ModelError> {
        if let Some(v) = values.get(name) {
            return Ok(*v);
        }
        let raw = &exprs[name];
        if visiting.iter().any(|v| v == name) {
            return Err(self
                .err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!(
                        "parameter `{name}` depends on itself: {} -> {name}",
                        visiting.join(" -> ")
                    ),
                )
                .hint("break the cycle: give one of these parameters a number"));
        }
        let e = match &raw.value {
            toml::Value::Float(v) => Expr::Num(*v),
            toml::Value::Integer(i) => Expr::Num(*i as f64),
            toml::Value::String(s) => Expr::parse(s).map_err(|e| {
                self.err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!("parameter `{name}` = \"{s}\": {e}"),
                )
            })?,
            other => {
                return Err(self.err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!(
                        "parameter `{name}` must be a number or an expression string, not {}",
                        other.type_str()
                    ),
                ));
            }
        };
        visiting.push(name.to_owned());
        let mut deps = HashMap::new();
        for n in e.names() {
            if n == "pi" {
                continue;
            }
            if !exprs.contains_key(&n) {
                return Err(self
                    .err(
                        ErrorKind::BadParameter,
                        Some(&raw.span),
                        format!("parameter `{name}` uses `{n}`, which is not a parameter"),
                    )
                    .hint(format!(
                        "parameters may only use numbers and other parameters; known: {}",
                        exprs.keys().cloned().collect::<Vec<_>>().join(", ")
                    )));
            }
            let v = self.eval_param(&n, exprs, values, visiting)?;
            deps.insert(n, v);
        }
        visiting.pop();
        let v = e
            .eval(&|n| deps.get(n).copied())
            .map_err(|m| self.err(ErrorKind::BadParameter, Some(&raw.span), m))?;
        if !v.is_finite() {
            return Err(self
                .err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!("parameter `{name}` is {v}, which is not finite"),
                )
                .hint("check for division by zero, a negative square root or a typo"));
        }
        values.insert(name.to_owned(), v);
        Ok(v)
    }

    fn build_element(
        &self,
        def: &ElementDef,
        constants: &IndexMap<String, f64>,
    ) -> Result<(BuiltDef, HashSet<String>), ModelError> {
        let info = self.registry.get(&def.kind).ok_or_else(|| {
            let mut kinds: Vec<&str> = self.registry.kinds().map(|(k, _)| k).collect();
            kinds.sort_unstable();
            let close: Vec<&str> = kinds
                .iter()
                .copied()
                .filter(|k| {
                    k.eq_ignore_ascii_case(&def.kind) || k.ends_with(&format!(".{}", def.kind))
                })
                .collect();
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
                format!("unknown element kind `{}`", def.kind),
            )
            .element(&def.name)
            .hint(hint)
        })?;
        let spec = ElementSpec {
            name: &def.name,
            kind: &def.kind,
            params: &def.params,
            constants,
            file: &self.file,
            text: &self.text,
            name_span: def.name_span.clone(),
            asked: RefCell::new(Vec::new()),
            used_constants: RefCell::new(HashSet::new()),
        };
        let element = match info.build {
            crate::registry::Builder::Element(f) => BuiltDef::One(f(&spec)?),
            crate::registry::Builder::Composite(f) => BuiltDef::Many(f(&spec)?),
        };
        let (unused, asked) = spec.unused();
        if let Some(k) = unused.first() {
            let close = asked.iter().find(|a| {
                a.eq_ignore_ascii_case(k)
                    || (a.len() > 1 && (k.starts_with(a.as_str()) || a.starts_with(k.as_str())))
            });
            let takes = if asked.is_empty() {
                "it takes none".to_owned()
            } else {
                format!("it takes: {}", asked.join(", "))
            };
            let hint = close.map_or(takes.clone(), |c| format!("did you mean `{c}`? {takes}"));
            return Err(spec
                .error(
                    k,
                    ErrorKind::ExtraParameter,
                    format!("({}) has no parameter `{k}`", def.kind),
                )
                .hint(hint));
        }
        Ok((element, spec.used_constants.into_inner()))
    }
}

impl Source {
    /// Build `def` with `constants` into global members (name, element); a composite's
    /// internal bonds and exposed ports are returned in global names.
    fn build_members(
        &self,
        def: &ElementDef,
        constants: &IndexMap<String, f64>,
    ) -> Result<Members, ModelError> {
        let (built, used) = self.build_element(def, constants)?;
        match built {
            BuiltDef::One(e) => Ok((vec![(def.name.clone(), e)], Vec::new(), Vec::new(), used)),
            BuiltDef::Many(c) => {
                let global = |local: &str| format!("{}_{local}", def.name);
                let global_end = |end: &str| match end.split_once('.') {
                    Some((el, port)) => format!("{}.{port}", global(el)),
                    None => global(end),
                };
                let members = c
                    .elements
                    .into_iter()
                    .map(|(n, e)| (global(&n), e))
                    .collect();
                let bonds = c
                    .bonds
                    .iter()
                    .map(|(n, a, b)| (global(n), global_end(a), global_end(b)))
                    .collect();
                let ports = c
                    .ports
                    .iter()
                    .map(|(n, inner)| (n.clone(), global_end(inner)))
                    .collect();
                Ok((members, bonds, ports, used))
            }
        }
    }

    /// Elements rebuilt with `constants`, as (element id, element), for every entry that
    /// uses one of `changed` (all entries if `changed` is `None`).
    fn rebuild(
        &self,
        eqs: &StateEquations,
        constants: &IndexMap<String, f64>,
        changed: Option<&HashSet<&String>>,
        span: Option<&Range<usize>>,
    ) -> Result<Replacements, ModelError> {
        let mut out = Vec::new();
        for def in &self.elements {
            if changed.is_some_and(|c| !def.used.iter().any(|u| c.contains(u))) {
                continue;
            }
            let (members, _, _, _) = self.build_members(def, constants)?;
            for (name, el) in members {
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
                    self.err(ErrorKind::Settings, span, e.to_string())
                        .element(&def.name)
                })?;
                out.push((id, el));
            }
        }
        Ok(out)
    }
}

/// A loaded model, ready to run.
pub struct Model {
    /// Title from the file.
    pub title: Option<String>,
    /// Description from the file.
    pub description: Option<String>,
    /// The assembled equations.
    pub equations: StateEquations,
    /// Initial state (element initial values, then `[initial]`).
    pub x0: Vec<f64>,
    /// Solver settings.
    pub settings: Settings,
    /// Output columns besides `t`.
    pub outputs: Vec<Output>,
    /// Checks against expected results.
    pub checks: Vec<Check>,
    /// Named parameters and their values.
    pub parameters: IndexMap<String, f64>,
    source: Source,
}

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("file", &self.source.file)
            .field("title", &self.title)
            .field("n_states", &self.equations.n_states())
            .finish_non_exhaustive()
    }
}

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
    /// Problems found.
    pub problems: Vec<ModelError>,
}

struct Parsed {
    spec: FileSpec,
    source: Source,
    parameters: IndexMap<String, f64>,
}

fn syntax(file: &str, text: &str, e: &toml::de::Error) -> ModelError {
    let pos = e.span().map(|s| line_col(text, s.start));
    let mut message = e.message().trim().to_owned();
    if let Some(s) = e.span() {
        // name the key or value the parser stopped at
        let at = text.get(s.clone()).unwrap_or("").trim();
        if !at.is_empty() && at.len() < 60 && !at.contains('\n') && !message.contains(at) {
            message = format!("{message}: `{at}`");
        }
    }
    ModelError::new(ErrorKind::Syntax, file, message)
        .at(pos)
        .hint("a model has the sections title, description, [parameters], [elements], [bonds], [simulation], [initial], [[events]], [outputs], [[check]]")
}

fn valid_name(n: &str) -> bool {
    let mut c = n.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

fn raw(v: &Spanned<toml::Value>) -> RawValue {
    RawValue {
        value: v.get_ref().clone(),
        span: v.span(),
    }
}

fn parse(
    file: &str,
    text: &str,
    registry: &Registry,
    overrides: &[String],
) -> Result<Parsed, ModelError> {
    let text = crate::overrides::apply(file, text, overrides)?;
    let spec: FileSpec = toml::from_str(&text).map_err(|e| syntax(file, &text, &e))?;
    if spec.elements.is_empty() {
        return Err(ModelError::new(ErrorKind::Syntax, file, "the model has no elements")
            .at(Some((1, 1)))
            .hint("add an [elements] section, e.g. `mass = { kind = \"I\", m = 1.0 }`; see docs/model-format.md"));
    }
    let mut source = Source {
        file: file.to_owned(),
        text: text.clone(),
        registry: registry.clone(),
        param_exprs: IndexMap::new(),
        elements: Vec::new(),
        events: Vec::new(),
    };
    for (k, v) in &spec.parameters {
        if !valid_name(k.get_ref()) || RESERVED.contains(&k.get_ref().as_str()) {
            return Err(source
                .err(ErrorKind::BadParameter, Some(&k.span()), format!("`{}` cannot be a parameter name", k.get_ref()))
                .hint("parameter names are letters, digits and _ (starting with a letter); `t`, `time` and `pi` are reserved"));
        }
        source.param_exprs.insert(k.get_ref().clone(), raw(v));
    }
    let parameters = source.evaluate_parameters(&IndexMap::new())?;
    for (name, table) in &spec.elements {
        let n = name.get_ref();
        if !valid_name(n) {
            return Err(source
                .err(
                    ErrorKind::Syntax,
                    Some(&name.span()),
                    format!("`{n}` cannot be an element name"),
                )
                .hint(
                    "element names are letters, digits and _ (starting with a letter), no dots",
                ));
        }
        let mut params = IndexMap::new();
        let mut kind = None;
        for (k, v) in table.get_ref() {
            if k.get_ref() == "kind" {
                match v.get_ref() {
                    toml::Value::String(s) => kind = Some(s.clone()),
                    _ => {
                        return Err(source
                            .err(
                                ErrorKind::Syntax,
                                Some(&v.span()),
                                "`kind` must be a string such as \"R\" or \"hydraulics.orifice\"",
                            )
                            .element(n))
                    }
                }
            } else {
                params.insert(k.get_ref().clone(), raw(v));
            }
        }
        let kind = kind.ok_or_else(|| {
            source
                .err(ErrorKind::Syntax, Some(&name.span()), "has no `kind`")
                .element(n)
                .hint("write e.g. `mass = { kind = \"I\", m = 1.0 }`")
        })?;
        source.elements.push(ElementDef {
            name: n.clone(),
            kind,
            params,
            name_span: name.span(),
            used: HashSet::new(),
            members: vec![n.clone()],
            ports: Vec::new(),
        });
    }
    for ev in &spec.events {
        let set = ev
            .get_ref()
            .set
            .iter()
            .map(|(k, v)| (k.get_ref().clone(), raw(v)))
            .collect();
        source.events.push(EventDef {
            t: ev.get_ref().t,
            set,
            span: ev.span(),
        });
    }
    Ok(Parsed {
        spec,
        source,
        parameters,
    })
}

fn build_graph(p: &mut Parsed) -> Result<BondGraph, ModelError> {
    let mut g = BondGraph::new();
    let mut internal = Vec::new();
    for i in 0..p.source.elements.len() {
        let def = p.source.elements[i].clone();
        let (members, bonds, ports, used) = p.source.build_members(&def, &p.parameters)?;
        let d = &mut p.source.elements[i];
        d.used = used;
        d.members = members.iter().map(|(n, _)| n.clone()).collect();
        d.ports = ports;
        for (name, element) in members {
            g.add_boxed(&name, element).map_err(|e| {
                p.source
                    .err(ErrorKind::Graph, Some(&def.name_span), e.to_string())
                    .element(&def.name)
            })?;
        }
        internal.extend(bonds.into_iter().map(|b| (i, b)));
    }
    for (i, (name, from, to)) in internal {
        let def = &p.source.elements[i];
        let err = |e: String| {
            p.source
                .err(
                    ErrorKind::Graph,
                    Some(&def.name_span),
                    format!("inside {} `{}`: bond {name}: {e}", def.kind, def.name),
                )
                .element(&def.name)
        };
        let end = |s: &str| -> Result<(usize, Option<usize>), ModelError> {
            let (el, port) = s.split_once('.').map_or((s, None), |(e, p)| (e, Some(p)));
            let id = g.find(el).ok_or_else(|| err(format!("no member `{el}`")))?;
            let port = port
                .map(|p| g.port_index(id, p))
                .transpose()
                .map_err(|e| err(e.to_string()))?;
            Ok((id, port))
        };
        let (f, t) = (end(&from)?, end(&to)?);
        g.connect_named(&name, f, t)
            .map_err(|e| err(e.to_string()))?;
    }
    for (name, text) in &p.spec.bonds {
        let src = &p.source;
        let span = text.span();
        let err =
            |kind, m: String| src.err(kind, Some(&span), format!("bond `{}`: {m}", name.get_ref()));
        if !valid_name(name.get_ref()) {
            return Err(err(
                ErrorKind::Syntax,
                "bond names are letters, digits and _".into(),
            ));
        }
        let (a, b) = text.get_ref().split_once("->").ok_or_else(|| {
            err(
                ErrorKind::Syntax,
                format!("`{}` is not of the form \"from -> to\"", text.get_ref()),
            )
            .hint("the arrow points in the direction of positive power: \"source -> junction\"")
        })?;
        let end = |s: &str| -> Result<(usize, Option<usize>), ModelError> {
            let s = s.trim();
            let (mut el, mut port) = match s.split_once('.') {
                Some((e, p)) => (e, Some(p)),
                None => (s, None),
            };
            // A composite stands for the member port it exposes.
            let inner: String;
            if let Some(def) = src
                .elements
                .iter()
                .find(|d| d.name == el && !d.ports.is_empty())
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
                Some(p) => Some(
                    g.port_index(id, p)
                        .map_err(|e| err(ErrorKind::Graph, e.to_string()).element(el))?,
                ),
            };
            Ok((id, port))
        };
        let (from, to) = (end(a)?, end(b)?);
        g.connect_named(name.get_ref(), from, to).map_err(|e| {
            let hint = match &e {
                GraphError::NoFreePort { element, .. } => format!(
                    "name the port: `{element}.<port>`, and check `{element}` is not bonded twice"
                ),
                _ => "each port takes exactly one bond".into(),
            };
            let text = e.to_string();
            let (msg, core_hint) = text.split_once("; hint: ").unwrap_or((text.as_str(), ""));
            let hint = if core_hint.is_empty() {
                hint
            } else {
                format!("{core_hint}; {hint}")
            };
            let m = err(ErrorKind::Graph, msg.to_owned()).hint(hint);
            match graph_element(&e) {
                Some(el) => m.element(el),
                None => m,
            }
        })?;
    }
    Ok(g)
}

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

fn core_error(source: &Source, e: bondgraph::Error) -> ModelError {
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
    // The core's messages end in "; hint: …": keep the hint apart.
    let text = e.to_string();
    let mut m = match text.split_once("; hint: ") {
        Some((msg, hint)) => ModelError::new(kind, &source.file, msg).hint(hint),
        None => ModelError::new(kind, &source.file, text),
    };
    if let Some(el) = element {
        m = m.at(source.element_pos(&el)).element(&el);
    }
    m
}

fn causal(p: &Parsed, g: BondGraph) -> Result<CausalGraph, ModelError> {
    assign_causality(g).map_err(|e| core_error(&p.source, e))
}

/// Read the check of `bg-sim check`: elements, bonds with causality, states, and every
/// problem found, going as far as the model allows.
#[must_use]
pub fn inspect(path: &Path, registry: &Registry, overrides: &[String]) -> Inspection {
    let mut out = Inspection::default();
    let file = path.display().to_string();
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => {
            out.problems.push(ModelError::new(
                ErrorKind::Io,
                &file,
                format!("cannot read: {e}"),
            ));
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
    let g = match build_graph(&mut p) {
        Ok(g) => g,
        Err(e) => {
            out.problems.push(e);
            return out;
        }
    };
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
    let cg = match causal(&p, g) {
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
            if let Err(e) = finish(p, eqs) {
                out.problems.push(e);
            }
        }
        Err(e) => out.problems.push(core_error(&p.source, e)),
    }
    out
}

fn finish(p: Parsed, mut eqs: StateEquations) -> Result<Model, ModelError> {
    let Parsed {
        spec,
        source,
        parameters,
    } = p;
    // initial values
    let mut flat = Vec::new();
    flatten("", &spec.initial, &mut flat);
    for (name, value, span) in flat {
        let v = match &value {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            toml::Value::String(s) => Expr::parse(s)
                .ok()
                .and_then(|e| e.eval(&|n| parameters.get(n).copied()).ok()),
            _ => None,
        }
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            source.err(
                ErrorKind::BadParameter,
                Some(&span),
                format!(
                    "initial value of `{name}` must be a finite number or a constant expression"
                ),
            )
        })?;
        eqs.set_initial(&name, v).map_err(|_| {
            let el = name.split('.').next().unwrap_or("");
            let states: Vec<String> = eqs
                .states()
                .iter()
                .filter(|s| s.name.starts_with(&format!("{el}.")))
                .map(|s| s.name.clone())
                .collect();
            source
                .err(
                    ErrorKind::Settings,
                    Some(&span),
                    format!("[initial]: there is no state `{name}`"),
                )
                .hint(if states.is_empty() {
                    "states are named `<element>.<state>`, e.g. `mass.p`, `spring.q`".to_owned()
                } else {
                    format!("states of `{el}`: {}", states.join(", "))
                })
        })?;
    }
    // settings
    let sim = spec.simulation.unwrap_or_default();
    let mut settings = Settings::default();
    let num = |v: &Option<Spanned<f64>>, default: f64, key: &str| -> Result<f64, ModelError> {
        match v {
            None => Ok(default),
            Some(s) if s.get_ref().is_finite() => Ok(*s.get_ref()),
            Some(s) => Err(source.err(
                ErrorKind::Settings,
                Some(&s.span()),
                format!("[simulation] {key} must be finite"),
            )),
        }
    };
    settings.t_start = num(&sim.t_start, 0.0, "t_start")?;
    settings.t_end = num(&sim.t_end, 1.0, "t_end")?;
    settings.dt_out = num(
        &sim.dt_out,
        (settings.t_end - settings.t_start) / 100.0,
        "dt_out",
    )?;
    settings.rtol = num(&sim.rtol, 1e-6, "rtol")?;
    settings.atol = num(&sim.atol, 1e-8, "atol")?;
    if let Some(s) = &sim.solver {
        settings.method = Method::parse(s.get_ref()).ok_or_else(|| {
            source
                .err(
                    ErrorKind::Settings,
                    Some(&s.span()),
                    format!("unknown solver `{}`", s.get_ref()),
                )
                .hint(format!("solvers: {}", Method::names()))
        })?;
    }
    if let Err(e) = settings.validate() {
        let span_of = |v: &Option<Spanned<f64>>| v.as_ref().map(Spanned::span);
        let span = match &e {
            bondgraph::SimulationError::InvalidSetting { setting, .. } => match *setting {
                "dt_out" => span_of(&sim.dt_out),
                "rtol" => span_of(&sim.rtol),
                "atol" => span_of(&sim.atol),
                _ => span_of(&sim.t_end).or_else(|| span_of(&sim.t_start)),
            },
            _ => None,
        };
        return Err(source
            .err(
                ErrorKind::Settings,
                span.as_ref(),
                format!("[simulation] {e}"),
            )
            .hint("t_start < t_end, dt_out > 0, 0 < rtol < 1, atol > 0"));
    }
    // outputs
    let mut outputs = Vec::new();
    if spec.outputs.is_empty() {
        for (i, s) in eqs.states().iter().enumerate() {
            outputs.push(Output {
                name: s.name.clone(),
                probe: bondgraph::Probe::State(i),
            });
        }
    }
    for (col, name) in &spec.outputs {
        let probe = eqs.probe(name.get_ref()).ok_or_else(|| {
            let el = name.get_ref().split('.').next().unwrap_or("");
            let offers: Vec<String> = eqs.probe_names().into_iter().filter(|n| n.starts_with(&format!("{el}."))).take(16).collect();
            source.err(ErrorKind::Settings, Some(&name.span()), format!("[outputs] `{}`: nothing is called `{}`", col.get_ref(), name.get_ref())).hint(if offers.is_empty() {
                "outputs name a state (`mass.p`), its derivative (`mass.p.dot`), a signal (`ctrl.out`) or a bond variable (`mass.e`, `mass.f`, `b3.P`, `lever.2.e`)".to_owned()
            } else {
                format!("`{el}` offers: {}", offers.join(", "))
            })
        })?;
        outputs.push(Output {
            name: col.get_ref().clone(),
            probe,
        });
    }
    // checks
    let mut checks = Vec::new();
    for c in &spec.check {
        let cs = c.get_ref();
        let parse_checked = |what: &str, text: &Spanned<String>| -> Result<Expr, ModelError> {
            let span = text.span();
            let e = Expr::parse(text.get_ref()).map_err(|e| {
                source.err(
                    ErrorKind::Settings,
                    Some(&span),
                    format!("[[check]] {what} = \"{}\": {e}", text.get_ref()),
                )
            })?;
            for n in e.names() {
                if n != "t"
                    && n != "pi"
                    && !parameters.contains_key(&n)
                    && !outputs.iter().any(|o| o.name == n)
                {
                    return Err(source
                        .err(ErrorKind::Settings, Some(&span), format!("[[check]] {what} uses `{n}`, which is neither `t`, a parameter nor an output column"))
                        .hint("name output columns in [outputs] with plain names (letters, digits, _) to use them in checks"));
                }
            }
            Ok(e)
        };
        let value_expr = parse_checked("value", &cs.value)?;
        let expected_expr = parse_checked("expected", &cs.expected)?;
        let tol = *cs.tol.get_ref();
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(source.err(
                ErrorKind::Settings,
                Some(&cs.tol.span()),
                format!("[[check]] tol must be finite and >= 0, got {tol}"),
            ));
        }
        checks.push(Check {
            value: cs.value.get_ref().clone(),
            expected: cs.expected.get_ref().clone(),
            tol,
            value_expr,
            expected_expr,
        });
    }
    let model = Model {
        title: spec.title,
        description: spec.description,
        x0: eqs.initial_state(),
        equations: eqs,
        settings,
        outputs,
        checks,
        parameters,
        source,
    };
    // events must build now, so that their errors show at load time
    model.events()?;
    Ok(model)
}

fn flatten(
    prefix: &str,
    map: &SpannedMap<toml::Value>,
    out: &mut Vec<(String, toml::Value, Range<usize>)>,
) {
    for (k, v) in map {
        let name = if prefix.is_empty() {
            k.get_ref().clone()
        } else {
            format!("{prefix}.{}", k.get_ref())
        };
        flatten_value(&name, v.get_ref(), v.span(), out);
    }
}

fn flatten_value(
    name: &str,
    v: &toml::Value,
    span: Range<usize>,
    out: &mut Vec<(String, toml::Value, Range<usize>)>,
) {
    match v {
        toml::Value::Table(t) => {
            for (k, v) in t {
                flatten_value(&format!("{name}.{k}"), v, span.clone(), out);
            }
        }
        other => out.push((name.to_owned(), other.clone(), span)),
    }
}

impl Model {
    /// Load a model file with the given element kinds and `--set` overrides.
    pub fn load(
        path: &Path,
        registry: &Registry,
        overrides: &[String],
    ) -> Result<Self, ModelError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            ModelError::new(ErrorKind::Io, &file, format!("cannot read: {e}"))
                .hint("check the path")
        })?;
        Self::from_text(&file, &text, registry, overrides)
    }

    /// Load a model from text; `file` names it in errors.
    pub fn from_text(
        file: &str,
        text: &str,
        registry: &Registry,
        overrides: &[String],
    ) -> Result<Self, ModelError> {
        let mut p = parse(file, text, registry, overrides)?;
        let g = build_graph(&mut p)?;
        let cg = causal(&p, g)?;
        let eqs = StateEquations::new(cg).map_err(|e| core_error(&p.source, e))?;
        finish(p, eqs)
    }

    /// The file the model came from.
    #[must_use]
    pub fn file(&self) -> &str {
        &self.source.file
    }

    /// 1-based line where element `name` is defined.
    #[must_use]
    pub fn element_line(&self, name: &str) -> Option<usize> {
        self.source.element_pos(name).map(|p| p.0)
    }

    /// The scheduled events: at each event time the named parameters change (cumulatively),
    /// and every element whose definition uses a changed parameter is rebuilt.
    pub fn events(&self) -> Result<Vec<Event>, ModelError> {
        let mut defs = self.source.events.clone();
        defs.sort_by(|a, b| a.t.total_cmp(&b.t));
        let mut set: IndexMap<String, RawValue> = IndexMap::new();
        let mut current = self.parameters.clone();
        let mut events = Vec::new();
        for ev in defs {
            if !ev.t.is_finite() {
                return Err(self.source.err(
                    ErrorKind::Settings,
                    Some(&ev.span),
                    format!("event time {} is not finite", ev.t),
                ));
            }
            for (k, v) in &ev.set {
                if !self.source.param_exprs.contains_key(k) {
                    return Err(self
                        .source
                        .err(
                            ErrorKind::Settings,
                            Some(&v.span),
                            format!("event at t = {}: `{k}` is not a parameter", ev.t),
                        )
                        .hint(format!(
                            "events set names from [parameters]: {}",
                            self.parameters
                                .keys()
                                .cloned()
                                .collect::<Vec<_>>()
                                .join(", ")
                        )));
                }
                set.insert(k.clone(), v.clone());
            }
            let values = self.source.evaluate_parameters(&set)?;
            let changed: HashSet<&String> = values
                .iter()
                .filter(|(k, v)| current.get(*k) != Some(*v))
                .map(|(k, _)| k)
                .collect();
            let replacements =
                self.source
                    .rebuild(&self.equations, &values, Some(&changed), Some(&ev.span))?;
            current = values;
            events.push(Event {
                t: ev.t,
                replacements,
            });
        }
        Ok(events)
    }

    /// Run the model with its settings; the elements are restored afterwards, so the model
    /// can run again.
    pub fn run(&mut self) -> Result<bondgraph::Outcome, ModelError> {
        let events = self.events()?;
        let has_events = !events.is_empty();
        let x0 = self.x0.clone();
        let out = bondgraph::simulate(
            &mut self.equations,
            &x0,
            &self.settings,
            &self.outputs,
            events,
        );
        if has_events {
            for (id, el) in self
                .source
                .rebuild(&self.equations, &self.parameters, None, None)?
            {
                self.equations
                    .replace(id, el)
                    .map_err(|e| self.source.err(ErrorKind::Settings, None, e.to_string()))?;
            }
        }
        Ok(out)
    }

    /// Compare a trajectory with the model's `[[check]]`s.
    #[must_use]
    pub fn verify(&self, traj: &bondgraph::Trajectory) -> Vec<CheckResult> {
        self.checks
            .iter()
            .map(|c| {
                let mut worst = (0.0f64, f64::NAN);
                let mut finite = !traj.rows.is_empty();
                for row in &traj.rows {
                    let t = row[0];
                    let lookup = |n: &str| {
                        if n == "t" {
                            Some(t)
                        } else if let Some(k) = traj.columns.iter().position(|col| col == n) {
                            Some(row[k])
                        } else {
                            self.parameters.get(n).copied()
                        }
                    };
                    let err = match (c.value_expr.eval(&lookup), c.expected_expr.eval(&lookup)) {
                        (Ok(v), Ok(e)) => (v - e).abs(),
                        _ => f64::NAN,
                    };
                    if !err.is_finite() {
                        finite = false;
                    }
                    if err > worst.0 || worst.1.is_nan() {
                        worst = (err, t);
                    }
                }
                CheckResult {
                    value: c.value.clone(),
                    max_error: worst.0,
                    t_worst: worst.1,
                    tol: c.tol,
                    passed: finite && worst.0 <= c.tol,
                }
            })
            .collect()
    }
}
