//! The sweep spec: its values, design and metrics ([`Spec`]), and reading it from TOML
//! ([`parse_spec`], [`parse_metric`]).

use bg_model::expr::Expr;

use super::uncertainty::{parse_dist, Dist, FromFit};
use super::{err, SweepError, MAX_RUNS};

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
    /// A distribution, sampled by Monte Carlo or a Latin hypercube
    /// ([`super::uncertainty`]).
    Dist(Dist),
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
    /// Independent random samples (the distributions' own; ranges and lists uniform).
    MonteCarlo {
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
    /// An entry of the run's energy audit, written bare: `energy.<element or
    /// composite>.<supplied|stored|dissipated|net|activity|share>` or a total
    /// `energy.<supplied|stored|dissipated|residual|relative_residual>` (docs/energy.md);
    /// the run is then audited.
    Energy,
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
    /// The multivariate normal of a fit (`[from_fit]`), whose parameters are entries of
    /// `parameters` with [`Dist::FromFit`].
    pub from_fit: Option<FromFit>,
    /// Columns whose band over time (mean, 5/95 % quantiles) the sweep writes (`[band]`).
    pub band: Vec<String>,
}

/// Parse a sweep spec; `file` names it in errors, with the line of the key at fault
/// (`spec.toml:7`) where there is one.
pub fn parse_spec(file: &str, text: &str) -> Result<Spec, SweepError> {
    parse(file, text).map_err(|(key, mut e)| {
        if let Some(line) = key.and_then(|(section, k)| line_of(text, section, &k)) {
            e.file = format!("{file}:{line}");
        }
        e
    })
}

/// The 1-based line of `key` in `[section]` of a TOML `text` (bare or quoted, before `=`).
fn line_of(text: &str, section: &str, key: &str) -> Option<usize> {
    let mut current = String::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if let Some(h) = l.strip_prefix('[') {
            current = h.split(']').next().unwrap_or("").trim().to_owned();
            continue;
        }
        if current != section {
            continue;
        }
        let Some((k, _)) = l.split_once('=') else {
            continue;
        };
        let k = k.trim();
        if k == key || k.trim_matches('"') == key || k.trim_matches('\'') == key {
            return Some(i + 1);
        }
    }
    None
}

