//! [`ElementSpec`]: one model-file entry's parameters, read by their kind's declarations
//! ([`bondgraph::kind`]). It is the loader's side of [`Params`]: defaults and ranges come
//! from the [`ParamDecl`]s, expressions are evaluated against the model's `[parameters]`,
//! values may carry a unit (`"200 bar"`), and every problem becomes a [`BuildError`] naming
//! the parameter, which [`ElementSpec::locate`] turns into a [`ModelError`] at its line.

use std::cell::RefCell;
use std::collections::HashSet;
use std::ops::Range;

use bondgraph::kind::{
    self, units, BuildError, BuildErrorKind, Default, ParamDecl, ParamType, Params,
};
use indexmap::IndexMap;

use crate::error::{clip, line_col, ErrorKind, ModelError};
use crate::expr::{Compiled, Expr};
use crate::tables::Tables;
use std::sync::Arc;

mod params;

/// A parameter value as written in the file, with its byte span.
#[derive(Clone, Debug)]
pub struct RawValue {
    /// The TOML value.
    pub value: toml::Value,
    /// Byte range in the file.
    pub span: Range<usize>,
}

/// One entry's parameters as its builder sees them (see the module documentation).
pub struct ElementSpec<'a> {
    /// Element name.
    pub name: &'a str,
    /// Element kind.
    pub kind: &'a str,
    pub(crate) decls: &'static [ParamDecl],
    pub(crate) params: IndexMap<String, RawValue>,
    pub(crate) constants: &'a IndexMap<String, f64>,
    pub(crate) file: &'a str,
    pub(crate) text: &'a str,
    pub(crate) name_span: Range<usize>,
    /// Where a nested table sits (`links[2]`); empty at the top.
    pub(crate) path: String,
    pub(crate) used_constants: &'a RefCell<HashSet<String>>,
    /// The model's `[inputs]`: bare names read as signals.
    pub(crate) inputs: &'a [String],
    /// The model's `[tables]`, callable in expressions.
    pub(crate) tables: Arc<Tables>,
    /// The `[inputs]` whose time derivatives are known, for [`Params::motion`].
    pub(crate) motions: Arc<IndexMap<String, bondgraph::Motion>>,
}

fn kind_of(e: &BuildError) -> ErrorKind {
    match e.kind {
        BuildErrorKind::Missing => ErrorKind::MissingParameter,
        BuildErrorKind::Unknown => ErrorKind::ExtraParameter,
        _ => ErrorKind::BadParameter,
    }
}

