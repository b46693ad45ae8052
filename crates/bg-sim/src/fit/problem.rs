//! The least-squares problem of a fit: the parameters with their bounds ([`ParamSpec`]), the
//! experiments (one data file each, [`Experiment`]), the weights, and the residuals of a run
//! at given parameter values ([`Problem::residuals`]).
//!
//! A residual is `√w_j · (y_j(t_i; p) − d_j(t_i))` for every data row `i` inside the run and
//! every fitted output `j`; the model's value at a data time is interpolated linearly between
//! its output rows (exact where the data lie on the output grid, as the docs' data do).

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use bg_model::{DataFile, ErrorKind, Model, ModelError, Registry};
use bondgraph::Interp;

/// One fitted parameter: its `--set` path, its bounds and its start.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSpec {
    /// As the user named it (`beta`, `elements.cyl1.beta`).
    pub name: String,
    /// The `--set` path (`parameters.beta`).
    pub path: String,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Start value (`@START`, else the model's value).
    pub start: Option<f64>,
}

/// Parse `NAME=LO..HI[@START]`.
///
/// # Errors
/// The argument's form, or bounds reversed or excluding the start, as a message with a hint.
pub fn parse_param(arg: &str) -> Result<ParamSpec, String> {
    let form =
        "\n  hint: --param NAME=LO..HI or NAME=LO..HI@START, e.g. --param beta=1e9..2e9@1.2e9";
    let (name, rest) = arg
        .split_once('=')
        .ok_or_else(|| format!("--param `{arg}`: expected NAME=LO..HI[@START]{form}"))?;
    let name = name.trim();
    let (range, start) = match rest.split_once('@') {
        Some((r, s)) => (r, Some(s)),
        None => (rest, None),
    };
    let num = |s: &str, what: &str| -> Result<f64, String> {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                format!(
                    "--param `{arg}`: {what} `{}` is not a finite number{form}",
                    s.trim()
                )
            })
    };
    let (lo, hi) = range
        .split_once("..")
        .ok_or_else(|| format!("--param `{arg}`: expected bounds LO..HI{form}"))?;
    let (lo, hi) = (num(lo, "lower bound")?, num(hi, "upper bound")?);
    if name.is_empty() {
        return Err(format!("--param `{arg}`: the name is empty{form}"));
    }
    if lo >= hi {
        return Err(format!(
            "--param `{arg}`: the bounds are reversed or empty ({lo} ≥ {hi})\n  hint: write the lower bound first: {name}={}..{}",
            hi.min(lo),
            hi.max(lo)
        ));
    }
    let start = start.map(|s| num(s, "start")).transpose()?;
    if let Some(s) = start {
        if s < lo || s > hi {
            return Err(format!(
                "--param `{arg}`: the start {s} is outside the bounds {lo}..{hi}\n  hint: widen the bounds or start inside them"
            ));
        }
    }
    let path = if name.contains('.') {
        name.to_owned()
    } else {
        format!("parameters.{name}")
    };
    Ok(ParamSpec {
        name: name.to_owned(),
        path,
        lo,
        hi,
        start,
    })
}

/// One experiment: a data file whose output columns are fitted and whose input columns
/// drive the run.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// The data file (as named in errors).
    pub file: String,
    /// The data.
    pub data: DataFile,
    /// Rows of the data inside the run (indices into the data's columns).
    pub rows: Vec<usize>,
    /// Fitted outputs: (index into [`Problem::outputs`], data column).
    pub fitted: Vec<(usize, usize)>,
    /// Input columns: (input name, data column).
    pub inputs: Vec<(String, usize)>,
}

/// How the runs of a fit are set up (run's options).
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `--set` overrides applied before the fitted values.
    pub set: Vec<String>,
    /// `--t-end`.
    pub t_end: Option<f64>,
    /// `--rtol`.
    pub rtol: Option<f64>,
    /// `--inputs-interp` (linear or hold).
    pub interp: Option<String>,
}

