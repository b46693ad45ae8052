//! Many runs of one model: `bg-sim sweep MODEL --spec SWEEP.toml`.
//!
//! A sweep spec names the values to change (any `--set` path; a bare name means
//! `parameters.NAME`), how to combine them (a full grid, or a Latin-hypercube sample with a
//! seed) and the metrics to keep per run. The model file is read once; each run applies its
//! values as `--set` overrides to that text and builds the model anew ([`Model::from_text`]),
//! so runs share nothing and run in parallel on a rayon pool. Each finished run is appended
//! to `summary.csv` at once, so an interrupted sweep keeps what it did; started again on the
//! same folder it skips the runs already there (a run is identified by a hash of its values).
//!
//! ```toml
//! [sweep]
//! design = "grid"                          # or "lhs" (with samples = N, seed = S)
//! [parameters]
//! k = [10.0, 20.0, 40.0]                   # a list
//! c = { from = 0.2, to = 1.0, n = 5 }      # n evenly spaced values, both ends included
//! "simulation.rtol" = [1e-6]               # any --set path
//! [metrics]
//! x_peak = "max(abs(x))"                   # reduction(expression over output columns)
//! t_zero = "first_crossing(v, 0)"
//! ```
//!
//! Metrics are `REDUCTION(EXPR)` or `first_crossing(EXPR, LEVEL)`, where `EXPR` is an
//! expression of the model-file syntax ([`bg_model::expr`]) over the output columns, `t` and
//! the model's parameters. Reductions: `max`, `min`, `mean`, `rms`, `initial`, `final`,
//! `time_of_max`, `time_of_min`, `first_crossing` (linear interpolation between output rows;
//! empty if never crossed). `mean` and `rms` are over the output rows (uniform `dt_out`).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use bg_model::expr::Expr;
use bg_model::{Model, Registry};
use rayon::prelude::*;

/// Name of the summary table in the output folder.
pub const SUMMARY: &str = "summary.csv";

/// Most runs one spec may ask for (a guard against a mistyped grid).
pub const MAX_RUNS: usize = 1_000_000;

/// Something wrong with a sweep spec or its output folder (not with one run: a run that fails
/// is a row of the summary).
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct SweepError {
    /// The file concerned (spec, model or summary).
    pub file: String,
    /// What is wrong, and what to do.
    pub message: String,
}

fn err(file: &str, message: impl Into<String>) -> SweepError {
    SweepError {
        file: file.to_owned(),
        message: message.into(),
    }
}

/// A value given to one `--set` path.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Num(f64),
    /// Text (a solver name, an expression).
    Text(String),
}

impl Value {
    /// As written in `--set` and in the summary.
    #[must_use]
    pub fn render(&self) -> String {
        match self {
            // `{:?}` is the shortest text that reads back as the same f64, and valid TOML
            Self::Num(v) => format!("{v:?}"),
            Self::Text(s) => s.clone(),
        }
    }
}

/// The values of one swept parameter.
#[derive(Clone, Debug)]
pub enum Values {
    /// Explicit values.
    List(Vec<Value>),
    /// `n` values from `from` to `to`, both included; spaced evenly, or evenly in log.
    Range {
        /// First value.
        from: f64,
        /// Last value.
        to: f64,
        /// How many (grid); ignored by a Latin hypercube, which samples the interval.
        n: usize,
        /// Spaced evenly in log10 (both ends > 0).
        log: bool,
    },
}

/// How the parameters' values combine into runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// Every combination (the first parameter varies slowest).
    Grid,
    /// A Latin-hypercube sample of `samples` points, reproducible from `seed`.
    Lhs {
        /// Number of runs.
        samples: usize,
        /// Seed of the generator.
        seed: u64,
    },
}

/// What to reduce a column expression to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reduction {
    /// Largest value.
    Max,
    /// Smallest value.
    Min,
    /// Mean over the output rows.
    Mean,
    /// Root mean square over the output rows.
    Rms,
    /// Value at the first row.
    Initial,
    /// Value at the last row.
    Final,
    /// Time of the largest value.
    TimeOfMax,
    /// Time of the smallest value.
    TimeOfMin,
    /// First time the value crosses the level (interpolated); empty if it never does.
    FirstCrossing,
}

const REDUCTIONS: &[(&str, Reduction)] = &[
    ("max", Reduction::Max),
    ("min", Reduction::Min),
    ("mean", Reduction::Mean),
    ("rms", Reduction::Rms),
    ("initial", Reduction::Initial),
    ("final", Reduction::Final),
    ("time_of_max", Reduction::TimeOfMax),
    ("time_of_min", Reduction::TimeOfMin),
    ("first_crossing", Reduction::FirstCrossing),
];

