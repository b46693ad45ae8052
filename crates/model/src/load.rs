//! Loading a model file: TOML → [`BondGraph`] → [`CausalGraph`] → [`StateEquations`], with
//! settings, initial values, events, outputs and checks. Every error names the file, the line
//! and column, the element and a hint.

use std::cell::RefCell;
use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use bondgraph::{
    assign_causality, BondGraph, CausalGraph, CausalityError, Element, Event, GraphError, Method,
    Output, Settings, StateEquations,
};
use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

use crate::error::{clip, line_col, ErrorKind, ModelError};
use crate::expr::{Expr, RESERVED};
use crate::reader::{ElementSpec, RawValue};
use crate::registry::Registry;
use crate::scene::Scene;

mod structure;
pub use structure::{structure, Entry, Structure};

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
    #[serde(default)]
    scene: SpannedMap<toml::Value>,
    /// `[[plot]]`: read by `crate::plots`.
    #[serde(default, rename = "plot")]
    _plot: serde::de::IgnoredAny,
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

/// A check of the results: at every output row and every accepted solver step,
/// |value − expected| ≤ tol, where `value` and `expected` are expressions of `t`, parameters
/// and output columns ([`Model::run_into`]).
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
    /// Largest |value − expected| over the points evaluated.
    pub max_error: f64,
    /// Time of the largest error.
    pub t_worst: f64,
    /// Tolerance.
    pub tol: f64,
    /// `max_error <= tol` (and every value finite).
    pub passed: bool,
    /// How many points were evaluated (output rows, plus accepted steps if `every_step`).
    pub points: usize,
    /// Evaluated at every accepted solver step as well as at every output row
    /// ([`Model::run_into`]); `false`: at the output rows only ([`Model::verify`]).
    pub every_step: bool,
}

/// The worst error of one check so far.
#[derive(Clone, Copy)]
struct Worst {
    error: f64,
    t: f64,
    finite: bool,
}

impl Worst {
    const NONE: Self = Self {
        error: 0.0,
        t: f64::NAN,
        finite: true,
    };
    fn add(&mut self, t: f64, error: f64) {
        if !error.is_finite() {
            self.finite = false;
        }
        if error > self.error || self.t.is_nan() {
            self.error = error;
            self.t = t;
        }
    }
    fn result(self, c: &Check, points: usize, every_step: bool) -> CheckResult {
        CheckResult {
            value: c.value.clone(),
            max_error: self.error,
            t_worst: self.t,
            tol: c.tol,
            passed: points > 0 && self.finite && self.error <= c.tol,
            points,
            every_step,
        }
    }
}

/// Evaluates the checks at every output row and every accepted step, and hands the rows on.
struct CheckSink<'a> {
    inner: &'a mut dyn bondgraph::RowSink,
    /// Compiled (value, expected) of each check, reading the columns (`t` first).
    compiled: Vec<(crate::expr::Compiled, crate::expr::Compiled)>,
    worst: Vec<Worst>,
    points: usize,
}

impl<'a> CheckSink<'a> {
    fn new(model: &Model, inner: &'a mut dyn bondgraph::RowSink) -> Result<Self, ModelError> {
        let columns: Vec<String> = std::iter::once("t".to_owned())
            .chain(model.outputs.iter().map(|o| o.name.clone()))
            .collect();
        let constant = |n: &str| {
            if columns.iter().any(|c| c == n) {
                None
            } else {
                model.parameters.get(n).copied()
            }
        };
        let mut compiled = Vec::new();
        for c in &model.checks {
            let compile = |e: &Expr| {
                e.compile(&constant, &columns).map_err(|m| {
                    model.source.err(
                        ErrorKind::Settings,
                        None,
                        format!("[[check]] {}: {m}", clip(&c.value)),
                    )
                })
            };
            compiled.push((compile(&c.value_expr)?, compile(&c.expected_expr)?));
        }
        Ok(Self {
            inner,
            worst: vec![Worst::NONE; compiled.len()],
            compiled,
            points: 0,
        })
    }
    fn evaluate(&mut self, values: &[f64]) {
        self.points += 1;
        let t = values.first().copied().unwrap_or(f64::NAN);
        for ((v, e), w) in self.compiled.iter().zip(&mut self.worst) {
            w.add(t, (v.eval(values) - e.eval(values)).abs());
        }
    }
    fn results(&self, checks: &[Check]) -> Vec<CheckResult> {
        checks
            .iter()
            .zip(&self.worst)
            .map(|(c, w)| w.result(c, self.points, true))
            .collect()
    }
}