/// The loss: plain least squares or Huber's (reweighted, [`crate::fit::lm`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Loss {
    /// ½ Σ r².
    #[default]
    L2,
    /// Huber: quadratic within 1.345 robust standard deviations, linear beyond.
    Huber,
}

/// A fit problem, ready to evaluate.
pub struct Problem {
    /// The model file.
    pub file: String,
    /// Its text after the `--set` overrides.
    pub text: String,
    /// The element kinds.
    pub registry: fn() -> Registry,
    /// The fitted parameters.
    pub params: Vec<ParamSpec>,
    /// Start values (resolved).
    pub start: Vec<f64>,
    /// The fitted output names (model `[outputs]` columns).
    pub outputs: Vec<String>,
    /// Weight per fitted output (`w_j` of the residual `√w_j (y − d)`).
    pub weights: Vec<f64>,
    /// The experiments.
    pub experiments: Vec<Experiment>,
    /// Run settings.
    pub run: RunOptions,
    /// Interpolation of input data.
    pub interp: Interp,
    /// The loss.
    pub loss: Loss,
    /// Model runs so far (every run of every experiment, finite-difference runs included).
    pub runs: AtomicUsize,
    /// What the set-up chose that the user should know.
    pub notes: Vec<String>,
}

/// The loosest rtol a fit runs with unless `--rtol` says otherwise.
pub const FIT_RTOL: f64 = 1e-7;

fn bad(file: &str, message: impl Into<String>) -> ModelError {
    merr(ErrorKind::Data, file, message)
}

/// A [`ModelError`] of `kind` about `file` (bg-model keeps its constructor to itself).
fn merr(kind: ErrorKind, file: &str, message: impl Into<String>) -> ModelError {
    ModelError {
        kind,
        file: file.to_owned(),
        line: None,
        col: None,
        element: None,
        message: message.into(),
        hint: None,
        source: None,
    }
}

/// Place an error at a line and column of its file.
trait AtCell {
    fn at_cell(self, line: usize, col: usize) -> Self;
}

impl AtCell for ModelError {
    fn at_cell(mut self, line: usize, col: usize) -> Self {
        self.line = Some(line);
        self.col = Some(col);
        self
    }
}

impl Problem {
    /// Set up a fit of the model at `model_path` to the `data` files.
    ///
    /// # Errors
    /// Every bad input as a [`ModelError`] naming file, line and column where there is one,
    /// with a hint: a data column matching no output or input ("did you mean"), a parameter
    /// the model does not have, NaN in the data, data not covering the run, a weight for an
    /// output that is not fitted.
    #[allow(clippy::too_many_lines)]
    pub fn new(
        model_path: &Path,
        data: &[&Path],
        params: Vec<ParamSpec>,
        outputs: Option<&[String]>,
        weights: &[(String, f64)],
        run: RunOptions,
        registry: fn() -> Registry,
    ) -> Result<Self, ModelError> {
        let file = model_path.display().to_string();
        let raw = std::fs::read_to_string(model_path)
            .map_err(|e| merr(ErrorKind::Io, &file, format!("cannot read the model: {e}")))?;
        let text = bg_model::overrides::apply(&file, &raw, &run.set)?;
        let mut data_files = Vec::new();
        for d in data {
            let shown = d.display().to_string();
            let df = DataFile::read(d, &shown)?;
            df.times()?;
            data_files.push(df);
        }
        Self::from_parts(
            file,
            text,
            &data_files,
            params,
            outputs,
            weights,
            run,
            registry,
        )
    }