/// One metric kept per run.
#[derive(Clone, Debug)]
pub struct Metric {
    /// Column name in the summary.
    pub name: String,
    /// The reduction.
    pub reduction: Reduction,
    /// The expression over output columns, `t` and parameters.
    pub expr: Expr,
    /// The level of `first_crossing`.
    pub level: f64,
    /// As written in the spec.
    pub source: String,
}

/// A parsed sweep spec.
#[derive(Clone, Debug)]
pub struct Spec {
    /// `--set` paths and their values, in the order of the file.
    pub parameters: Vec<(String, Values)>,
    /// How they combine.
    pub design: Design,
    /// What to keep per run.
    pub metrics: Vec<Metric>,
    /// Also write every run's full results to `runs/`.
    pub keep_runs: bool,
}

/// One run of a sweep: its position and its values.
#[derive(Clone, Debug)]
pub struct Point {
    /// 0-based position in the design.
    pub index: usize,
    /// `--set` path and value, one per swept parameter.
    pub values: Vec<(String, Value)>,
}

impl Point {
    /// The run's identity: a hash of its paths and values (16 hex digits), the same across
    /// processes and machines, so a resumed sweep recognises the runs it already did.
    #[must_use]
    pub fn id(&self) -> String {
        // FNV-1a, 64 bit
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for (k, v) in &self.values {
            for b in k.bytes().chain([b'=']).chain(v.render().bytes()).chain([0]) {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
        format!("{h:016x}")
    }

    /// The `--set` overrides of this run.
    #[must_use]
    pub fn overrides(&self) -> Vec<String> {
        self.values
            .iter()
            .map(|(k, v)| format!("{k}={}", v.render()))
            .collect()
    }
}

/// How one run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Ran to the end; every `[[check]]` held.
    Ok,
    /// Ran to the end, but a `[[check]]` failed.
    CheckFailed,
    /// The run stopped early (solver failure, a watched limit, …).
    Failed,
    /// The model does not load with these values.
    Error,
}

impl Status {
    /// As written in the summary.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::CheckFailed => "check-failed",
            Self::Failed => "failed",
            Self::Error => "error",
        }
    }
}

/// One row of the summary.
#[derive(Clone, Debug)]
pub struct RunRow {
    /// The run's point.
    pub point: Point,
    /// Metric values, in the spec's order (`None`: not computed or never crossed).
    pub metrics: Vec<Option<f64>>,
    /// How it ended.
    pub status: Status,
    /// Accepted solver steps.
    pub steps: usize,
    /// Wall time of load and run, s.
    pub wall_s: f64,
    /// The error, for a run that did not end `ok` (file, line, element and hint).
    pub error: String,
}

// ---------------------------------------------------------------- spec