impl bondgraph::RowSink for CheckSink<'_> {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.evaluate(row);
        self.inner.row(row)
    }
    fn wants_steps(&self) -> bool {
        !self.compiled.is_empty() || self.inner.wants_steps()
    }
    fn step(&mut self, values: &[f64]) {
        self.evaluate(values);
        if self.inner.wants_steps() {
            self.inner.step(values);
        }
    }
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
    Many(bondgraph::Composite),
}

/// A parameter being evaluated: its expression, the names it uses and the next to look at.
struct PendingParam {
    name: String,
    expr: Expr,
    names: Vec<String>,
    next: usize,
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
    /// Lines (1-based) that `--set` wrote or changed: errors there say so.
    changed_lines: Vec<usize>,
    /// The `[[plot]]` tables (`crate::plots`).
    plots: Vec<crate::plots::Plot>,
}

impl Source {
    fn err(
        &self,
        kind: ErrorKind,
        span: Option<&Range<usize>>,
        message: impl Into<String>,
    ) -> ModelError {
        let pos = span.map(|s| line_col(&self.text, s.start));
        let e = ModelError::new(kind, &self.file, message).at(pos);
        mark_set_line(e, &self.changed_lines)
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
        for name in exprs.keys() {
            self.eval_param(name, &exprs, &mut values)?;
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

    /// The parsed expression of parameter `name` and the names it uses.
    fn parse_param(
        &self,
        name: &str,
        exprs: &IndexMap<String, RawValue>,
    ) -> Result<PendingParam, ModelError> {
        let raw = &exprs[name];
        let expr = match &raw.value {
            toml::Value::Float(v) => Expr::Num(*v),
            toml::Value::Integer(i) => Expr::Num(*i as f64),
            toml::Value::String(s) => Expr::parse(s).map_err(|e| {
                self.err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!("parameter `{name}` = \"{}\": {e}", clip(s)),
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
        Ok(PendingParam {
            name: name.to_owned(),
            names: expr.names(),
            expr,
            next: 0,
        })
    }

    /// Evaluate parameter `root` and those it uses, depth first with an explicit stack (a
    /// chain of 100 000 parameters must not overflow the call stack).
    fn eval_param(
        &self,
        root: &str,
        exprs: &IndexMap<String, RawValue>,
        values: &mut IndexMap<String, f64>,
    ) -> Result<(), ModelError> {
        if values.contains_key(root) {
            return Ok(());
        }
        let mut stack = vec![self.parse_param(root, exprs)?];
        let mut on_stack: HashSet<String> = HashSet::from([root.to_owned()]);
        while let Some(top) = stack.last_mut() {
            if let Some(n) = top.names.get(top.next).cloned() {
                top.next += 1;
                if n == "pi" || values.contains_key(&n) {
                    continue;
                }
                let name = &top.name;
                if !exprs.contains_key(&n) {
                    return Err(self
                        .err(
                            ErrorKind::BadParameter,
                            Some(&exprs[name].span),
                            format!(
                                "parameter `{name}` uses `{}`, which is not a parameter",
                                clip(&n)
                            ),
                        )
                        .hint(format!(
                            "parameters may only use numbers and other parameters; known: {}",
                            clip(&exprs.keys().cloned().collect::<Vec<_>>().join(", "))
                        )));
                }
                if on_stack.contains(&n) {
                    let chain: Vec<&str> = stack.iter().map(|p| p.name.as_str()).collect();
                    return Err(self
                        .err(
                            ErrorKind::BadParameter,
                            Some(&exprs[&n].span),
                            clip(&format!(
                                "parameter `{n}` depends on itself: {} -> {n}",
                                chain.join(" -> ")
                            )),
                        )
                        .hint("break the cycle: give one of these parameters a number"));
                }
                on_stack.insert(n.clone());
                let p = self.parse_param(&n, exprs)?;
                stack.push(p);
                continue;
            }
            let Some(done) = stack.pop() else { break };
            on_stack.remove(&done.name);
            let span = &exprs[&done.name].span;
            let v = done
                .expr
                .eval(&|n| values.get(n).copied())
                .map_err(|m| self.err(ErrorKind::BadParameter, Some(span), m))?;
            if !v.is_finite() {
                return Err(self
                    .err(
                        ErrorKind::BadParameter,
                        Some(span),
                        format!("parameter `{}` is {v}, which is not finite", done.name),
                    )
                    .hint("check for division by zero, a negative square root or a typo"));
            }
            values.insert(done.name, v);
        }
        Ok(())
    }

    fn build_element(
        &self,
        def: &ElementDef,
        constants: &IndexMap<String, f64>,
    ) -> Result<(BuiltDef, HashSet<String>), ModelError> {
        let info = self.registry.get(&def.kind).ok_or_else(|| {
            let mut kinds: Vec<&str> = self.registry.kinds().map(|k| k.name).collect();
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
                format!("unknown element kind `{}`", clip(&def.kind)),
            )
            .element(&def.name)
            .hint(hint)
        })?;
        let used = RefCell::new(HashSet::new());
        let spec = ElementSpec::new(
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
        spec.validate().map_err(|e| spec.locate(e))?;
        let element = match info.build {
            bondgraph::kind::Build::Element(f) => {
                BuiltDef::One(f(&spec).map_err(|e| spec.locate(e))?)
            }
            bondgraph::kind::Build::Composite(f) => {
                BuiltDef::Many(f(&spec).map_err(|e| spec.locate(e))?)
            }
        };
        drop(spec);
        Ok((element, used.into_inner()))
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
                let x = c.expand(&def.name);
                let (members, bonds, ports) = (x.elements, x.bonds, x.ports);
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
    /// The scene switches the file declares (`[scene]`, [`crate::scene`]).
    pub scene: Scene,
    /// The steady state solved for the start (`[initial.steady]`), if the file asks for one.
    pub steady: Option<crate::steady::SteadyReport>,
    /// Notes from loading: things that load but were likely meant otherwise.
    notes: Vec<ModelError>,
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
    /// Notes: what loads but was likely meant otherwise ([`Model::notes`]).
    pub notes: Vec<ModelError>,
    /// The scene switches (`[scene]`).
    pub scene: Scene,
}

struct Parsed {
    spec: FileSpec,
    source: Source,
    parameters: IndexMap<String, f64>,
    scene: Scene,
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
        .hint("a model has the sections title, description, [parameters], [elements], [bonds], [simulation], [initial], [[events]], [outputs], [[check]], [scene], [[plot]]")
}

/// The lines (1-based) of `after` that differ from those of `before`.
fn changed_lines(before: &str, after: &str) -> Vec<usize> {
    if before == after {
        return Vec::new();
    }
    let old: Vec<&str> = before.lines().collect();
    after
        .lines()
        .enumerate()
        .filter(|(i, l)| old.get(*i) != Some(l))
        .map(|(i, _)| i + 1)
        .collect()
}

/// Say so when an error points at a line that `--set` wrote or changed.
fn mark_set_line(mut e: ModelError, changed: &[usize]) -> ModelError {
    if e.line.is_some_and(|l| changed.contains(&l)) {
        e.message
            .push_str(" (at a line written by --set: the file as changed by the overrides)");
    }
    e
}

/// Largest model file (and model text after `--set`), in bytes.
pub const MAX_FILE_BYTES: usize = 16 << 20;

/// Read a model file: at most [`MAX_FILE_BYTES`] (`/dev/zero` is refused, not read until
/// memory runs out), UTF-8 (an invalid byte is named with its line, column and offset).
fn read_model(path: &Path, file: &str) -> Result<String, ModelError> {
    use std::io::Read;
    let io = |e: std::io::Error| {
        ModelError::new(ErrorKind::Io, file, format!("cannot read: {e}")).hint("check the path")
    };
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES as u64 + 1).read_to_end(&mut bytes))
        .map_err(io)?;
    check_size(file, bytes.len())?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let valid = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        let pos = line_col(valid, valid.len());
        ModelError::new(
            ErrorKind::Syntax,
            file,
            format!(
                "not UTF-8 text: the byte at offset {at} (0x{:02x}) is not valid UTF-8",
                bytes.get(at).copied().unwrap_or(0)
            ),
        )
        .at(Some(pos))
        .hint("save the model as UTF-8")
    })
}

fn check_size(file: &str, len: usize) -> Result<(), ModelError> {
    if len > MAX_FILE_BYTES {
        return Err(ModelError::new(
            ErrorKind::Io,
            file,
            format!(
                "is larger than {} MiB, the limit for a model file",
                MAX_FILE_BYTES >> 20
            ),
        )
        .hint("a model file is text of a few kB; is this the right file?"));
    }
    Ok(())
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
    check_size(file, text.len())?;
    let original = text;
    let text = crate::overrides::apply(file, text, overrides)?;
    check_size(file, text.len())?;
    let changed_lines = changed_lines(original, &text);
    let spec: FileSpec = toml::from_str(&text)
        .map_err(|e| mark_set_line(syntax(file, &text, &e), &changed_lines))?;
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
        changed_lines,
        plots: Vec::new(),
    };
    source.plots = crate::plots::read(&text, &|span, m| source.err(ErrorKind::Plot, span, m))?;
    for (k, v) in &spec.parameters {
        if !valid_name(k.get_ref()) || RESERVED.contains(&k.get_ref().as_str()) {
            return Err(source
                .err(ErrorKind::BadParameter, Some(&k.span()), format!("`{}` cannot be a parameter name", clip(k.get_ref())))
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
                    format!("`{}` cannot be an element name", clip(n)),
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
    let scene = crate::scene::read(file, &text, &spec.scene, &|span, m| {
        source.err(ErrorKind::Scene, span, m)
    })?;
    Ok(Parsed {
        spec,
        source,
        parameters,
        scene,
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
                format!(
                    "`{}` is not of the form \"from -> to\"",
                    clip(text.get_ref())
                ),
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
            match finish(p, eqs) {
                Ok(m) => {
                    // the start as the model runs it: `[initial]` and a solved steady start
                    for (s, v) in out.states.iter_mut().zip(&m.x0) {
                        s.1 = *v;
                    }
                    out.notes = m.notes();
                    out.scene = m.scene;
                }
                Err(e) => out.problems.push(e),
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
        scene,
    } = p;
    // initial values
    let mut flat = Vec::new();
    let mut steady_spec = None;
    for (k, v) in &spec.initial {
        if k.get_ref() == "steady" && v.get_ref().is_table() {
            steady_spec = Some(v);
        } else {
            let mut one = SpannedMap::default();
            one.insert(k.clone(), v.clone());
            flatten("", &one, &mut flat);
        }
    }
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
                    format!("unknown solver `{}`", clip(s.get_ref())),
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
    // a steady start ([initial.steady], crate::steady), from the values above
    let steady = match steady_spec {
        None => None,
        Some(v) => {
            let x0 = eqs.initial_state();
            let report =
                crate::steady::solve(v.get_ref(), &eqs, &parameters, settings.t_start, &x0)
                    .map_err(|(message, hint)| {
                        let e = source.err(ErrorKind::Settings, Some(&v.span()), message);
                        match hint {
                            Some(h) => e.hint(h),
                            None => e,
                        }
                    })?;
            if let Some(r) = &report {
                for name in &r.kept {
                    if let Some(i) = eqs.states().iter().position(|s| &s.name == name) {
                        let value = r.solution.x[i];
                        eqs.set_initial(name, value)
                            .map_err(|e| source.err(ErrorKind::Settings, None, e.to_string()))?;
                    }
                }
            }
            report
        }
    };
    let (outputs, notes) = read_outputs(&spec.outputs, &source, &eqs)?;
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
                    format!("[[check]] {what} = \"{}\": {e}", clip(text.get_ref())),
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
        scene,
        steady,
        notes,
        source,
    };
    // events must build now, so that their errors show at load time
    model.events()?;
    Ok(model)
}

/// Longest output column name, in characters.
pub const MAX_COLUMN_NAME: usize = 100;

/// Whether `n` may name an output column: 1 to [`MAX_COLUMN_NAME`] characters, letters,
/// digits, `_`, `.`, `[`, `]`, starting with a letter or `_`; not `t`, `time` or `pi`. Such a
/// name needs no quoting in a CSV header and can be used in a `[[check]]`.
#[must_use]
pub fn valid_column_name(n: &str) -> bool {
    let mut c = n.chars();
    n.chars().count() <= MAX_COLUMN_NAME
        && !RESERVED.contains(&n)
        && c.next()
            .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || "_.[]".contains(ch))
}

/// `[outputs]` as columns (every state if the section is absent), and notes on outputs that
/// likely meant another variable: `p_hose = "hose.P"` reads the power, next to `hose.p`, the
/// pressure (a column whose name starts with `P` or says `power` is taken to mean a power).
fn read_outputs(
    spec: &SpannedMap<String>,
    source: &Source,
    eqs: &StateEquations,
) -> Result<(Vec<Output>, Vec<ModelError>), ModelError> {
    let mut outputs = Vec::new();
    let mut notes = Vec::new();
    if spec.is_empty() {
        for (i, s) in eqs.states().iter().enumerate() {
            outputs.push(Output {
                name: s.name.clone(),
                probe: bondgraph::Probe::State(i),
            });
        }
        return Ok((outputs, notes));
    }
    let names = eqs.probe_names();
    for (col, name) in spec {
        if !valid_column_name(col.get_ref()) {
            return Err(source
                .err(
                    ErrorKind::Settings,
                    Some(&col.span()),
                    format!("[outputs] `{}` cannot be a column name", clip(col.get_ref())),
                )
                .hint(format!("column names are 1 to {MAX_COLUMN_NAME} letters, digits, `_`, `.`, `[`, `]`, starting with a letter or `_`; `t` is the first column already, `time` and `pi` are reserved")));
        }
        let probe = eqs.probe(name.get_ref()).ok_or_else(|| {
            let el = name.get_ref().split('.').next().unwrap_or("");
            let offers: Vec<&String> = names
                .iter()
                .filter(|n| n.starts_with(&format!("{el}.")))
                .take(16)
                .collect();
            let offers: Vec<&str> = offers.iter().map(|s| s.as_str()).collect();
            source.err(ErrorKind::Settings, Some(&name.span()), format!("[outputs] `{}`: nothing is called `{}`", col.get_ref(), clip(name.get_ref()))).hint(if offers.is_empty() {
                "outputs name a state (`mass.p`), its derivative (`mass.p.dot`), a signal (`ctrl.out`) or a bond variable (`mass.e`, `mass.f`, `b3.P`, `lever.2.e`)".to_owned()
            } else {
                format!("`{}` offers: {}", clip(el), offers.join(", "))
            })
        })?;
        // A power read into a column whose name does not say so (or the reverse), where a
        // variable differing only in case exists: likely the other was meant.
        let col_says_power =
            col.get_ref().starts_with('P') || col.get_ref().to_ascii_lowercase().contains("power");
        let is_power = matches!(probe, bondgraph::Probe::Power(_));
        let other = names
            .iter()
            .find(|n| *n != name.get_ref() && n.eq_ignore_ascii_case(name.get_ref()));
        if let Some(other) = other.filter(|_| col_says_power != is_power) {
            let what = |p: Option<bondgraph::Probe>| match p {
                Some(bondgraph::Probe::State(_)) => "a state",
                Some(bondgraph::Probe::Derivative(_)) => "a state's derivative",
                Some(bondgraph::Probe::Effort(_)) => "an effort",
                Some(bondgraph::Probe::Flow(_)) => "a flow",
                Some(bondgraph::Probe::Signal(_)) => "a signal",
                Some(bondgraph::Probe::Power(_)) => "a power (e·f)",
                _ => "a variable",
            };
            notes.push(
                source
                    .err(
                        ErrorKind::Settings,
                        Some(&name.span()),
                        format!(
                            "[outputs] `{}` reads `{}`, {}; `{other}` is {}: names differ in case",
                            col.get_ref(),
                            name.get_ref(),
                            what(Some(probe)),
                            what(eqs.probe(other))
                        ),
                    )
                    .hint(format!(
                        "if you meant {}, write `{other}`",
                        what(eqs.probe(other))
                    )),
            );
        }
        outputs.push(Output {
            name: col.get_ref().clone(),
            probe,
        });
    }
    Ok((outputs, notes))
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
        let text = read_model(path, &file)?;
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

    /// The figures the file declares (`[[plot]]`, [`crate::plots`]).
    #[must_use]
    pub fn plots(&self) -> &[crate::plots::Plot] {
        &self.source.plots
    }

    /// The file the model came from.
    #[must_use]
    pub fn file(&self) -> &str {
        &self.source.file
    }

    /// What loads but was likely meant otherwise, for the current settings: an output that
    /// differs only in case from another variable, events before `t_start` (applied at the
    /// start) or after `t_end` (not reached).
    #[must_use]
    pub fn notes(&self) -> Vec<ModelError> {
        let mut notes = self.notes.clone();
        let s = &self.settings;
        for ev in &self.source.events {
            let when = if ev.t < s.t_start {
                format!(
                    "before t_start = {} s: it is applied at the start",
                    s.t_start
                )
            } else if ev.t > s.t_end {
                format!("after t_end = {} s: it is not reached", s.t_end)
            } else {
                continue;
            };
            notes.push(self.source.err(
                ErrorKind::Settings,
                Some(&ev.span),
                format!("the event at t = {} s is {when}", ev.t),
            ));
        }
        notes
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

    /// Run the model with its settings and keep the rows in memory; the elements are
    /// restored afterwards, so the model can run again. The rows are bounded
    /// ([`bondgraph::MAX_VALUES_IN_MEMORY`]); [`Model::run_into`] streams them instead.
    pub fn run(&mut self) -> Result<bondgraph::Outcome, ModelError> {
        self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate(eqs, x0, s, outputs, events)
        })
    }

    /// Run the model, handing each output row to `sink` as it is computed, and evaluate the
    /// `[[check]]`s at every output row and every accepted solver step (a check must hold
    /// between the rows too). The elements are restored afterwards.
    pub fn run_into(
        &mut self,
        sink: &mut dyn bondgraph::RowSink,
    ) -> Result<(bondgraph::Outcome, Vec<CheckResult>), ModelError> {
        let mut checker = CheckSink::new(self, sink)?;
        let out = self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate_into(eqs, x0, s, outputs, events, &mut checker)
        })?;
        let results = checker.results(&self.checks);
        Ok((out, results))
    }

    /// [`Model::run_into`] keeping the rows in memory (in `trajectory.rows`), bounded as
    /// [`Model::run`].
    pub fn run_checked(&mut self) -> Result<(bondgraph::Outcome, Vec<CheckResult>), ModelError> {
        bondgraph::check_in_memory(&self.settings, self.outputs.len() + 1).map_err(|e| {
            self.source
                .err(ErrorKind::Settings, None, format!("[simulation] {e}"))
        })?;
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let (mut out, checks) = self.run_into(&mut rows)?;
        out.trajectory.rows = rows;
        Ok((out, checks))
    }

    /// Run `simulate` with the model's events, then restore the elements the events replaced.
    fn run_events(
        &mut self,
        simulate: impl FnOnce(
            &mut StateEquations,
            &[f64],
            &Settings,
            &[Output],
            Vec<Event>,
        ) -> bondgraph::Outcome,
    ) -> Result<bondgraph::Outcome, ModelError> {
        let events = self.events()?;
        let has_events = !events.is_empty();
        let out = simulate(
            &mut self.equations,
            &self.x0,
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

    /// Compare a trajectory with the model's `[[check]]`s at its output rows only (a sample:
    /// [`Model::run_into`] checks every accepted step too).
    #[must_use]
    pub fn verify(&self, traj: &bondgraph::Trajectory) -> Vec<CheckResult> {
        self.checks
            .iter()
            .map(|c| {
                let mut worst = Worst::NONE;
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
                    worst.add(t, err);
                }
                worst.result(c, traj.rows.len(), false)
            })
            .collect()
    }
}