    /// As [`Problem::new`] with the model's text (after `--set`) and the data read.
    ///
    /// # Errors
    /// As [`Problem::new`].
    #[allow(clippy::too_many_arguments, clippy::too_many_lines)]
    pub fn from_parts(
        file: String,
        text: String,
        data: &[DataFile],
        params: Vec<ParamSpec>,
        outputs: Option<&[String]>,
        weights: &[(String, f64)],
        mut run: RunOptions,
        registry: fn() -> Registry,
    ) -> Result<Self, ModelError> {
        let reg = registry();
        let mut model = Model::from_text(&file, &text, &reg, &[])?;
        let mut notes = Vec::new();
        if run.rtol.is_none() && model.settings.rtol > FIT_RTOL {
            notes.push(format!(
                "the runs use rtol {FIT_RTOL:e} (the model's {:e} is too loose for finite differences; --rtol to choose)",
                model.settings.rtol
            ));
            run.rtol = Some(FIT_RTOL);
        }
        apply_settings(&mut model, &run).map_err(|m| merr(ErrorKind::Settings, &file, m))?;
        let interp = match run.interp.as_deref() {
            None => Interp::Linear,
            Some(s) => Interp::parse(s).ok_or_else(|| {
                merr(
                    ErrorKind::Settings,
                    &file,
                    format!("--inputs-interp {s}: not an interpolation"),
                )
                .hint("linear or hold")
            })?,
        };
        if data.is_empty() {
            return Err(merr(ErrorKind::Data, &file, "no --data file: nothing to fit to")
                .hint("--data measured.csv with a `t` column and columns named after the model's [outputs]"));
        }
        if params.is_empty() {
            return Err(
                merr(ErrorKind::Override, &file, "no --param: nothing to fit")
                    .hint("--param NAME=LO..HI[@START]"),
            );
        }
        // the parameters: each must exist; the start is the model's value unless given
        let names: Vec<&str> = model.parameters.keys().map(String::as_str).collect();
        let mut start = Vec::new();
        for (k, p) in params.iter().enumerate() {
            if params[..k].iter().any(|q| q.path == p.path) {
                return Err(merr(
                    ErrorKind::Override,
                    &file,
                    format!("--param `{}` is given twice", p.name),
                ));
            }
            let value = if let Some(bare) = p.path.strip_prefix("parameters.") {
                let Some(v) = model.parameters.get(bare) else {
                    let hint = match bondgraph::kind::suggest(bare, names.iter().copied()) {
                        Some(c) => format!("did you mean `{c}`? the model's parameters: {}", names.join(", ")),
                        None => format!("the model's parameters: {}; an element's parameter is `elements.NAME.PARAM`", names.join(", ")),
                    };
                    return Err(merr(
                        ErrorKind::Override,
                        &file,
                        format!("--param `{}`: the model has no parameter `{bare}`", p.name),
                    )
                    .hint(hint));
                };
                Some(*v)
            } else {
                number_at(&text, &p.path)
            };
            // the path must take a value (an element parameter that exists)
            bg_model::overrides::apply(&file, &text, &[format!("{}=1.0", p.path)]).map_err(
                |e| {
                    merr(
                        ErrorKind::Override,
                        &file,
                        format!("--param `{}`: {}", p.name, e.message),
                    )
                    .hint(e.hint.clone().unwrap_or_else(|| {
                        "name a [parameters] entry or elements.NAME.PARAM".into()
                    }))
                },
            )?;
            let s = match (p.start, value) {
                (Some(s), _) => s,
                (None, Some(v)) if v >= p.lo && v <= p.hi => v,
                (None, Some(v)) => {
                    return Err(merr(
                        ErrorKind::Override,
                        &file,
                        format!(
                            "--param `{}`: the model's value {v} is outside the bounds {}..{}",
                            p.name, p.lo, p.hi
                        ),
                    )
                    .hint(format!(
                        "give a start inside them: {}={}..{}@START",
                        p.name, p.lo, p.hi
                    )))
                }
                (None, None) => {
                    return Err(merr(
                        ErrorKind::Override,
                        &file,
                        format!(
                            "--param `{}`: the model's value is not a plain number",
                            p.name
                        ),
                    )
                    .hint(format!(
                        "give the start: {}={}..{}@START",
                        p.name, p.lo, p.hi
                    )))
                }
            };
            // and the model must build with it (an element's parameter that its kind has)
            if !p.path.starts_with("parameters.") {
                Model::from_text(&file, &text, &reg, &[format!("{}={s:?}", p.path)]).map_err(
                    |e| {
                        let mut e = e;
                        e.message = format!("--param `{}`: {}", p.name, e.message);
                        e
                    },
                )?;
            }
            start.push(s);
        }
        let model_outputs: Vec<String> = model.outputs.iter().map(|o| o.name.clone()).collect();
        let model_inputs: Vec<String> = model.inputs().into_iter().map(|s| s.name).collect();
        let wanted: Option<Vec<String>> = outputs.map(<[String]>::to_vec);
        if let Some(w) = &wanted {
            for o in w {
                if !model_outputs.contains(o) {
                    return Err(merr(
                        ErrorKind::Override,
                        &file,
                        format!("--outputs: `{o}` is not an output of the model"),
                    )
                    .hint(suggestion(
                        o,
                        &model_outputs,
                        "the model's [outputs]",
                    )));
                }
            }
        }
        let (t_start, t_end) = (model.settings.t_start, model.settings.t_end);
        let mut fitted_names: Vec<String> = Vec::new();
        let mut experiments = Vec::new();
        for df in data {
            let t = df.times()?;
            let mut fitted = Vec::new();
            let mut inputs = Vec::new();
            for (k, name) in df.names.iter().enumerate() {
                if name == "t" || name == "time" {
                    continue;
                }
                if model_outputs.contains(name) {
                    if wanted.as_ref().is_some_and(|w| !w.contains(name)) {
                        continue;
                    }
                    let j = match fitted_names.iter().position(|n| n == name) {
                        Some(j) => j,
                        None => {
                            fitted_names.push(name.clone());
                            fitted_names.len() - 1
                        }
                    };
                    fitted.push((j, k));
                } else if model_inputs.contains(name) {
                    inputs.push((name.clone(), k));
                } else {
                    let all: Vec<String> =
                        model_outputs.iter().chain(&model_inputs).cloned().collect();
                    return Err(bad(
                        &df.file,
                        format!("column `{name}` matches no output or input of the model"),
                    )
                    .at_cell(1, df.starts[k])
                    .hint(suggestion(
                        name,
                        &all,
                        "the model's [outputs] and [inputs]",
                    )));
                }
            }
            if fitted.is_empty() {
                return Err(bad(&df.file, "has no column named after a fitted output")
                    .at_cell(1, 1)
                    .hint(format!(
                        "name columns after the model's [outputs]: {}",
                        model_outputs.join(", ")
                    )));
            }
            // the run must lie within the data (inputs are needed all along; outputs are
            // compared where the data are)
            df.covers(t_start, t_end, "the data").map_err(|e| {
                e.hint(format!(
                    "data from t = {t_start} to {t_end} s are needed; shorten the run with --t-end"
                ))
            })?;
            let tol = 1e-10 * (1.0 + t_end.abs());
            let rows: Vec<usize> = (0..t.len())
                .filter(|&i| t[i] >= t_start - tol && t[i] <= t_end + tol)
                .collect();
            experiments.push(Experiment {
                file: df.file.clone(),
                data: df.clone(),
                rows,
                fitted,
                inputs,
            });
        }
        // weights: given, else 1/scale² of the data column (its range, or |mean| if larger)
        for (o, _) in weights {
            if !fitted_names.contains(o) {
                return Err(merr(
                    ErrorKind::Override,
                    &file,
                    format!("--weights: `{o}` is not a fitted output"),
                )
                .hint(suggestion(o, &fitted_names, "the fitted outputs")));
            }
        }
        let weights: Vec<f64> = fitted_names
            .iter()
            .enumerate()
            .map(|(j, n)| {
                weights.iter().find(|(o, _)| o == n).map_or_else(
                    || {
                        let (mut lo, mut hi, mut sum, mut count) =
                            (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0);
                        for e in &experiments {
                            for &(jj, k) in &e.fitted {
                                if jj == j {
                                    for &i in &e.rows {
                                        let v = e.data.columns[k][i];
                                        lo = lo.min(v);
                                        hi = hi.max(v);
                                        sum += v;
                                        count += 1.0;
                                    }
                                }
                            }
                        }
                        let scale = (hi - lo).max((sum / f64::max(count, 1.0)).abs());
                        if scale > 0.0 && scale.is_finite() {
                            1.0 / (scale * scale)
                        } else {
                            1.0
                        }
                    },
                    |(_, w)| *w,
                )
            })
            .collect();
        Ok(Self {
            file,
            text,
            registry,
            params,
            start,
            outputs: fitted_names,
            weights,
            experiments,
            run,
            interp,
            loss: Loss::L2,
            runs: AtomicUsize::new(0),
            notes,
        })
    }

