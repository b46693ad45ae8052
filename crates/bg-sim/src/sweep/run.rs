//! One run of a sweep: build the model with the point's values, run it and reduce its
//! metrics ([`run_point`]); how it ended ([`Status`], [`RunRow`]).

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use bg_model::{Model, Registry};

use super::csv::csv_field;
use super::design::Point;
use super::spec::{Metric, Reduction};

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
        // read from the audit by `run_point`, never reduced from rows
        Reduction::Energy => None,
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
    let audited = metrics.iter().any(|m| m.reduction == Reduction::Energy);
    let mut audit = None;
    let result = if audited {
        run_audited(&mut model).map(|(out, checks, report)| {
            audit = Some(report);
            (out, checks)
        })
    } else {
        model.run_checked()
    };
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
        if m.reduction == Reduction::Energy {
            match audit.as_ref().map(|a| (a.metric(&m.source), a)) {
                Some((Some(v), _)) => *slot = Some(v),
                Some((None, a)) => {
                    row.status = Status::Error;
                    row.error = format!(
                        "metric `{}` = \"{}\": no element or composite of that name in the energy audit (they are: {})",
                        m.name,
                        m.source,
                        a.by_composite().iter().map(|g| g.name.as_str()).collect::<Vec<_>>().join(", ")
                    );
                    break;
                }
                None => {}
            }
            continue;
        }
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

/// [`Model::run_checked`] with the energy audit (rows in memory, bounded alike).
type Audited = (
    bondgraph::Outcome,
    Vec<bg_model::CheckResult>,
    bondgraph::EnergyReport,
);
fn run_audited(model: &mut Model) -> Result<Audited, bg_model::ModelError> {
    let run = model.run_energy_checked()?;
    Ok((run.outcome, run.checks, run.report))
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::sweep::parse_metric;

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
}