/// Parse a sweep spec; `file` names it in errors.
pub fn parse_spec(file: &str, text: &str) -> Result<Spec, SweepError> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        err(
            file,
            format!("not a valid TOML sweep spec: {}", e.message()),
        )
    })?;
    for key in table.keys() {
        if !["sweep", "parameters", "metrics"].contains(&key.as_str()) {
            return Err(err(
                file,
                format!(
                    "unknown section `{key}`; a sweep spec has [sweep], [parameters] and [metrics]"
                ),
            ));
        }
    }
    let sweep = match table.get("sweep") {
        None => toml::Table::new(),
        Some(toml::Value::Table(t)) => t.clone(),
        Some(_) => return Err(err(file, "`sweep` must be a table")),
    };
    let int = |k: &str| -> Result<Option<u64>, SweepError> {
        match sweep.get(k) {
            None => Ok(None),
            Some(toml::Value::Integer(i)) if *i >= 0 => Ok(u64::try_from(*i).ok()),
            Some(_) => Err(err(file, format!("[sweep] {k} must be a whole number ≥ 0"))),
        }
    };
    for k in sweep.keys() {
        if !["design", "samples", "seed", "keep_runs"].contains(&k.as_str()) {
            return Err(err(
                file,
                format!("[sweep] has no key `{k}`; keys: design, samples, seed, keep_runs"),
            ));
        }
    }
    let design = match sweep.get("design").map(toml::Value::as_str) {
        None | Some(Some("grid")) => {
            if sweep.contains_key("samples") {
                return Err(err(file, "[sweep] samples is for design = \"lhs\""));
            }
            Design::Grid
        }
        Some(Some("lhs")) => {
            let samples =
                int("samples")?.ok_or_else(|| err(file, "design = \"lhs\" needs samples = N"))?;
            let samples = usize::try_from(samples).unwrap_or(usize::MAX);
            if samples == 0 || samples > MAX_RUNS {
                return Err(err(file, format!("samples must be 1 to {MAX_RUNS}")));
            }
            Design::Lhs {
                samples,
                seed: int("seed")?.unwrap_or(0),
            }
        }
        Some(_) => return Err(err(file, "[sweep] design is \"grid\" or \"lhs\"")),
    };
    let keep_runs = match sweep.get("keep_runs") {
        None => false,
        Some(toml::Value::Boolean(b)) => *b,
        Some(_) => return Err(err(file, "[sweep] keep_runs is true or false")),
    };

    let mut parameters = Vec::new();
    if let Some(p) = table.get("parameters") {
        let toml::Value::Table(p) = p else {
            return Err(err(file, "`parameters` must be a table"));
        };
        for (name, v) in p {
            let path = if name.contains('.') {
                name.clone()
            } else {
                format!("parameters.{name}")
            };
            parameters.push((path, parse_values(file, name, v)?));
        }
    }
    if parameters.is_empty() {
        return Err(err(
            file,
            "[parameters] is empty: name at least one value to sweep (k = [1.0, 2.0])",
        ));
    }

    let mut metrics = Vec::new();
    if let Some(m) = table.get("metrics") {
        let toml::Value::Table(m) = m else {
            return Err(err(file, "`metrics` must be a table"));
        };
        for (name, v) in m {
            let Some(src) = v.as_str() else {
                return Err(err(
                    file,
                    format!("metric `{name}` must be a string such as \"max(x)\""),
                ));
            };
            metrics.push(parse_metric(name, src).map_err(|m| err(file, m))?);
        }
    }
    if design == Design::Grid {
        if let Some((k, _)) = parameters
            .iter()
            .find(|(_, v)| matches!(v, Values::Range { n: 0, .. }))
        {
            return Err(err(
                file,
                format!("`{k}`: a range in a grid needs n, the number of values"),
            ));
        }
    }
    let spec = Spec {
        parameters,
        design,
        metrics,
        keep_runs,
    };
    let n = run_count(&spec);
    if n > MAX_RUNS {
        return Err(err(
            file,
            format!("the grid has {n} runs, more than {MAX_RUNS}; use design = \"lhs\""),
        ));
    }
    Ok(spec)
}

fn parse_values(file: &str, name: &str, v: &toml::Value) -> Result<Values, SweepError> {
    let scalar = |x: &toml::Value| -> Result<Value, SweepError> {
        match x {
            toml::Value::Float(f) if f.is_finite() => Ok(Value::Num(*f)),
            #[allow(clippy::cast_precision_loss)]
            toml::Value::Integer(i) => Ok(Value::Num(*i as f64)),
            toml::Value::String(s) => Ok(Value::Text(s.clone())),
            _ => Err(err(
                file,
                format!("`{name}`: values are finite numbers or strings"),
            )),
        }
    };
    let num = |t: &toml::Table, k: &str| -> Result<f64, SweepError> {
        match t.get(k) {
            Some(toml::Value::Float(f)) if f.is_finite() => Ok(*f),
            #[allow(clippy::cast_precision_loss)]
            Some(toml::Value::Integer(i)) => Ok(*i as f64),
            _ => Err(err(
                file,
                format!("`{name}`: `{k}` must be a finite number"),
            )),
        }
    };
    match v {
        toml::Value::Array(a) if !a.is_empty() => Ok(Values::List(
            a.iter().map(scalar).collect::<Result<_, _>>()?,
        )),
        toml::Value::Array(_) => Err(err(file, format!("`{name}`: the list is empty"))),
        toml::Value::Table(t) => {
            for k in t.keys() {
                if !["from", "to", "n", "scale"].contains(&k.as_str()) {
                    return Err(err(
                        file,
                        format!("`{name}`: a range has from, to, n and scale, not `{k}`"),
                    ));
                }
            }
            let (from, to) = (num(t, "from")?, num(t, "to")?);
            let n = match t.get("n") {
                None => 0,
                Some(toml::Value::Integer(i)) if *i >= 1 => usize::try_from(*i).unwrap_or(0),
                Some(_) => return Err(err(file, format!("`{name}`: n must be ≥ 1"))),
            };
            let log = match t.get("scale").map(toml::Value::as_str) {
                None | Some(Some("linear")) => false,
                Some(Some("log")) => true,
                Some(_) => {
                    return Err(err(
                        file,
                        format!("`{name}`: scale is \"linear\" or \"log\""),
                    ))
                }
            };
            if log && (from <= 0.0 || to <= 0.0) {
                return Err(err(
                    file,
                    format!("`{name}`: scale = \"log\" needs from and to > 0"),
                ));
            }
            Ok(Values::Range { from, to, n, log })
        }
        other => Ok(Values::List(vec![scalar(other)?])),
    }
}