    /// Number of residuals.
    #[must_use]
    pub fn n_residuals(&self) -> usize {
        self.experiments
            .iter()
            .map(|e| e.rows.len() * e.fitted.len())
            .sum()
    }

    /// The `--set` overrides of parameter values `p`.
    #[must_use]
    pub fn overrides(&self, p: &[f64]) -> Vec<String> {
        self.params
            .iter()
            .zip(p)
            .map(|(s, v)| format!("{}={v:?}", s.path))
            .collect()
    }

    /// The model of experiment `e` at parameter values `p`, ready to run.
    ///
    /// # Errors
    /// The model does not build at these values, or the data do not drive it.
    pub fn model(&self, reg: &Registry, e: &Experiment, p: &[f64]) -> Result<Model, String> {
        let mut m = Model::from_text(&self.file, &self.text, reg, &self.overrides(p))
            .map_err(|e| e.to_string())?;
        apply_settings(&mut m, &self.run)?;
        for (name, k) in &e.inputs {
            let s = e.data.series(*k, self.interp).map_err(|e| e.to_string())?;
            let i = m.equations.input_index(name).map_err(|e| e.message())?;
            m.equations
                .set_input_series(i, s)
                .map_err(|e| e.message())?;
        }
        Ok(m)
    }

    /// The fitted outputs of experiment `e` at `p` at the data's rows, row-major
    /// (`[row][fitted column]`, in the order of `e.fitted`).
    ///
    /// # Errors
    /// The model fails to build or its run stops early.
    pub fn simulate(&self, reg: &Registry, e: &Experiment, p: &[f64]) -> Result<Vec<f64>, String> {
        let mut m = self.model(reg, e, p)?;
        self.runs.fetch_add(1, Ordering::Relaxed);
        let out = m.run().map_err(|e| e.to_string())?;
        if let Some(err) = &out.error {
            return Err(format!("the run stopped at t = {} s: {err}", out.t_final));
        }
        let cols: Vec<usize> = e
            .fitted
            .iter()
            .map(|&(j, _)| {
                out.trajectory
                    .columns
                    .iter()
                    .position(|c| *c == self.outputs[j])
                    .unwrap_or(0)
            })
            .collect();
        let t: Vec<f64> = out.trajectory.rows.iter().map(|r| r[0]).collect();
        let times = &e.data.columns[e
            .data
            .column("t")
            .or_else(|| e.data.column("time"))
            .unwrap_or(0)];
        let mut y = Vec::with_capacity(e.rows.len() * cols.len());
        for &i in &e.rows {
            let (a, b, w) = bracket(&t, times[i]);
            for &c in &cols {
                let ra = &out.trajectory.rows[a];
                let rb = &out.trajectory.rows[b];
                y.push(ra[c] + w * (rb[c] - ra[c]));
            }
        }
        Ok(y)
    }

