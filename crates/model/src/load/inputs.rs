//! The `[inputs]` table: a model's external inputs, each an [`Input`] element publishing its
//! value under its bare name, so any expression, modulated parameter or signal port reads it
//! like a signal (`force = { kind = "Se", e = "F" }`).
//!
//! ```toml
//! [inputs]
//! F  = { default = 0.0, unit = "N", description = "force on the mass" }
//! u1 = 0.0                                         # a default alone
//! Fd = { file = "data/force.csv", column = "F" }   # from data, relative to the model
//! ```
//!
//! Data come from a CSV ([`DataFile`]): from the file (`file`, `column`, `interp`,
//! `extrapolate`) or for a run ([`Model::set_inputs_from_csv`], `bg-sim run --inputs`).

use std::ops::Range;
use std::path::{Path, PathBuf};

use bondgraph::{Input, InputSpec, Interp};
use indexmap::IndexMap;

use super::model::Model;
use super::parse::{valid_name, SpannedMap};
use super::source::Source;
use crate::data::DataFile;
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::{Expr, RESERVED};

/// What beyond the data's span does: refuse (the default) or hold the end values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extrapolate {
    /// Data that do not cover the run are an error.
    #[default]
    Error,
    /// The first and last values hold outside the data.
    Hold,
}

impl Extrapolate {
    /// Parse `error` or `hold`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "error" => Some(Self::Error),
            "hold" => Some(Self::Hold),
            _ => None,
        }
    }
}

/// Where an input's data come from (`file`, `column` in its entry).
#[derive(Clone, Debug)]
pub(crate) struct DataRef {
    pub(crate) file: String,
    pub(crate) column: String,
    pub(crate) interp: Interp,
    pub(crate) extrapolate: Extrapolate,
}

/// One `[inputs]` entry.
#[derive(Clone, Debug)]
pub(crate) struct InputDef {
    pub(crate) spec: InputSpec,
    pub(crate) span: Range<usize>,
    pub(crate) data: Option<DataRef>,
    /// The input's motion when its time derivatives are known: a sea state, or data with
    /// `interp = "spline"` (`super::sea`).
    pub(crate) motion: Option<bondgraph::Motion>,
}

const KEYS: &[&str] = &[
    "default",
    "unit",
    "description",
    "file",
    "column",
    "interp",
    "extrapolate",
    "sea",
];

/// Read the `[inputs]` entries; each problem goes to `problems`.
pub(super) fn read(
    table: &SpannedMap<toml::Value>,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    problems: &mut Vec<ModelError>,
) -> Vec<InputDef> {
    let mut out = Vec::new();
    for (name, value) in table {
        match entry(
            name.get_ref(),
            name.span(),
            value.get_ref(),
            source,
            parameters,
        ) {
            Ok(d) => out.push(d),
            Err(e) => problems.push(e),
        }
    }
    out
}