/// Parse one metric, `REDUCTION(EXPR)` or `first_crossing(EXPR, LEVEL)`.
pub fn parse_metric(name: &str, src: &str) -> Result<Metric, String> {
    let bad = |m: &str| {
        format!(
            "metric `{name}` = \"{}\": {m}; write REDUCTION(EXPR) with a reduction among {}",
            bg_model::error::clip(src),
            REDUCTIONS
                .iter()
                .map(|r| r.0)
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let s = src.trim();
    let (head, rest) = s.split_once('(').ok_or_else(|| bad("no `(`"))?;
    let inner = rest
        .strip_suffix(')')
        .ok_or_else(|| bad("it must end with `)`"))?;
    let reduction = REDUCTIONS
        .iter()
        .find(|r| r.0 == head.trim())
        .map(|r| r.1)
        .ok_or_else(|| bad(&format!("unknown reduction `{}`", head.trim())))?;
    // split at the last comma outside parentheses
    let mut depth = 0i32;
    let mut split = None;
    for (i, c) in inner.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => split = Some(i),
            _ => {}
        }
    }
    let (expr_src, level) = match (reduction, split) {
        (Reduction::FirstCrossing, Some(i)) => {
            let level = Expr::parse(&inner[i + 1..])
                .map_err(|e| bad(&e.to_string()))?
                .eval(&|_| None)
                .map_err(|e| bad(&format!("the level must be a number: {e}")))?;
            (&inner[..i], level)
        }
        (Reduction::FirstCrossing, None) => return Err(bad("first_crossing(EXPR, LEVEL)")),
        (_, Some(_)) => return Err(bad("this reduction takes one argument")),
        (_, None) => (inner, 0.0),
    };
    let expr = Expr::parse(expr_src).map_err(|e| bad(&e.to_string()))?;
    Ok(Metric {
        name: name.to_owned(),
        reduction,
        expr,
        level,
        source: src.to_owned(),
    })
}

fn run_count(spec: &Spec) -> usize {
    match spec.design {
        Design::Lhs { samples, .. } => samples,
        Design::Grid => spec
            .parameters
            .iter()
            .map(|(_, v)| match v {
                Values::List(l) => l.len(),
                Values::Range { n, .. } => (*n).max(1),
            })
            .fold(1usize, usize::saturating_mul),
    }
}

fn range_value(from: f64, to: f64, log: bool, u: f64) -> f64 {
    if log {
        10f64.powf(from.log10() + u * (to.log10() - from.log10()))
    } else {
        from + u * (to - from)
    }
}