    /// Residuals at `p`, experiment after experiment (unweighted by the loss).
    ///
    /// # Errors
    /// As [`Problem::simulate`].
    pub fn residuals(&self, reg: &Registry, p: &[f64]) -> Result<Vec<f64>, String> {
        let mut r = Vec::with_capacity(self.n_residuals());
        for e in &self.experiments {
            let y = self.simulate(reg, e, p)?;
            self.residuals_of(e, &y, &mut r);
        }
        Ok(r)
    }

    /// Append the residuals of experiment `e` with model values `y` (from
    /// [`Problem::simulate`]) to `r`.
    pub fn residuals_of(&self, e: &Experiment, y: &[f64], r: &mut Vec<f64>) {
        let n = e.fitted.len();
        for (row, &i) in e.rows.iter().enumerate() {
            for (c, &(j, k)) in e.fitted.iter().enumerate() {
                r.push(self.weights[j].sqrt() * (y[row * n + c] - e.data.columns[k][i]));
            }
        }
    }

    /// Runs so far.
    #[must_use]
    pub fn runs(&self) -> usize {
        self.runs.load(Ordering::Relaxed)
    }
}

/// Apply `--t-end` and `--rtol` to a model's settings.
fn apply_settings(m: &mut Model, run: &RunOptions) -> Result<(), String> {
    if let Some(t) = run.t_end {
        m.settings.t_end = t;
    }
    if let Some(r) = run.rtol {
        m.settings.rtol = r;
    }
    m.settings.validate().map_err(|e| e.to_string())
}