fn entry(
    name: &str,
    span: Range<usize>,
    value: &toml::Value,
    source: &Source,
    parameters: &IndexMap<String, f64>,
) -> Result<InputDef, ModelError> {
    let err = |m: String| source.err(ErrorKind::Input, Some(&span), m).element(name);
    if !valid_name(name) || RESERVED.contains(&name) {
        return Err(err(format!("`{}` cannot be an input name", clip(name)))
            .hint("input names are letters, digits and _ (starting with a letter); `t`, `time` and `pi` are reserved"));
    }
    if parameters.contains_key(name) || source.param_exprs.contains_key(name) {
        return Err(err(format!("`{name}` is both a parameter and an input"))
            .hint("rename one of them: an input is a signal that changes during a run, a parameter a constant"));
    }
    if source.elements.iter().any(|e| e.name == name) {
        return Err(err(format!("`{name}` is both an element and an input"))
            .hint("rename one of them: an input publishes its value under its own name"));
    }
    let number = |key: &str, v: &toml::Value| -> Result<f64, ModelError> {
        let x = match v {
            toml::Value::Float(x) => *x,
            toml::Value::Integer(i) => *i as f64,
            toml::Value::String(s) => Expr::parse(s)
                .map_err(|e| err(format!("`{key}` of input `{name}`: {e}")))?
                .eval(&|n| parameters.get(n).copied())
                .map_err(|m| {
                    err(format!("`{key}` of input `{name}`: {m}"))
                        .hint("a default is a number or an expression of [parameters]")
                })?,
            _ => return Err(err(format!("`{key}` of input `{name}` must be a number"))),
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(err(format!("`{key}` of input `{name}` is {x}, not finite")))
        }
    };
    let mut spec = InputSpec {
        name: name.to_owned(),
        unit: String::new(),
        default: 0.0,
        description: String::new(),
    };
    let table = match value {
        toml::Value::Table(t) => t,
        v @ (toml::Value::Float(_) | toml::Value::Integer(_) | toml::Value::String(_)) => {
            spec.default = number("default", v)?;
            return Ok(InputDef {
                spec,
                span,
                data: None,
                motion: None,
            });
        }
        _ => {
            return Err(err(format!(
                "input `{name}` must be a number (its default) or a table"
            ))
            .hint("write `F = { default = 0.0, unit = \"N\", description = \"…\" }`"))
        }
    };
    for k in table.keys() {
        if !KEYS.contains(&k.as_str()) {
            let close = bondgraph::kind::suggest(k, KEYS.iter().copied());
            return Err(
                err(format!("input `{name}` has no key `{}`", clip(k))).hint(match close {
                    Some(c) => format!("did you mean `{c}`? keys: {}", KEYS.join(", ")),
                    None => format!("keys: {}", KEYS.join(", ")),
                }),
            );
        }
    }
    let text = |key: &str| -> Result<Option<String>, ModelError> {
        match table.get(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s.clone())),
            Some(_) => Err(err(format!("`{key}` of input `{name}` must be a string"))),
        }
    };
    if let Some(v) = table.get("default") {
        spec.default = number("default", v)?;
    }
    spec.unit = text("unit")?.unwrap_or_default();
    spec.description = text("description")?.unwrap_or_default();
    let interp = match text("interp")? {
        None => Interp::Linear,
        Some(s) => Interp::parse(&s).ok_or_else(|| {
            err(format!("`interp` of input `{name}` is `{}`", clip(&s)))
                .hint("`interp` is \"linear\", \"hold\" or \"spline\"")
        })?,
    };
    let extrapolate = match text("extrapolate")? {
        None => Extrapolate::Error,
        Some(s) => Extrapolate::parse(&s).ok_or_else(|| {
            err(format!("`extrapolate` of input `{name}` is `{}`", clip(&s)))
                .hint("`extrapolate` is \"error\" (the default) or \"hold\"")
        })?,
    };
    let data = match (text("file")?, text("column")?) {
        (None, None) => None,
        (Some(file), column) => Some(DataRef {
            file,
            column: column.unwrap_or_else(|| name.to_owned()),
            interp,
            extrapolate,
        }),
        (None, Some(_)) => {
            return Err(
                err(format!("input `{name}` names a `column` but no `file`"))
                    .hint("write `file = \"data/force.csv\"` beside it"),
            )
        }
    };
    let motion = motion_of(name, table, &data, source, parameters, &err)?;
    Ok(InputDef {
        spec,
        span,
        data,
        motion,
    })
}

/// The motion of an input with known derivatives: its `sea` table, or its data when
/// interpolated by a spline (`super::sea`).
fn motion_of(
    name: &str,
    table: &toml::map::Map<String, toml::Value>,
    data: &Option<DataRef>,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    err: &dyn Fn(String) -> ModelError,
) -> Result<Option<bondgraph::Motion>, ModelError> {
    match (table.get("sea"), data) {
        (Some(_), Some(_)) => Err(err(format!("input `{name}` has both `sea` and `file`"))
            .hint("an input follows either a sea state or data: drop one")),
        (Some(v), None) => super::sea::motion(name, v, source, parameters, err).map(Some),
        (None, Some(r)) => Ok(super::sea::spline(source, &r.file, &r.column, r.interp)),
        (None, None) => Ok(None),
    }
}

/// The input elements, to add to the graph before the entries.
pub(super) fn elements(
    defs: &[InputDef],
    source: &Source,
) -> Vec<(String, Result<Input, ModelError>)> {
    defs.iter()
        .map(|d| {
            let el = Input::new(d.spec.clone()).map_err(|e| {
                source
                    .err(ErrorKind::Input, Some(&d.span), e.to_string())
                    .element(&d.spec.name)
            });
            let el = el.map(|el| with_motion(el, d));
            (d.spec.name.clone(), el)
        })
        .collect()
}

/// A sea input follows its motion (a data input gets its series in [`apply_files`]).
fn with_motion(el: Input, d: &InputDef) -> Input {
    if let (Some(m), None) = (&d.motion, &d.data) {
        el.set_motion(m.clone());
    }
    el
}

/// The motions of the inputs whose time derivatives are known, by name.
pub(super) fn motions(defs: &[InputDef]) -> IndexMap<String, bondgraph::Motion> {
    defs.iter()
        .filter_map(|d| Some((d.spec.name.clone(), d.motion.clone()?)))
        .collect()
}

/// A path written in the model, relative to the model's directory.
pub(super) fn relative(model_file: &str, path: &str) -> PathBuf {
    let p = Path::new(path);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    Path::new(model_file)
        .parent()
        .map_or_else(|| p.to_path_buf(), |d| d.join(p))
}