/// The runs of a spec, in order.
#[must_use]
pub fn points(spec: &Spec) -> Vec<Point> {
    match spec.design {
        Design::Grid => {
            let axes: Vec<Vec<Value>> = spec
                .parameters
                .iter()
                .map(|(_, v)| match v {
                    Values::List(l) => l.clone(),
                    Values::Range { from, to, n, log } => {
                        let n = (*n).max(1);
                        (0..n)
                            .map(|i| {
                                #[allow(clippy::cast_precision_loss)]
                                let u = if n == 1 {
                                    0.0
                                } else {
                                    i as f64 / (n - 1) as f64
                                };
                                Value::Num(range_value(*from, *to, *log, u))
                            })
                            .collect()
                    }
                })
                .collect();
            let total = run_count(spec);
            (0..total)
                .map(|index| {
                    let mut rest = index;
                    let mut values = vec![Value::Num(0.0); axes.len()];
                    for (j, axis) in axes.iter().enumerate().rev() {
                        values[j] = axis[rest % axis.len()].clone();
                        rest /= axis.len();
                    }
                    Point {
                        index,
                        values: spec
                            .parameters
                            .iter()
                            .map(|(k, _)| k.clone())
                            .zip(values)
                            .collect(),
                    }
                })
                .collect()
        }
        Design::Lhs { samples, seed } => {
            let mut rng = SplitMix(seed);
            // one random permutation of the strata per parameter
            let columns: Vec<Vec<Value>> = spec
                .parameters
                .iter()
                .map(|(_, v)| {
                    let mut strata: Vec<usize> = (0..samples).collect();
                    for i in (1..samples).rev() {
                        strata.swap(i, rng.below(i + 1));
                    }
                    strata
                        .into_iter()
                        .map(|s| {
                            #[allow(clippy::cast_precision_loss)]
                            let u = (s as f64 + rng.unit()) / samples as f64;
                            match v {
                                Values::Range { from, to, log, .. } => {
                                    Value::Num(range_value(*from, *to, *log, u))
                                }
                                Values::List(l) => {
                                    #[allow(
                                        clippy::cast_possible_truncation,
                                        clippy::cast_sign_loss,
                                        clippy::cast_precision_loss
                                    )]
                                    let i = ((u * l.len() as f64) as usize).min(l.len() - 1);
                                    l[i].clone()
                                }
                            }
                        })
                        .collect()
                })
                .collect();
            (0..samples)
                .map(|index| Point {
                    index,
                    values: spec
                        .parameters
                        .iter()
                        .zip(&columns)
                        .map(|((k, _), c)| (k.clone(), c[index].clone()))
                        .collect(),
                })
                .collect()
        }
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): small, seedable, and the same on every platform.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        u
    }
    fn below(&mut self, n: usize) -> usize {
        #[allow(clippy::cast_possible_truncation)]
        let i = (self.next() % n as u64) as usize;
        i
    }
}

// ---------------------------------------------------------------- one run

/// Reduce one metric over a run's rows (`columns` names the row entries, `t` first).
fn reduce(
    metric: &Metric,
    columns: &[String],
    rows: &[Vec<f64>],
    parameters: &indexmap::IndexMap<String, f64>,
) -> Result<Option<f64>, String> {
    let index: HashMap<&str, usize> = columns
        .iter()
        .enumerate()
        .map(|(i, c)| (c.as_str(), i))
        .collect();
    for n in metric.expr.names() {
        if n != "pi" && !index.contains_key(n.as_str()) && !parameters.contains_key(&n) {
            return Err(format!(
                "metric `{}`: `{n}` is not an output column ({}) nor a parameter",
                metric.name,
                columns.join(", ")
            ));
        }
    }
    let mut series = Vec::with_capacity(rows.len());
    for row in rows {
        let v = metric.expr.eval(&|n| {
            index
                .get(n)
                .map(|&i| row[i])
                .or_else(|| parameters.get(n).copied())
        })?;
        series.push((row[0], v));
    }
    if series.is_empty() {
        return Ok(None);
    }
    let arg = |better: fn(f64, f64) -> bool| {
        series
            .iter()
            .copied()
            .reduce(|a, b| if better(b.1, a.1) { b } else { a })
    };
    #[allow(clippy::cast_precision_loss)]
    let n = series.len() as f64;
    Ok(match metric.reduction {
        Reduction::Max => arg(|b, a| b > a).map(|p| p.1),
        Reduction::Min => arg(|b, a| b < a).map(|p| p.1),
        Reduction::TimeOfMax => arg(|b, a| b > a).map(|p| p.0),
        Reduction::TimeOfMin => arg(|b, a| b < a).map(|p| p.0),
        Reduction::Mean => Some(series.iter().map(|p| p.1).sum::<f64>() / n),
        Reduction::Rms => Some((series.iter().map(|p| p.1 * p.1).sum::<f64>() / n).sqrt()),
        Reduction::Initial => series.first().map(|p| p.1),
        Reduction::Final => series.last().map(|p| p.1),
        Reduction::FirstCrossing => {
            let l = metric.level;
            series.windows(2).find_map(|w| {
                let ((t0, a), (t1, b)) = (w[0], w[1]);
                let (da, db) = (a - l, b - l);
                // a crossing leaves the level's side: a row exactly on the level counts as
                // the crossing only when the previous row was off it
                if (da < 0.0 && db >= 0.0) || (da > 0.0 && db <= 0.0) {
                    Some(t0 + (t1 - t0) * da / (da - db))
                } else {
                    None
                }
            })
        }
    })
}