/// Indices `a ≤ b` of the rows around time `t` and the weight of `b`.
pub(crate) fn bracket(t: &[f64], x: f64) -> (usize, usize, f64) {
    let n = t.len();
    if n < 2 || x <= t[0] {
        return (0, 0, 0.0);
    }
    if x >= t[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let b = t.partition_point(|&v| v < x);
    if (t[b] - x).abs() <= 1e-12 * (1.0 + x.abs()) {
        return (b, b, 0.0);
    }
    let a = b - 1;
    (a, b, (x - t[a]) / (t[b] - t[a]))
}

/// The plain number at a dotted path of a TOML text (an element's inline-table entry).
fn number_at(text: &str, path: &str) -> Option<f64> {
    let doc: toml_edit::DocumentMut = text.parse().ok()?;
    let mut item = doc.as_item();
    for seg in path.split('.') {
        item = item.get(seg)?;
    }
    item.as_float().or_else(|| {
        item.as_integer().map(|i| {
            #[allow(clippy::cast_precision_loss)]
            let f = i as f64;
            f
        })
    })
}

fn suggestion(name: &str, names: &[String], what: &str) -> String {
    match bondgraph::kind::suggest(name, names.iter().map(String::as_str)) {
        Some(c) => format!("did you mean `{c}`? {what}: {}", names.join(", ")),
        None => format!("{what}: {}", names.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn param_arguments_are_read_and_checked() {
        let p = parse_param("beta=1e9..2e9@1.2e9").unwrap();
        assert_eq!(
            (p.path.as_str(), p.lo, p.hi, p.start),
            ("parameters.beta", 1e9, 2e9, Some(1.2e9))
        );
        let p = parse_param("elements.cyl1.beta=1..2").unwrap();
        assert_eq!((p.path.as_str(), p.start), ("elements.cyl1.beta", None));
        assert!(parse_param("beta=2e9..1e9")
            .unwrap_err()
            .contains("reversed"));
        assert!(parse_param("beta=1..2@3")
            .unwrap_err()
            .contains("outside the bounds"));
        assert!(parse_param("beta=1,2").unwrap_err().contains("LO..HI"));
        assert!(parse_param("beta").unwrap_err().contains("expected"));
    }

    #[test]
    fn bracket_finds_rows_and_weights() {
        let t = [0.0, 1.0, 2.0];
        assert_eq!(bracket(&t, 1.0), (1, 1, 0.0));
        let (a, b, w) = bracket(&t, 1.25);
        assert_eq!((a, b), (1, 2));
        assert!((w - 0.25).abs() < 1e-15);
        assert_eq!(bracket(&t, 5.0), (2, 2, 0.0));
    }
}
