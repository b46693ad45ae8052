//! [`Params`] for [`ElementSpec`]: each typed read a kind's builder makes (a number, a
//! modulated value, a word, a vector, a matrix, nested tables), checked against the
//! parameter's declaration.

use bondgraph::kind::{self, BuildError, BuildErrorKind, Default, MatrixParam, ParamType, Params};
use bondgraph::Param;

use super::ElementSpec;
use crate::error::clip;

impl Params for ElementSpec<'_> {
    fn name(&self) -> &str {
        self.name
    }
    fn kind(&self) -> &str {
        self.kind
    }
    fn has(&self, key: &str) -> bool {
        self.params.contains_key(key)
    }
    fn number(&self, key: &str) -> Result<f64, BuildError> {
        let d = self.decl(key)?;
        match self.raw(key) {
            None => self.default_number(d)?.ok_or_else(|| self.missing(d)),
            Some(v) => {
                let e = self.expr(d, v)?;
                self.constant(d, &e)
            }
        }
    }
    fn optional(&self, key: &str) -> Result<Option<f64>, BuildError> {
        let d = self.decl(key)?;
        match self.raw(key) {
            None => self.default_number(d),
            Some(_) => self.number(key).map(Some),
        }
    }
    fn modulated(&self, key: &str) -> Result<Param, BuildError> {
        let d = self.decl(key)?;
        let Some(v) = self.raw(key) else {
            return self
                .default_number(d)?
                .map(Param::Const)
                .ok_or_else(|| self.missing(d));
        };
        let e = self.expr(d, v)?;
        let (compiled, inputs) = self.compile(key, &e, d.variable)?;
        if let Some(c) = compiled.constant() {
            return self.in_range(d, c).map(Param::Const);
        }
        if !compiled.has_exact_gradient() {
            return Ok(Param::modulated(inputs, move |_, u| compiled.eval(u)));
        }
        // the exact gradient of the expression (forward mode): tables' slopes included
        let c = std::sync::Arc::new(compiled);
        let g = std::sync::Arc::clone(&c);
        Ok(Param::modulated_exact(
            inputs,
            move |_, u| c.eval(u),
            move |_, u, grad| g.eval_grad(u, grad),
        ))
    }
    fn motion(&self, key: &str) -> Result<bondgraph::Motion, BuildError> {
        let d = self.decl(key)?;
        let Some(v) = self.raw(key) else {
            return self
                .default_number(d)?
                .map(bondgraph::Motion::Const)
                .ok_or_else(|| self.missing(d));
        };
        let e = self.expr(d, v)?;
        for n in e.names() {
            if self.constants.contains_key(&n) {
                self.used_constants.borrow_mut().insert(n);
            }
        }
        let m = e
            .motion(&|n| self.constants.get(n).copied(), &|n| self.motions.get(n).cloned())
            .map_err(|m| {
                self.err(BuildErrorKind::Invalid, key, format!("`{key}` is a motion, but {m}"))
                    .hint("a motion needs exact ẋ and ẍ: write it of `t` and parameters, or read an input with `sea = {…}` or data with interp = \"spline\"")
            })?;
        if let Some(c) = m.constant() {
            self.in_range(d, c)?;
        }
        Ok(m)
    }
    fn count(&self, key: &str) -> Result<usize, BuildError> {
        let v = self.number(key)?;
        if v.fract() != 0.0 || !(0.0..=1e9).contains(&v) {
            return Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` = {v} must be a whole number ≥ 0"),
            ));
        }
        Ok(v as usize)
    }
    fn signal(&self, key: &str) -> Result<String, BuildError> {
        let d = self.decl(key)?;
        match self.raw(key) {
            None => Err(self.missing(d)),
            Some(toml::Value::String(s)) if !s.trim().is_empty() => Ok(s.trim().to_owned()),
            Some(_) => Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` must name a signal, e.g. \"spring.q\""),
            )),
        }
    }
    fn flag(&self, key: &str) -> Result<bool, BuildError> {
        let d = self.decl(key)?;
        match (self.raw(key), d.default) {
            (Some(toml::Value::Boolean(b)), _) => Ok(*b),
            (Some(_), _) => Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` must be true or false"),
            )),
            (None, Default::Flag(b)) => Ok(b),
            (None, _) => Err(self.missing(d)),
        }
    }
    fn word(&self, key: &str) -> Result<String, BuildError> {
        let d = self.decl(key)?;
        let ParamType::Choice(choices) = d.ty else {
            return Err(self.type_error(d));
        };
        match (self.raw(key), d.default) {
            (Some(toml::Value::String(s)), _) if choices.contains(&s.as_str()) => Ok(s.clone()),
            (Some(v), _) => {
                let given = v
                    .as_str()
                    .map_or_else(|| v.type_str().to_owned(), |s| format!("\"{}\"", clip(s)));
                let list = choices
                    .iter()
                    .map(|c| format!("\"{c}\""))
                    .collect::<Vec<_>>()
                    .join(", ");
                let hint = match v
                    .as_str()
                    .and_then(|s| kind::suggest(s, choices.iter().copied()))
                {
                    Some(c) => format!("did you mean \"{c}\"?"),
                    None => format!("`{key}` is the {}", d.doc),
                };
                Err(self
                    .err(
                        BuildErrorKind::Invalid,
                        key,
                        format!("`{key}` must be one of {list}, not {given}"),
                    )
                    .hint(hint))
            }
            (None, Default::Word(w)) => Ok(w.to_owned()),
            (None, _) => Err(self.missing(d)),
        }
    }
    fn vector(&self, key: &str) -> Result<Vec<f64>, BuildError> {
        let d = self.decl(key)?;
        match self.raw(key) {
            None => Ok(self.default_number(d)?.map_or_else(Vec::new, |v| vec![v])),
            Some(toml::Value::Array(items)) => items
                .iter()
                .map(|v| {
                    let e = self.expr(d, v)?;
                    self.constant(d, &e)
                })
                .collect(),
            Some(v) => {
                let e = self.expr(d, v)?;
                Ok(vec![self.constant(d, &e)?])
            }
        }
    }
    fn matrix(&self, key: &str) -> Result<MatrixParam, BuildError> {
        let d = self.decl(key)?;
        let raw = self.raw(key).ok_or_else(|| self.missing(d))?;
        let shape_err = || {
            self.err(
                BuildErrorKind::Invalid,
                key,
                format!(
                    "`{key}` must be an array of rows of equal length, e.g. [[1, 0], [0, \"x.q\"]]"
                ),
            )
        };
        let toml::Value::Array(rows) = raw else {
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
                exprs.push(self.expr(d, v)?);
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
        let max = bondgraph::element::MAX_PARAM_INPUTS;
        if inputs.len() > max {
            return Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` reads {} signals; at most {max}", inputs.len()),
            ));
        }
        let mut entries: Vec<kind::MatrixEntry> = Vec::with_capacity(exprs.len());
        for e in &exprs {
            self.note_constants(e);
            let c = e
                .compile_with(&|n| self.constants.get(n).copied(), &inputs, &self.tables)
                .map_err(|m| self.err(BuildErrorKind::Invalid, key, m))?;
            entries.push(Box::new(move |u| c.eval(u)));
        }
        Ok(MatrixParam {
            rows: n1,
            cols: n2,
            inputs,
            entries,
        })
    }
    fn table(&self, key: &str) -> Result<Option<Box<dyn Params + '_>>, BuildError> {
        let d = self.decl(key)?;
        let Some(fields) = d.fields() else {
            return Err(self.type_error(d));
        };
        let Some(raw) = self.params.get(key) else {
            return Ok(None);
        };
        match &raw.value {
            toml::Value::Table(t) => self.nested(self.full(key), fields, t, &raw.span).map(Some),
            other => Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!("`{key}` must be a table {{ … }}, not {}", other.type_str()),
            )),
        }
    }
    fn tables(&self, key: &str) -> Result<Vec<Box<dyn Params + '_>>, BuildError> {
        let d = self.decl(key)?;
        let Some(fields) = d.fields() else {
            return Err(self.type_error(d));
        };
        let Some(raw) = self.params.get(key) else {
            return if d.required() {
                Err(self.missing(d))
            } else {
                Ok(Vec::new())
            };
        };
        let toml::Value::Array(items) = &raw.value else {
            return Err(self.err(
                BuildErrorKind::Invalid,
                key,
                format!(
                    "`{key}` must be an array of tables [{{ … }}, …], not {}",
                    raw.value.type_str()
                ),
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, v)| match v {
                toml::Value::Table(t) => self.nested(
                    format!("{}[{}]", self.full(key), i + 1),
                    fields,
                    t,
                    &raw.span,
                ),
                other => Err(self.err(
                    BuildErrorKind::Invalid,
                    key,
                    format!(
                        "`{key}[{}]` must be a table {{ … }}, not {}",
                        i + 1,
                        other.type_str()
                    ),
                )),
            })
            .collect()
    }
}