/// Run one point: build the model from `text` with the point's values, run it, reduce the
/// metrics, and (with `keep`) write the full results to `keep/<index>_<id>.csv`. Never
/// fails: what goes wrong is the row's status and error.
#[must_use]
pub fn run_point(
    file: &str,
    text: &str,
    registry: &Registry,
    point: &Point,
    metrics: &[Metric],
    keep: Option<&Path>,
    interrupt: Option<&Arc<AtomicBool>>,
) -> RunRow {
    let start = Instant::now();
    let mut row = RunRow {
        point: point.clone(),
        metrics: vec![None; metrics.len()],
        status: Status::Error,
        steps: 0,
        wall_s: 0.0,
        error: String::new(),
    };
    let mut model = match Model::from_text(file, text, registry, &point.overrides()) {
        Ok(m) => m,
        Err(e) => {
            row.error = e.to_string();
            row.wall_s = start.elapsed().as_secs_f64();
            return row;
        }
    };
    model.settings.interrupt = interrupt.cloned();
    let result = model.run_checked();
    row.wall_s = start.elapsed().as_secs_f64();
    let (out, checks) = match result {
        Ok(r) => r,
        Err(e) => {
            row.error = e.to_string();
            return row;
        }
    };
    row.steps = out.stats.steps;
    if let Some(e) = &out.error {
        row.status = Status::Failed;
        row.error = format!("stopped at t = {} s: {e}", out.t_final);
        return row;
    }
    let columns = &out.trajectory.columns;
    let rows = &out.trajectory.rows;
    row.status = Status::Ok;
    let failed: Vec<String> = checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| {
            format!(
                "check `{}` failed: |error| {:e} > tol {:e} at t = {} s",
                c.value, c.max_error, c.tol, c.t_worst
            )
        })
        .collect();
    if !failed.is_empty() {
        row.status = Status::CheckFailed;
        row.error = failed.join("; ");
    }
    for (slot, m) in row.metrics.iter_mut().zip(metrics) {
        match reduce(m, columns, rows, &model.parameters) {
            Ok(v) => *slot = v,
            Err(e) => {
                row.status = Status::Error;
                row.error = e;
                break;
            }
        }
    }
    if let Some(dir) = keep {
        let path = dir.join(format!("{:06}_{}.csv", point.index, point.id()));
        if let Err(e) = write_run(&path, columns, rows) {
            row.error = format!("writing {}: {e}", path.display());
            row.status = Status::Error;
        }
    }
    row
}

fn write_run(path: &Path, columns: &[String], rows: &[Vec<f64>]) -> std::io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(
        w,
        "{}",
        columns
            .iter()
            .map(|c| csv_field(c))
            .collect::<Vec<_>>()
            .join(",")
    )?;
    for r in rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
        writeln!(w, "{}", line.join(","))?;
    }
    w.flush()
}

// ---------------------------------------------------------------- the table

/// RFC 4180 quoting where needed; line breaks become ` / ` so one run is one line.
fn csv_field(s: &str) -> String {
    let s = s.replace("\r\n", " / ").replace(['\n', '\r'], " / ");
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}