/// The key an error is about: its section and name.
type At = Option<(&'static str, String)>;

fn parse(file: &str, text: &str) -> Result<Spec, (At, SweepError)> {
    let at = |section: &'static str, key: &str| {
        let key = key.to_owned();
        move |e: SweepError| (Some((section, key)), e)
    };
    let nowhere = |e: SweepError| (None, e);
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        let file = line.map_or_else(|| file.to_owned(), |l| format!("{file}:{l}"));
        nowhere(err(
            &file,
            format!("not a valid TOML sweep spec: {}", e.message()),
        ))
    })?;
    for key in table.keys() {
        if !["sweep", "parameters", "metrics", "from_fit", "band"].contains(&key.as_str()) {
            return Err(nowhere(err(
                file,
                format!(
                    "unknown section `{key}`; a sweep spec has [sweep], [parameters], [metrics], [from_fit] and [band]"
                ),
            )));
        }
    }
    let sweep = match table.get("sweep") {
        None => toml::Table::new(),
        Some(toml::Value::Table(t)) => t.clone(),
        Some(_) => return Err(nowhere(err(file, "`sweep` must be a table"))),
    };
    let int = |k: &str| -> Result<Option<u64>, (At, SweepError)> {
        match sweep.get(k) {
            None => Ok(None),
            Some(toml::Value::Integer(i)) if *i >= 0 => Ok(u64::try_from(*i).ok()),
            Some(_) => Err(at("sweep", k)(err(
                file,
                format!("[sweep] {k} must be a whole number ≥ 0"),
            ))),
        }
    };
    for k in sweep.keys() {
        if !["design", "samples", "seed", "keep_runs"].contains(&k.as_str()) {
            return Err(at("sweep", k)(err(
                file,
                format!("[sweep] has no key `{k}`; keys: design, samples, seed, keep_runs"),
            )));
        }
    }
    let design = match sweep.get("design").map(toml::Value::as_str) {
        None | Some(Some("grid")) => {
            if sweep.contains_key("samples") {
                return Err(at("sweep", "samples")(err(
                    file,
                    "[sweep] samples is for design = \"lhs\"",
                )));
            }
            Design::Grid
        }
        Some(Some(d @ ("lhs" | "monte_carlo"))) => {
            let samples = int("samples")?.ok_or_else(|| {
                at("sweep", "design")(err(file, format!("design = \"{d}\" needs samples = N")))
            })?;
            let samples = usize::try_from(samples).unwrap_or(usize::MAX);
            if samples == 0 || samples > MAX_RUNS {
                return Err(at("sweep", "samples")(err(
                    file,
                    format!("samples must be 1 to {MAX_RUNS}"),
                )));
            }
            let seed = int("seed")?.unwrap_or(0);
            if d == "lhs" {
                Design::Lhs { samples, seed }
            } else {
                Design::MonteCarlo { samples, seed }
            }
        }
        Some(_) => {
            return Err(at("sweep", "design")(err(
                file,
                "[sweep] design is \"grid\", \"lhs\" or \"monte_carlo\"",
            )))
        }
    };
    let keep_runs = match sweep.get("keep_runs") {
        None => false,
        Some(toml::Value::Boolean(b)) => *b,
        Some(_) => {
            return Err(at("sweep", "keep_runs")(err(
                file,
                "[sweep] keep_runs is true or false",
            )))
        }
    };

    let mut parameters = Vec::new();
    if let Some(p) = table.get("parameters") {
        let toml::Value::Table(p) = p else {
            return Err(nowhere(err(file, "`parameters` must be a table")));
        };
        for (name, v) in p {
            let path = if name.contains('.') {
                name.clone()
            } else {
                format!("parameters.{name}")
            };
            parameters.push((
                path,
                parse_values(file, name, v).map_err(at("parameters", name))?,
            ));
        }
    }
    let from_fit = match table.get("from_fit") {
        None => None,
        Some(toml::Value::Table(t)) => {
            let Some(f) = t
                .get("file")
                .and_then(toml::Value::as_str)
                .filter(|_| t.len() == 1)
            else {
                return Err(nowhere(err(
                    file,
                    "[from_fit] has one key, file = \"FIT.json\"",
                )));
            };
            // relative to the spec
            let path = std::path::Path::new(file)
                .parent()
                .unwrap_or(std::path::Path::new(""))
                .join(f);
            let ff = FromFit::read(&path, file).map_err(nowhere)?;
            for (k, p) in ff.paths.iter().enumerate() {
                if parameters.iter().any(|(q, _)| q == p) {
                    return Err(nowhere(err(
                        file,
                        format!("`{p}` is both in [parameters] and in the fit of [from_fit]"),
                    )));
                }
                parameters.push((p.clone(), Values::Dist(Dist::FromFit(k))));
            }
            Some(ff)
        }
        Some(_) => return Err(nowhere(err(file, "`from_fit` must be a table"))),
    };
    let band = match table.get("band") {
        None => Vec::new(),
        Some(toml::Value::Table(t)) => {
            match (t.get("columns").and_then(toml::Value::as_array), t.len()) {
                (Some(a), 1) if !a.is_empty() => a
                    .iter()
                    .map(|c| {
                        c.as_str().map(str::to_owned).ok_or_else(|| {
                            nowhere(err(file, "[band] columns are names of output columns"))
                        })
                    })
                    .collect::<Result<_, _>>()?,
                _ => {
                    return Err(nowhere(err(
                        file,
                        "[band] has one key, columns = [\"y1\", …]",
                    )))
                }
            }
        }
        Some(_) => return Err(nowhere(err(file, "`band` must be a table"))),
    };
    if design == Design::Grid {
        if let Some((k, _)) = parameters
            .iter()
            .find(|(_, v)| matches!(v, Values::Dist(_)))
        {
            return Err(nowhere(err(
                file,
                format!("`{k}` is a distribution: sample it with design = \"lhs\" or \"monte_carlo\" (samples = N, seed = S)"),
            )));
        }
    }
    if parameters.is_empty() {
        return Err(nowhere(err(
            file,
            "[parameters] is empty: name at least one value to sweep (k = [1.0, 2.0])",
        )));
    }

    let mut metrics = Vec::new();
    if let Some(m) = table.get("metrics") {
        let toml::Value::Table(m) = m else {
            return Err(nowhere(err(file, "`metrics` must be a table")));
        };
        for (name, v) in m {
            let Some(src) = v.as_str() else {
                return Err(at("metrics", name)(err(
                    file,
                    format!("metric `{name}` must be a string such as \"max(x)\""),
                )));
            };
            metrics.push(parse_metric(name, src).map_err(|m| at("metrics", name)(err(file, m)))?);
        }
    }
    if design == Design::Grid {
        if let Some((k, _)) = parameters
            .iter()
            .find(|(_, v)| matches!(v, Values::Range { n: 0, .. }))
        {
            let name = k.strip_prefix("parameters.").unwrap_or(k);
            return Err(at("parameters", name)(err(
                file,
                format!("`{k}`: a range in a grid needs n, the number of values"),
            )));
        }
    }
    let spec = Spec {
        parameters,
        design,
        metrics,
        keep_runs,
        from_fit,
        band,
    };
    let n = run_count(&spec);
    if n > MAX_RUNS {
        return Err(nowhere(err(
            file,
            format!("the grid has {n} runs, more than {MAX_RUNS}; use design = \"lhs\""),
        )));
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
        toml::Value::Table(t) if t.contains_key("dist") => {
            Ok(Values::Dist(parse_dist(name, t, file)?))
        }
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
    if let Some(rest) = s.strip_prefix("energy.").filter(|_| !s.contains('(')) {
        const FIELDS: &[&str] = &[
            "supplied",
            "stored",
            "dissipated",
            "net",
            "activity",
            "share",
        ];
        const TOTALS: &[&str] = &[
            "supplied",
            "stored",
            "dissipated",
            "residual",
            "relative_residual",
        ];
        let ok = match rest.rsplit_once('.') {
            Some((who, field)) => !who.is_empty() && FIELDS.contains(&field),
            None => TOTALS.contains(&rest),
        };
        if !ok {
            return Err(format!(
                "metric `{name}` = \"{}\": an energy metric is energy.<element or composite>.<{}> or energy.<{}>",
                bg_model::error::clip(src),
                FIELDS.join("|"),
                TOTALS.join("|")
            ));
        }
        return Ok(Metric {
            name: name.to_owned(),
            reduction: Reduction::Energy,
            expr: Expr::parse("0").map_err(|e| e.to_string())?,
            level: 0.0,
            source: s.to_owned(),
        });
    }
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

/// How many runs `spec` asks for: its samples, or the product of its grid's lengths.
pub(super) fn run_count(spec: &Spec) -> usize {
    match spec.design {
        Design::Lhs { samples, .. } | Design::MonteCarlo { samples, .. } => samples,
        Design::Grid => spec
            .parameters
            .iter()
            .map(|(_, v)| match v {
                Values::List(l) => l.len(),
                Values::Range { n, .. } => (*n).max(1),
                Values::Dist(_) => 1,
            })
            .fold(1usize, usize::saturating_mul),
    }
}