/// Give the inputs that name a data file their series; problems go to `problems`.
pub(super) fn apply_files(
    source: &Source,
    eqs: &bondgraph::StateEquations,
    settings: &bondgraph::Settings,
    problems: &mut Vec<ModelError>,
) {
    for d in &source.inputs {
        let Some(r) = &d.data else { continue };
        let at = |e: ModelError| {
            let mut e = e;
            if e.element.is_none() {
                e = e.element(&d.spec.name);
            }
            e
        };
        let path = relative(&source.file, &r.file);
        let shown = path.display().to_string();
        let result = DataFile::read(&path, &shown).and_then(|data| {
            let k = data.column(&r.column).ok_or_else(|| {
                source
                    .err(
                        ErrorKind::Input,
                        Some(&d.span),
                        format!(
                            "input `{}`: `{shown}` has no column `{}`",
                            d.spec.name,
                            clip(&r.column)
                        ),
                    )
                    .hint(column_hint(&r.column, &data.names))
            })?;
            if r.extrapolate == Extrapolate::Error {
                data.covers(
                    settings.t_start,
                    settings.t_end,
                    &format!("column `{}`", r.column),
                )?;
            }
            let s = data.series(k, r.interp)?;
            let i = eqs
                .input_index(&d.spec.name)
                .map_err(|e| ModelError::new(ErrorKind::Input, &source.file, e.message()))?;
            eqs.set_input_series(i, s)
                .map_err(|e| ModelError::new(ErrorKind::Input, &source.file, e.message()))
        });
        if let Err(e) = result {
            problems.push(at(e));
        }
    }
}

fn column_hint(name: &str, names: &[String]) -> String {
    match bondgraph::kind::suggest(name, names.iter().map(String::as_str)) {
        Some(c) => format!("did you mean `{c}`? the columns are: {}", names.join(", ")),
        None => format!("the columns are: {}", names.join(", ")),
    }
}

impl Model {
    /// The model's external inputs (`[inputs]`), in order: name, unit, default, description.
    #[must_use]
    pub fn inputs(&self) -> Vec<InputSpec> {
        self.equations.inputs()
    }

    /// Drive the inputs from a CSV: a `t` column and one column per input (any subset; the
    /// others keep what they had), interpolated by `interp`. Data that do not cover the run
    /// (`settings.t_start..t_end`) are refused unless `extrapolate` is [`Extrapolate::Hold`].
    ///
    /// # Returns
    /// The names of the inputs set, in the file's column order.
    ///
    /// # Errors
    /// A [`ModelError`] at the data file's line and column: a bad cell or row, unsorted or
    /// repeated times, a column that names no input ("did you mean"), the end not covered.
    pub fn set_inputs_from_csv(
        &mut self,
        path: &Path,
        interp: Interp,
        extrapolate: Extrapolate,
    ) -> Result<Vec<String>, ModelError> {
        let shown = path.display().to_string();
        let data = DataFile::read(path, &shown)?;
        let times = data.times()?;
        let _ = times;
        let inputs: Vec<String> = self.inputs().into_iter().map(|s| s.name).collect();
        let mut set = Vec::new();
        for (k, name) in data.names.iter().enumerate() {
            if name == "t" || name == "time" {
                continue;
            }
            let Ok(i) = self.equations.input_index(name) else {
                let hint = match bondgraph::kind::suggest(name, inputs.iter().map(String::as_str)) {
                    Some(c) => format!(
                        "did you mean `{c}`? the model's inputs: {}",
                        inputs.join(", ")
                    ),
                    None if inputs.is_empty() => {
                        format!("{} declares no [inputs]", self.source.file)
                    }
                    None => format!("the model's inputs: {}", inputs.join(", ")),
                };
                return Err(ModelError::new(
                    ErrorKind::Data,
                    &shown,
                    format!("column `{}` is not an input of the model", clip(name)),
                )
                .at(Some((1, data.starts[k])))
                .hint(hint));
            };
            if extrapolate == Extrapolate::Error {
                data.covers(
                    self.settings.t_start,
                    self.settings.t_end,
                    &format!("column `{name}`"),
                )?;
            }
            let s = data.series(k, interp)?;
            self.equations
                .set_input_series(i, s)
                .map_err(|e| ModelError::new(ErrorKind::Data, &shown, e.message()))?;
            set.push(name.clone());
        }
        if set.is_empty() {
            return Err(
                ModelError::new(ErrorKind::Data, &shown, "has no input column")
                    .at(Some((1, 1)))
                    .hint(format!(
                        "name columns after the model's inputs: {}",
                        inputs.join(", ")
                    )),
            );
        }
        Ok(set)
    }

    /// Whether runs stop and restart at the inputs' breakpoints (the default); turn it off
    /// for dense data ([`bondgraph::StateEquations::set_stop_at_breakpoints`]).
    pub fn set_stop_at_breakpoints(&mut self, on: bool) {
        self.equations.set_stop_at_breakpoints(on);
    }
}