/// Split one CSV line written by [`csv_field`] into fields.
fn csv_split(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', q) => quoted = !q,
            (',', false) => out.push(std::mem::take(&mut cur)),
            (c, _) => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// The summary's header: run id, index, the swept paths, the metrics, then the run's facts.
#[must_use]
pub fn header(spec: &Spec) -> Vec<String> {
    let mut h = vec!["run".to_owned(), "index".to_owned()];
    h.extend(spec.parameters.iter().map(|(k, _)| k.clone()));
    h.extend(spec.metrics.iter().map(|m| m.name.clone()));
    h.extend(["status", "steps", "wall_s", "error"].map(str::to_owned));
    h
}

/// One summary line (no line break).
#[must_use]
pub fn line(row: &RunRow) -> String {
    let mut f = vec![row.point.id(), row.point.index.to_string()];
    f.extend(row.point.values.iter().map(|(_, v)| csv_field(&v.render())));
    f.extend(
        row.metrics
            .iter()
            .map(|m| m.map(|v| format!("{v:?}")).unwrap_or_default()),
    );
    f.push(row.status.as_str().to_owned());
    f.push(row.steps.to_string());
    let mut w = String::new();
    let _ = write!(w, "{:.6}", row.wall_s);
    f.push(w);
    f.push(csv_field(&row.error));
    f.join(",")
}

/// Options of [`sweep`].
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Worker threads (0: one per core).
    pub jobs: usize,
    /// Output folder; `summary.csv` (and `runs/`) go there.
    pub out_dir: PathBuf,
    /// Set to stop: running runs stop after their current step and are not recorded.
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// What a sweep did.
#[derive(Debug)]
pub struct Summary {
    /// The summary table.
    pub path: PathBuf,
    /// Runs in the design.
    pub total: usize,
    /// Runs skipped because the summary already had them.
    pub skipped: usize,
    /// Runs done now, by status.
    pub ok: usize,
    /// Runs done now that did not end `ok`.
    pub not_ok: usize,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
    /// Sum of the runs' wall times, s (÷ `wall_s` = the speed-up of the pool).
    pub run_s: f64,
    /// Runs skipped because of an interrupt (to be done by a resume).
    pub interrupted: usize,
}

/// Run a sweep of the model at `model_path`; see the module doc. Runs already in
/// `out_dir/summary.csv` (same header, same run id) are skipped.
pub fn sweep(
    model_path: &Path,
    spec: &Spec,
    registry: fn() -> Registry,
    opts: &Options,
) -> Result<Summary, SweepError> {
    let file = model_path.display().to_string();
    let text = fs::read_to_string(model_path)
        .map_err(|e| err(&file, format!("cannot read the model: {e}")))?;
    // the model must load as written: a mistake common to every run is an error, not N rows
    Model::from_text(&file, &text, &registry(), &[]).map_err(|e| err(&file, e.to_string()))?;
    let all = points(spec);
    fs::create_dir_all(&opts.out_dir).map_err(|e| {
        err(
            &opts.out_dir.display().to_string(),
            format!("cannot create the output folder: {e}"),
        )
    })?;
    let path = opts.out_dir.join(SUMMARY);
    let shown = path.display().to_string();
    let head = header(spec).join(",");
    let mut done: HashMap<String, String> = HashMap::new();
    if path.exists() {
        let old = fs::read_to_string(&path).map_err(|e| err(&shown, e.to_string()))?;
        let mut lines = old.lines();
        if lines.next() != Some(head.as_str()) {
            return Err(err(
                &shown,
                "was written by a different sweep spec (its header differs); use another -o folder or remove it",
            ));
        }
        let width = header(spec).len();
        for l in lines {
            let f = csv_split(l);
            // a line cut short by an interrupt is not a run done
            if f.len() == width {
                done.insert(f[0].clone(), l.to_owned());
            }
        }
    }
    let todo: Vec<&Point> = all.iter().filter(|p| !done.contains_key(&p.id())).collect();
    let skipped = all.len() - todo.len();
    let keep = if spec.keep_runs {
        let d = opts.out_dir.join("runs");
        fs::create_dir_all(&d).map_err(|e| err(&d.display().to_string(), e.to_string()))?;
        Some(d)
    } else {
        None
    };
    // rows are appended as runs end, so an interrupted sweep keeps them
    let mut f = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| err(&shown, e.to_string()))?;
    if done.is_empty() {
        f.set_len(0).map_err(|e| err(&shown, e.to_string()))?;
        writeln!(f, "{head}").map_err(|e| err(&shown, e.to_string()))?;
    }
    let sink = Mutex::new((f, HashMap::<String, String>::new(), 0usize, 0usize, 0.0f64));
    let write_error: Mutex<Option<String>> = Mutex::new(None);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| err(&file, format!("cannot start the worker threads: {e}")))?;
    let start = Instant::now();
    let stopped = || {
        opts.interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    };
    pool.install(|| {
        todo.par_iter().for_each_init(registry, |reg, p| {
            if stopped() {
                return;
            }
            let row = run_point(
                &file,
                &text,
                reg,
                p,
                &spec.metrics,
                keep.as_deref(),
                opts.interrupt.as_ref(),
            );
            if stopped() {
                return; // cut short: not a result
            }
            let l = line(&row);
            if let Ok(mut s) = sink.lock() {
                if let Err(e) = writeln!(s.0, "{l}").and_then(|()| s.0.flush()) {
                    if let Ok(mut w) = write_error.lock() {
                        w.get_or_insert(e.to_string());
                    }
                }
                s.1.insert(p.id(), l);
                if row.status == Status::Ok {
                    s.2 += 1;
                } else {
                    s.3 += 1;
                }
                s.4 += row.wall_s;
            }
        });
    });
    let wall_s = start.elapsed().as_secs_f64();
    if let Some(e) = write_error.into_inner().ok().flatten() {
        return Err(err(&shown, format!("cannot write the summary: {e}")));
    }
    let (_, new, ok, not_ok, run_s) = sink
        .into_inner()
        .map_err(|_| err(&shown, "a worker panicked"))?;
    let interrupted = todo.len() - ok - not_ok;
    done.extend(new);
    // rewrite in design order, atomically
    let tmp = opts.out_dir.join(format!("{SUMMARY}.tmp"));
    let mut out = String::with_capacity(64 * (done.len() + 1));
    out.push_str(&head);
    out.push('\n');
    for p in &all {
        if let Some(l) = done.get(&p.id()) {
            out.push_str(l);
            out.push('\n');
        }
    }
    fs::write(&tmp, out)
        .and_then(|()| fs::rename(&tmp, &path))
        .map_err(|e| err(&shown, format!("cannot write the summary: {e}")))?;
    Ok(Summary {
        path,
        total: all.len(),
        skipped,
        ok,
        not_ok,
        wall_s,
        run_s,
        interrupted,
    })
}