impl<'a> ElementSpec<'a> {
    /// The entry's parameters (top level), before they are checked against `decls`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        name: &'a str,
        kind: &'a str,
        decls: &'static [ParamDecl],
        params: IndexMap<String, RawValue>,
        constants: &'a IndexMap<String, f64>,
        file: &'a str,
        text: &'a str,
        name_span: Range<usize>,
        used_constants: &'a RefCell<HashSet<String>>,
    ) -> Self {
        Self {
            name,
            kind,
            decls,
            params,
            constants,
            file,
            text,
            name_span,
            path: String::new(),
            used_constants,
            inputs: &[],
            tables: Arc::new(Tables::default()),
            motions: Arc::default(),
        }
    }

    /// `key` with this table's place in front (`links[2].length`).
    fn full(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_owned()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// An error about `key`; inside a nested table the message names the key by its path
    /// (`links[3].type`).
    fn err(&self, kind: BuildErrorKind, key: &str, message: impl Into<String>) -> BuildError {
        let full = self.full(key);
        let mut message = message.into();
        if !self.path.is_empty() {
            message = message.replace(&format!("`{key}`"), &format!("`{full}`"));
        }
        BuildError::new(kind, Some(&full), message)
    }

    fn decl(&self, key: &str) -> Result<&'static ParamDecl, BuildError> {
        self.decls.iter().find(|d| d.name == key).ok_or_else(|| {
            self.err(
                BuildErrorKind::Undeclared,
                key,
                format!(
                    "the builder of `{}` reads `{key}`, which the kind does not declare",
                    self.kind
                ),
            )
            .hint("this is a bug in the element kind: declare the parameter in its table")
        })
    }

    /// Check the given keys against the declarations: unknown keys (with a suggestion),
    /// required keys, and every given value's type and range.
    pub(crate) fn validate(&self) -> Result<(), BuildError> {
        let declared = || self.decls.iter().map(|d| d.name);
        for key in self.params.keys() {
            if self.decls.iter().any(|d| d.name == key) {
                continue;
            }
            let takes = if self.decls.is_empty() {
                "it takes none".to_owned()
            } else {
                format!("it takes: {}", declared().collect::<Vec<_>>().join(", "))
            };
            let hint =
                match kind::suggest(key, declared().filter(|d| !self.params.contains_key(*d))) {
                    Some(s) => format!("did you mean `{s}`? {takes}"),
                    None => takes,
                };
            let message = if self.path.is_empty() {
                format!("has no parameter `{}`", clip(key))
            } else {
                format!("`{}` has an unknown key `{}`", self.path, clip(key))
            };
            return Err(
                BuildError::new(BuildErrorKind::Unknown, Some(&self.full(key)), message).hint(hint),
            );
        }
        for d in self.decls {
            if d.required() && !self.params.contains_key(d.name) {
                return Err(self.missing(d));
            }
        }
        for key in self.params.keys() {
            let d = self.decl(key)?;
            match d.ty {
                ParamType::Number => self.number(key).map(drop)?,
                ParamType::Modulated => self.modulated(key).map(drop)?,
                ParamType::Count => self.count(key).map(drop)?,
                ParamType::Signal => self.signal(key).map(drop)?,
                ParamType::Flag => self.flag(key).map(drop)?,
                ParamType::Choice(_) => self.word(key).map(drop)?,
                ParamType::Vector => self.vector(key).map(drop)?,
                ParamType::Matrix | ParamType::Table(_) | ParamType::Tables(_) => {}
            }
        }
        Ok(())
    }

    fn missing(&self, d: &ParamDecl) -> BuildError {
        let unit = if d.unit.is_empty() || d.unit == "1" {
            String::new()
        } else {
            format!(", {}", d.unit)
        };
        let what = format!("{}{unit}", d.doc);
        // A given key nobody declared that looks like this one is probably a misspelling.
        if let Some(t) = self
            .params
            .keys()
            .find(|k| !self.decls.iter().any(|d| d.name == k.as_str()) && kind::similar(k, d.name))
        {
            return self
                .err(
                    BuildErrorKind::Missing,
                    t,
                    format!(
                        "needs parameter `{}` ({what}); it has `{t}` instead",
                        d.name
                    ),
                )
                .hint(format!(
                    "did you mean `{}`? rename `{t}` to `{}`",
                    d.name, d.name
                ));
        }
        self.err(
            BuildErrorKind::Missing,
            d.name,
            format!("needs parameter `{}` ({what})", d.name),
        )
        .hint(format!("add `{} = …` to element `{}`", d.name, self.name))
    }

    /// Parse a value as an expression, with its unit converted to the declared one.
    fn expr(&self, d: &ParamDecl, value: &toml::Value) -> Result<Expr, BuildError> {
        let key = d.name;
        match value {
            toml::Value::Float(v) => Ok(Expr::Num(*v)),
            toml::Value::Integer(i) => Ok(Expr::Num(*i as f64)),
            toml::Value::String(s) => {
                if let Some((body, unit)) = units::split_value(s) {
                    if let Ok(e) = Expr::parse_with(body, &self.tables.signatures()) {
                        let Some(want) = units::parse(d.unit) else {
                            return Err(self.err(BuildErrorKind::WrongUnit, key, format!("`{key}` is given with a unit, but its unit `{}` cannot be converted", d.unit))
                                .hint(format!("write `{key}` as a number in {}", d.unit)));
                        };
                        if want.dim != unit.dim {
                            return Err(self
                                .err(
                                    BuildErrorKind::WrongUnit,
                                    key,
                                    format!(
                                        "`{key}` is a {} ({}), but \"{}\" is a {}",
                                        units::describe(want.dim),
                                        d.unit,
                                        clip(s),
                                        units::describe(unit.dim)
                                    ),
                                )
                                .hint(format!(
                                    "give `{key}` in {} or a unit of the same kind",
                                    d.unit
                                )));
                        }
                        let scale = unit.scale / want.scale;
                        return Ok(Expr::Bin('*', Box::new(Expr::Num(scale)), Box::new(e)));
                    }
                }
                Expr::parse_with(s, &self.tables.signatures()).map_err(|e| {
                    self.err(BuildErrorKind::Invalid, key, format!("cannot read `{key}` = \"{}\": {e}", clip(s)))
                        .hint("expressions use numbers, parameters, signals like `spring.q`, `t`, + - * / ^ and functions such as sqrt, sin, exp, min, max; a unit may follow after a space (\"200 bar\")")
                })
            }
            other => Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!(
                    "`{key}` must be a number or an expression string, not {}",
                    other.type_str()
                ),
            )),
        }
    }

    fn note_constants(&self, e: &Expr) {
        for n in e.names() {
            if self.constants.contains_key(&n) {
                self.used_constants.borrow_mut().insert(n);
            }
        }
    }

    fn constant(&self, d: &ParamDecl, e: &Expr) -> Result<f64, BuildError> {
        let key = d.name;
        self.note_constants(e);
        let v = e
            .compile_with(&|n| self.constants.get(n).copied(), &[], &self.tables)
            .map(|c| c.constant().unwrap_or(f64::NAN))
            .map_err(|m| {
                self.err(BuildErrorKind::Invalid, key, format!("`{key}`: {m}"))
                    .hint(format!(
                        "`{key}` must be constant: use numbers and names from [parameters] ({})",
                        clip(
                            &self
                                .constants
                                .keys()
                                .cloned()
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    ))
            })?;
        self.in_range(d, v)
    }

    fn in_range(&self, d: &ParamDecl, v: f64) -> Result<f64, BuildError> {
        if d.range.contains(v) {
            return Ok(v);
        }
        let unit = if d.unit.is_empty() || d.unit == "1" {
            String::new()
        } else {
            format!(" {}", d.unit)
        };
        Err(self
            .err(
                BuildErrorKind::Invalid,
                d.name,
                format!(
                    "`{}` = {v} is out of range: it must be {}{unit}",
                    d.name, d.range
                ),
            )
            .hint(format!(
                "fix `{}` of `{}`: it is the {}",
                d.name, self.name, d.doc
            )))
    }

    fn raw(&self, key: &str) -> Option<&toml::Value> {
        self.params.get(key).map(|r| &r.value)
    }

    /// Compile an expression: model parameters become constants, other names signal inputs
    /// (and the declared `variable` of a function, e.g. `x` along a link, an input too).
    fn compile(
        &self,
        key: &str,
        e: &Expr,
        variable: Option<&str>,
    ) -> Result<(Compiled, Vec<String>), BuildError> {
        let mut inputs = Vec::new();
        for n in e.names() {
            if n == "pi" {
                continue;
            }
            if self.constants.contains_key(&n) {
                self.used_constants.borrow_mut().insert(n);
            } else if n == "t"
                || n == "time"
                || n.contains('.')
                || self.inputs.contains(&n)
                || variable == Some(n.as_str())
            {
                if !inputs.contains(&n) {
                    inputs.push(n);
                }
            } else {
                return Err(self
                    .err(BuildErrorKind::Invalid, key, format!("`{key}` uses `{n}`, which is neither a parameter nor a signal"))
                    .hint(format!("{}define `{n}` in [parameters] or [inputs], or name a signal as `<element>.<variable>`; parameters: {}", variable.map(|v| format!("`{key}` is an expression of `{v}`; ")).unwrap_or_default(), clip(&self.constants.keys().cloned().collect::<Vec<_>>().join(", ")))));
            }
        }
        let max = bondgraph::element::MAX_PARAM_INPUTS;
        if inputs.len() > max {
            return Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` reads {} signals; at most {max}", inputs.len()),
            ));
        }
        let c = e
            .compile_with(&|n| self.constants.get(n).copied(), &inputs, &self.tables)
            .map_err(|m| self.err(BuildErrorKind::Invalid, key, m))?;
        Ok((c, inputs))
    }

    fn default_number(&self, d: &ParamDecl) -> Result<Option<f64>, BuildError> {
        match d.default {
            Default::Value(v) => Ok(Some(v)),
            Default::Optional(_) => Ok(None),
            Default::Required => Err(self.missing(d)),
            Default::Word(_) | Default::Flag(_) => Err(self.type_error(d)),
        }
    }

    fn type_error(&self, d: &ParamDecl) -> BuildError {
        self.err(
            BuildErrorKind::Undeclared,
            d.name,
            format!(
                "`{}` is declared as a {}, but read as another type",
                d.name,
                d.ty.describe()
            ),
        )
        .hint("this is a bug in the element kind")
    }

    /// A nested table's reader.
    fn nested(
        &self,
        path: String,
        fields: &'static [ParamDecl],
        table: &toml::Table,
        span: &Range<usize>,
    ) -> Result<Box<dyn Params + '_>, BuildError> {
        let params = table
            .iter()
            .map(|(k, v)| {
                (
                    k.clone(),
                    RawValue {
                        value: v.clone(),
                        span: span.clone(),
                    },
                )
            })
            .collect();
        let spec = ElementSpec {
            name: self.name,
            kind: self.kind,
            decls: fields,
            params,
            constants: self.constants,
            file: self.file,
            text: self.text,
            name_span: self.name_span.clone(),
            path,
            used_constants: self.used_constants,
            inputs: self.inputs,
            tables: Arc::clone(&self.tables),
            motions: Arc::clone(&self.motions),
        };
        spec.validate()?;
        Ok(Box::new(spec))
    }

    /// A [`BuildError`] as a [`ModelError`] at the line of the parameter it names.
    #[must_use]
    pub fn locate(&self, e: BuildError) -> ModelError {
        let key = e
            .param
            .as_deref()
            .map(|p| p.split(['.', '[']).next().unwrap_or(p));
        let span = key
            .and_then(|k| self.params.get(k))
            .map_or(self.name_span.start, |v| v.span.start);
        let kind = kind_of(&e);
        let mut m = ModelError::new(kind, self.file, format!("({}) {}", self.kind, e.message))
            .at(Some(line_col(self.text, span)))
            .element(self.name);
        if let Some(h) = &e.hint {
            m = m.hint(h.clone());
        } else if let Some(d) = key.and_then(|k| self.decls.iter().find(|d| d.name == k)) {
            let unit = if d.unit.is_empty() || d.unit == "1" {
                String::new()
            } else {
                format!(", in {}", d.unit)
            };
            m = m.hint(format!(
                "fix `{}` of `{}`: it is the {}{unit}",
                d.name, self.name, d.doc
            ));
        }
        m.with_source(e)
    }
}
