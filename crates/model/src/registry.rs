//! [`Registry`]: element kinds by name, each with a builder that reads its parameters from a
//! model file through an [`ElementSpec`]. Domain crates add their kinds
//! (`registry.register("hydraulics.chamber", …)`) without touching the loader.

use std::cell::RefCell;
use std::collections::HashSet;
use std::ops::Range;

use bondgraph::{Element, Param, ParamError};
use indexmap::IndexMap;

use crate::error::{line_col, ErrorKind, ModelError};
use crate::expr::{Compiled, Expr};

/// Builds an element from its parameters.
pub type BuildFn = fn(&ElementSpec<'_>) -> Result<Box<dyn Element>, ModelError>;

/// Builds a composite (a sub-graph) from its parameters.
pub type CompositeFn = fn(&ElementSpec<'_>) -> Result<Composite, ModelError>;

/// A sub-graph that one model-file entry expands into: a cylinder with its chambers, pistons
/// and leakage; a manipulator with its fields.
///
/// Members are named locally (`piston_chamber`); in the model they become
/// `<instance>_<local>` (`cyl1_piston_chamber`), so `bg-sim check` lists them all and their
/// states and signals are addressed as `cyl1_piston_chamber.p`. Use
/// [`ElementSpec::member`] to form those global names inside signal references.
#[derive(Debug, Default)]
pub struct Composite {
    /// Members: local name and element.
    pub elements: Vec<(String, Box<dyn Element>)>,
    /// Internal bonds: local bond name, from and to as `local` or `local.port`.
    pub bonds: Vec<(String, String, String)>,
    /// Exposed ports: the name the model file uses (`cyl1.mech`) and the member port it
    /// stands for (`local` or `local.port`), which must be left unbonded inside.
    pub ports: Vec<(String, String)>,
}

impl Composite {
    /// Add a member.
    pub fn element(&mut self, local: &str, element: impl Element + 'static) -> &mut Self {
        self.elements.push((local.to_owned(), Box::new(element)));
        self
    }
    /// Add an internal bond `from -> to` (local names, `name.port` for a port).
    pub fn bond(&mut self, name: &str, from: &str, to: &str) -> &mut Self {
        self.bonds
            .push((name.to_owned(), from.to_owned(), to.to_owned()));
        self
    }
    /// Expose the member port `inner` as `name`.
    pub fn port(&mut self, name: &str, inner: &str) -> &mut Self {
        self.ports.push((name.to_owned(), inner.to_owned()));
        self
    }
}

/// How a kind is built.
#[derive(Clone, Copy, Debug)]
pub enum Builder {
    /// One element.
    Element(BuildFn),
    /// A sub-graph.
    Composite(CompositeFn),
}

/// A registered element kind.
#[derive(Clone, Debug)]
pub struct KindInfo {
    /// The builder.
    pub build: Builder,
    /// One line for `bg-sim kinds` and error hints.
    pub summary: &'static str,
}

/// Element kinds by name.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    kinds: IndexMap<String, KindInfo>,
}

impl Registry {
    /// An empty registry.
    #[must_use]
    pub fn empty() -> Self {
        Self::default()
    }

    /// The core kinds: `Se Sf R C I TF MTF GY MGY 0 1 lag p_control signal`.
    #[must_use]
    pub fn with_core() -> Self {
        let mut r = Self::empty();
        crate::builtin::register(&mut r);
        r
    }

    /// Register `kind`; a later registration of the same name replaces the earlier one.
    pub fn register(&mut self, kind: &str, summary: &'static str, build: BuildFn) {
        self.kinds.insert(
            kind.to_owned(),
            KindInfo {
                build: Builder::Element(build),
                summary,
            },
        );
    }

    /// Register a composite `kind` that expands into a sub-graph ([`Composite`]).
    pub fn register_composite(&mut self, kind: &str, summary: &'static str, build: CompositeFn) {
        self.kinds.insert(
            kind.to_owned(),
            KindInfo {
                build: Builder::Composite(build),
                summary,
            },
        );
    }

    /// The kind called `kind`.
    #[must_use]
    pub fn get(&self, kind: &str) -> Option<&KindInfo> {
        self.kinds.get(kind)
    }

    /// All kinds with their summaries.
    pub fn kinds(&self) -> impl Iterator<Item = (&str, &KindInfo)> {
        self.kinds.iter().map(|(k, v)| (k.as_str(), v))
    }
}

/// Whether `a` looks like a misspelling of `b`: same ignoring case, one a prefix of the
/// other, or at most one edit apart.
pub(crate) fn similar(a: &str, b: &str) -> bool {
    if a.eq_ignore_ascii_case(b) || (a.len() > 1 && b.starts_with(a)) || a.starts_with(b) {
        return true;
    }
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    if a.len().abs_diff(b.len()) > 1 {
        return false;
    }
    // Levenshtein distance ≤ 1
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()] <= 1
}