/// Read a summary table back: the header and each row's fields.
pub fn read_summary(path: &Path) -> Result<(Vec<String>, Vec<Vec<String>>), SweepError> {
    let shown = path.display().to_string();
    let text = fs::read_to_string(path).map_err(|e| err(&shown, e.to_string()))?;
    let mut lines = text.lines();
    let head = lines
        .next()
        .map(csv_split)
        .ok_or_else(|| err(&shown, "empty"))?;
    Ok((head, lines.map(csv_split).collect()))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn grid_varies_the_last_parameter_fastest() {
        let s = parse_spec(
            "s",
            "[parameters]\nk = [1, 2]\nc = { from = 0.0, to = 1.0, n = 3 }\n",
        )
        .unwrap();
        let p = points(&s);
        assert_eq!(p.len(), 6);
        assert_eq!(p[1].overrides(), ["parameters.k=1.0", "parameters.c=0.5"]);
        assert_eq!(p[3].overrides(), ["parameters.k=2.0", "parameters.c=0.0"]);
        let e = parse_spec("s", "[parameters]\nc = { from = 0.0, to = 1.0 }\n").unwrap_err();
        assert!(e.message.contains("needs n"), "{e}");
    }

    #[test]
    fn lhs_puts_one_sample_in_each_stratum_and_is_reproducible() {
        let text = "[sweep]\ndesign = \"lhs\"\nsamples = 8\nseed = 3\n[parameters]\na = { from = 0.0, to = 8.0 }\nb = { from = 0.0, to = 8.0 }\n";
        let s = parse_spec("s", text).unwrap();
        let p = points(&s);
        for j in 0..2 {
            let mut strata: Vec<usize> = p
                .iter()
                .map(|q| match q.values[j].1 {
                    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                    Value::Num(v) => v.floor() as usize,
                    Value::Text(_) => usize::MAX,
                })
                .collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..8).collect::<Vec<_>>());
        }
        let again = points(&s);
        assert_eq!(p[5].id(), again[5].id());
    }

    #[test]
    fn metrics_parse_and_reduce() {
        let cols = vec!["t".to_owned(), "x".to_owned()];
        let rows: Vec<Vec<f64>> = (0..5)
            .map(|i| vec![f64::from(i), 2.0 - f64::from(i)])
            .collect();
        let params = indexmap::IndexMap::new();
        let get = |src: &str| {
            reduce(&parse_metric("m", src).unwrap(), &cols, &rows, &params)
                .unwrap()
                .unwrap()
        };
        assert!((get("max(x)") - 2.0).abs() < 1e-15);
        assert!((get("min(abs(x))") - 0.0).abs() < 1e-15);
        assert!((get("final(x)") + 2.0).abs() < 1e-15);
        assert!((get("time_of_min(x)") - 4.0).abs() < 1e-15);
        assert!((get("first_crossing(x, 0.5)") - 1.5).abs() < 1e-15);
        assert!((get("rms(x)") - 2.0f64.sqrt()).abs() < 1e-15);
        assert!(parse_metric("m", "median(x)")
            .unwrap_err()
            .contains("unknown reduction"));
        assert!(parse_metric("m", "max(x, 1)").is_err());
        let bad = reduce(&parse_metric("m", "max(y)").unwrap(), &cols, &rows, &params);
        assert!(bad.unwrap_err().contains("`y` is not an output column"));
    }

    #[test]
    fn csv_fields_round_trip() {
        let f = ["a", "b,c", "say \"hi\"", "two\nlines"];
        let l: Vec<String> = f.iter().map(|s| csv_field(s)).collect();
        let back = csv_split(&l.join(","));
        assert_eq!(back, ["a", "b,c", "say \"hi\"", "two / lines"]);
    }
}