/// A parameter value as written in the file, with its byte span.
#[derive(Clone, Debug)]
pub struct RawValue {
    /// The TOML value.
    pub value: toml::Value,
    /// Byte range in the file.
    pub span: Range<usize>,
}

/// What a builder sees: the element's name, kind and parameters, and the model's named
/// parameters. Reading a key marks it used; keys nobody read are reported as unknown.
pub struct ElementSpec<'a> {
    /// Element name.
    pub name: &'a str,
    /// Element kind.
    pub kind: &'a str,
    pub(crate) params: &'a IndexMap<String, RawValue>,
    pub(crate) constants: &'a IndexMap<String, f64>,
    pub(crate) file: &'a str,
    pub(crate) text: &'a str,
    pub(crate) name_span: Range<usize>,
    pub(crate) asked: RefCell<Vec<String>>,
    pub(crate) used_constants: RefCell<HashSet<String>>,
}

impl ElementSpec<'_> {
    fn ask(&self, key: &str) -> Option<&RawValue> {
        let mut asked = self.asked.borrow_mut();
        if !asked.iter().any(|k| k == key) {
            asked.push(key.to_owned());
        }
        self.params.get(key)
    }

    /// A positioned error about parameter `key` (or the element if the key is absent).
    #[must_use]
    pub fn error(&self, key: &str, kind: ErrorKind, message: impl Into<String>) -> ModelError {
        let span = self
            .params
            .get(key)
            .map_or(self.name_span.start, |v| v.span.start);
        ModelError::new(kind, self.file, message)
            .at(Some(line_col(self.text, span)))
            .element(self.name)
    }

    /// Turn an element constructor's [`ParamError`] into a positioned error.
    #[must_use]
    pub fn param_error(&self, e: &ParamError) -> ModelError {
        let key = match e {
            ParamError::OutOfRange { param, .. } | ParamError::Shape { param, .. } => {
                param.as_str()
            }
            _ => "",
        };
        self.error(key, ErrorKind::BadParameter, format!("({}) {e}", self.kind))
            .hint(format!("fix `{key}` of `{}`", self.name))
    }

    /// The global name of member `local` of this composite: `<instance>_<local>`.
    #[must_use]
    pub fn member(&self, local: &str) -> String {
        format!("{}_{local}", self.name)
    }

    /// The raw TOML value of `key`, for builders that read nested tables or arrays themselves
    /// (report problems with [`error`](Self::error) on the same key).
    #[must_use]
    pub fn raw(&self, key: &str) -> Option<&toml::Value> {
        self.ask(key).map(|r| &r.value)
    }

    /// Whether `key` is given.
    #[must_use]
    pub fn has(&self, key: &str) -> bool {
        self.ask(key).is_some()
    }

    fn missing(&self, key: &str, what: &str) -> ModelError {
        // A key nobody asked for that looks like this one is probably a misspelling of it.
        let asked = self.asked.borrow();
        let typo = self
            .params
            .keys()
            .find(|k| !asked.contains(k) && similar(k, key));
        match typo {
            Some(t) => self
                .error(
                    t,
                    ErrorKind::MissingParameter,
                    format!(
                        "({}) needs parameter `{key}` ({what}); it has `{t}` instead",
                        self.kind
                    ),
                )
                .hint(format!("did you mean `{key}`? rename `{t}` to `{key}`")),
            None => self
                .error(
                    key,
                    ErrorKind::MissingParameter,
                    format!("({}) needs parameter `{key}` ({what})", self.kind),
                )
                .hint(format!("add `{key} = …` to element `{}`", self.name)),
        }
    }

    /// Parse `key`'s value as an expression (a TOML number is a constant expression).
    fn expr(&self, key: &str, raw: &RawValue) -> Result<Expr, ModelError> {
        match &raw.value {
            toml::Value::Float(v) => Ok(Expr::Num(*v)),
            toml::Value::Integer(i) => Ok(Expr::Num(*i as f64)),
            toml::Value::String(s) => Expr::parse(s).map_err(|e| {
                self.error(key, ErrorKind::BadParameter, format!("cannot read `{key}` = \"{}\": {e}", crate::error::clip(s)))
                    .hint("expressions use numbers, parameters, signals like `spring.q`, `t`, + - * / ^ and functions such as sqrt, sin, exp, min, max")
            }),
            other => Err(self.error(key, ErrorKind::BadParameter, format!("`{key}` must be a number or an expression string, not {}", other.type_str()))),
        }
    }

    fn constant_of(&self, key: &str, e: &Expr) -> Result<f64, ModelError> {
        for n in e.names() {
            if self.constants.contains_key(&n) {
                self.used_constants.borrow_mut().insert(n);
            }
        }
        let v = e.eval(&|n| self.constants.get(n).copied()).map_err(|m| {
            self.error(key, ErrorKind::BadParameter, format!("`{key}`: {m}"))
                .hint(format!(
                    "`{key}` must be constant: use numbers and names from [parameters] ({})",
                    self.constants
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
        })?;
        if !v.is_finite() {
            return Err(self
                .error(
                    key,
                    ErrorKind::BadParameter,
                    format!("`{key}` evaluates to {v}, which is not finite"),
                )
                .hint("check for division by zero or a typo"));
        }
        Ok(v)
    }

    /// A required constant number.
    pub fn number(&self, key: &str, what: &str) -> Result<f64, ModelError> {
        let raw = self.ask(key).ok_or_else(|| self.missing(key, what))?;
        let e = self.expr(key, raw)?;
        self.constant_of(key, &e)
    }

    /// An optional constant number.
    pub fn number_or(&self, key: &str, default: f64) -> Result<f64, ModelError> {
        match self.ask(key) {
            None => Ok(default),
            Some(raw) => {
                let e = self.expr(key, raw)?;
                self.constant_of(key, &e)
            }
        }
    }

    /// A required parameter that may be modulated: names that are not model parameters are
    /// signals (`spring.q`, `t`), read at run time.
    pub fn param(&self, key: &str, what: &str) -> Result<Param, ModelError> {
        let raw = self.ask(key).ok_or_else(|| self.missing(key, what))?;
        self.param_of(key, raw)
    }

    /// An optional parameter that may be modulated.
    pub fn param_or(&self, key: &str, default: f64) -> Result<Param, ModelError> {
        match self.ask(key) {
            None => Ok(Param::Const(default)),
            Some(raw) => self.param_of(key, raw),
        }
    }

    fn param_of(&self, key: &str, raw: &RawValue) -> Result<Param, ModelError> {
        let e = self.expr(key, raw)?;
        let (compiled, inputs) = self.compile(key, &e)?;
        if let Some(v) = compiled.constant() {
            if !v.is_finite() {
                return Err(self.error(
                    key,
                    ErrorKind::BadParameter,
                    format!("`{key}` evaluates to {v}, which is not finite"),
                ));
            }
            return Ok(Param::Const(v));
        }
        Ok(Param::modulated(inputs, move |_, u| compiled.eval(u)))
    }

    /// Builders gather a law's inputs in a fixed buffer of `MAX_PARAM_INPUTS`.
    fn check_input_count(&self, key: &str, n: usize) -> Result<(), ModelError> {
        let max = bondgraph::element::MAX_PARAM_INPUTS;
        if n > max {
            return Err(self.error(
                key,
                ErrorKind::BadParameter,
                format!("`{key}` reads {n} signals; at most {max}"),
            ));
        }
        Ok(())
    }

    /// Compile an expression: model parameters become constants, other names signal inputs.
    pub fn compile(&self, key: &str, e: &Expr) -> Result<(Compiled, Vec<String>), ModelError> {
        let mut inputs = Vec::new();
        for n in e.names() {
            if n == "pi" {
                continue;
            }
            if self.constants.contains_key(&n) {
                self.used_constants.borrow_mut().insert(n);
            } else if n == "t" || n == "time" || n.contains('.') {
                inputs.push(n);
            } else {
                return Err(self
                    .error(key, ErrorKind::BadParameter, format!("`{key}` uses `{n}`, which is neither a parameter nor a signal"))
                    .hint(format!("define `{n}` in [parameters], or name a signal as `<element>.<variable>`; parameters: {}", self.constants.keys().cloned().collect::<Vec<_>>().join(", "))));
            }
        }
        self.check_input_count(key, inputs.len())?;
        let c = e
            .compile(&|n| self.constants.get(n).copied(), &inputs)
            .map_err(|m| self.error(key, ErrorKind::BadParameter, m))?;
        Ok((c, inputs))
    }

    /// A required expression, compiled (for builders that evaluate it themselves).
    pub fn expression(&self, key: &str, what: &str) -> Result<(Compiled, Vec<String>), ModelError> {
        let raw = self.ask(key).ok_or_else(|| self.missing(key, what))?;
        let e = self.expr(key, raw)?;
        self.compile(key, &e)
    }

    /// A constant vector: an array of numbers/expressions, or one number (length 1).
    pub fn vector_or(&self, key: &str, default: Vec<f64>) -> Result<Vec<f64>, ModelError> {
        match self.ask(key) {
            None => Ok(default),
            Some(raw) => match &raw.value {
                toml::Value::Array(items) => items
                    .iter()
                    .map(|v| {
                        let e = self.expr(
                            key,
                            &RawValue {
                                value: v.clone(),
                                span: raw.span.clone(),
                            },
                        )?;
                        self.constant_of(key, &e)
                    })
                    .collect(),
                _ => Ok(vec![self.constant_of(key, &self.expr(key, raw)?)?]),
            },
        }
    }

    /// A matrix of expressions (array of equal-length arrays), compiled with shared inputs.
    pub fn matrix(
        &self,
        key: &str,
        what: &str,
    ) -> Result<(usize, usize, Vec<String>, Vec<Compiled>), ModelError> {
        let raw = self.ask(key).ok_or_else(|| self.missing(key, what))?;
        let shape_err = || {
            self.error(
                key,
                ErrorKind::BadParameter,
                format!(
                    "`{key}` must be an array of rows of equal length, e.g. [[1, 0], [0, \"x.q\"]]"
                ),
            )
        };
        let toml::Value::Array(rows) = &raw.value else {
            return Err(shape_err());
        };
        let mut exprs = Vec::new();
        let mut cols = None;
        for row in rows {
            let toml::Value::Array(r) = row else {
                return Err(shape_err());
            };
            if cols.is_some_and(|c| c != r.len()) || r.is_empty() {
                return Err(shape_err());
            }
            cols = Some(r.len());
            for v in r {
                exprs.push(self.expr(
                    key,
                    &RawValue {
                        value: v.clone(),
                        span: raw.span.clone(),
                    },
                )?);
            }
        }
        let (n1, n2) = (rows.len(), cols.unwrap_or(0));
        if n1 == 0 {
            return Err(shape_err());
        }
        let mut inputs: Vec<String> = Vec::new();
        for e in &exprs {
            for n in e.names() {
                if !self.constants.contains_key(&n) && n != "pi" && !inputs.contains(&n) {
                    inputs.push(n);
                }
            }
        }
        self.check_input_count(key, inputs.len())?;
        let compiled = exprs
            .iter()
            .map(|e| {
                for n in e.names() {
                    if self.constants.contains_key(&n) {
                        self.used_constants.borrow_mut().insert(n);
                    }
                }
                e.compile(&|n| self.constants.get(n).copied(), &inputs)
                    .map_err(|m| self.error(key, ErrorKind::BadParameter, m))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok((n1, n2, inputs, compiled))
    }

    /// A required string naming a signal (`"rod.l"`, `"t"`).
    pub fn signal(&self, key: &str, what: &str) -> Result<String, ModelError> {
        let raw = self.ask(key).ok_or_else(|| self.missing(key, what))?;
        match &raw.value {
            toml::Value::String(s) if !s.trim().is_empty() => Ok(s.trim().to_owned()),
            _ => Err(self.error(
                key,
                ErrorKind::BadParameter,
                format!("`{key}` must name a signal, e.g. \"spring.q\""),
            )),
        }
    }

    /// An optional string.
    pub fn string_or(&self, key: &str, default: &str) -> Result<String, ModelError> {
        match self.ask(key) {
            None => Ok(default.to_owned()),
            Some(RawValue {
                value: toml::Value::String(s),
                ..
            }) => Ok(s.clone()),
            Some(_) => Err(self.error(
                key,
                ErrorKind::BadParameter,
                format!("`{key}` must be a string"),
            )),
        }
    }

    /// Keys given but never read, and the keys that were read.
    pub(crate) fn unused(&self) -> (Vec<String>, Vec<String>) {
        let asked = self.asked.borrow().clone();
        let unused = self
            .params
            .keys()
            .filter(|k| !asked.contains(k))
            .cloned()
            .collect();
        (unused, asked)
    }
}
