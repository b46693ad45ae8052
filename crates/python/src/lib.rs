//! The Rust half of the Python package `bgsim` (module `bgsim._bgsim`). The Python half,
//! `python/bgsim/__init__.py`, turns these plain values into DataFrames and holds the
//! documented API; nothing here is meant to be called directly.
//!
//! A model is named by its path and `--set` overrides and built anew for each call: a
//! `Model` holds `RefCell`s and cannot cross threads, while a path and a list of strings
//! pickle, so the same calls run on Dask workers. Loading costs milliseconds.

mod fit;
mod sensitivity;
mod stepping;

use std::path::{Path, PathBuf};

use bg_model::{Model, ModelError};
use bg_sim::sweep::{parse_metric, parse_spec, points, run_point, Options, Point, Value};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

create_exception!(
    _bgsim,
    BgSimError,
    PyException,
    "A problem with a model file, a sweep spec or a run."
);

/// A [`ModelError`] as a `BgSimError` carrying file, line, column, element, hint and kind.
fn model_error(py: Python<'_>, e: &ModelError) -> PyErr {
    let err = BgSimError::new_err(e.to_string());
    let v = err.value(py);
    // setting an attribute on a fresh exception instance does not fail
    let _ = v.setattr("line", e.line);
    let _ = v.setattr("column", e.col);
    let strings: [(&str, Option<String>); 4] = [
        ("file", Some(e.file.clone())),
        ("element", e.element.clone()),
        ("hint", e.hint.clone()),
        ("kind", Some(format!("{:?}", e.kind))),
    ];
    for (k, val) in strings {
        let _ = v.setattr(k, val);
    }
    err
}

fn other_error(message: String) -> PyErr {
    BgSimError::new_err(message)
}

/// Overrides for the run settings, after the user's.
fn settings(
    set: &[String],
    t_end: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    dt_out: Option<f64>,
    solver: Option<&str>,
) -> Vec<String> {
    let mut all = set.to_vec();
    for (k, v) in [
        ("t_end", t_end),
        ("rtol", rtol),
        ("atol", atol),
        ("dt_out", dt_out),
    ] {
        if let Some(v) = v {
            all.push(format!("simulation.{k}={v:?}"));
        }
    }
    if let Some(s) = solver {
        all.push(format!("simulation.solver={s}"));
    }
    all
}

/// Load a model and describe it: title, parameters, output columns, settings.
#[pyfunction]
#[pyo3(signature = (path, set))]
fn describe<'py>(py: Python<'py>, path: PathBuf, set: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
    let m = Model::load(&path, &bg_sim::registry(), &set).map_err(|e| model_error(py, &e))?;
    let d = PyDict::new(py);
    d.set_item("file", m.file())?;
    d.set_item("title", m.title.clone())?;
    d.set_item("description", m.description.clone())?;
    let params = PyDict::new(py);
    for (k, v) in &m.parameters {
        params.set_item(k, v)?;
    }
    d.set_item("parameters", params)?;
    let mut columns = vec!["t".to_owned()];
    columns.extend(m.outputs.iter().map(|o| o.name.clone()));
    d.set_item("columns", columns)?;
    let s = &m.settings;
    d.set_item("t_end", s.t_end)?;
    d.set_item("dt_out", s.dt_out)?;
    d.set_item("rtol", s.rtol)?;
    d.set_item("atol", s.atol)?;
    d.set_item(
        "notes",
        m.notes()
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// What [`run`] hands back: columns, row-major f64 values as bytes, statistics, the error.
type RunResult<'py> = (
    Vec<String>,
    Bound<'py, PyBytes>,
    Bound<'py, PyDict>,
    Option<String>,
);

/// Run a model: (columns, row-major f64 values as bytes, statistics, error or None).
#[pyfunction]
#[pyo3(signature = (path, set, t_end=None, rtol=None, atol=None, dt_out=None, solver=None, inputs=Vec::new(), extrapolate=false, energy=false))]
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    path: PathBuf,
    set: Vec<String>,
    t_end: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    dt_out: Option<f64>,
    solver: Option<String>,
    inputs: Vec<stepping::InputData>,
    extrapolate: bool,
    energy: bool,
) -> PyResult<RunResult<'py>> {
    let all = settings(&set, t_end, rtol, atol, dt_out, solver.as_deref());
    // the GIL is released while the model runs: other Python threads go on
    let result = py.detach(move || -> Result<_, Result<ModelError, String>> {
        let mut m = Model::load(&path, &bg_sim::registry(), &all).map_err(Ok)?;
        let span = Some((m.settings.t_start, m.settings.t_end));
        stepping::set_series(&mut m, inputs, span, extrapolate).map_err(Err)?;
        // with `energy`, the audit as the JSON of `bg-sim energy --format json`: by
        // composite, and every element
        let (out, checks, audit) = if energy {
            let run = m.run_energy_checked().map_err(Ok)?;
            let tables = (
                bg_sim::energy::json(&run.report, false).to_string(),
                bg_sim::energy::json(&run.report, true).to_string(),
            );
            (run.outcome, run.checks, Some(tables))
        } else {
            let (out, checks) = m.run_checked().map_err(Ok)?;
            (out, checks, None)
        };
        let failed: Vec<String> = checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| {
                format!(
                    "check `{}` failed: |error| {:e} > tol {:e}",
                    c.value, c.max_error, c.tol
                )
            })
            .collect();
        Ok((out, failed, audit))
    });
    let (out, failed, audit) = result.map_err(|e| match e {
        Ok(e) => model_error(py, &e),
        Err(message) => other_error(message),
    })?;
    let mut bytes =
        Vec::with_capacity(8 * out.trajectory.rows.len() * out.trajectory.columns.len());
    for r in &out.trajectory.rows {
        for v in r {
            bytes.extend_from_slice(&v.to_ne_bytes());
        }
    }
    let stats = PyDict::new(py);
    let s = &out.stats;
    stats.set_item("steps", s.steps)?;
    stats.set_item("rhs_evals", s.rhs_evals)?;
    stats.set_item("jac_evals", s.jac_evals)?;
    stats.set_item("error_test_failures", s.error_test_failures)?;
    stats.set_item("newton_failures", s.newton_failures)?;
    stats.set_item("wall_s", s.wall_time.as_secs_f64())?;
    stats.set_item("t_final", out.t_final)?;
    stats.set_item("failed_checks", failed)?;
    if let Some((grouped, expanded)) = audit {
        stats.set_item("energy", grouped)?;
        stats.set_item("energy_expanded", expanded)?;
    }
    let error = out
        .error
        .as_ref()
        .map(|e| format!("stopped at t = {} s: {e}", out.t_final));
    Ok((
        out.trajectory.columns,
        PyBytes::new(py, &bytes),
        stats,
        error,
    ))
}

fn py_value(v: &Bound<'_, PyAny>) -> PyResult<Value> {
    if let Ok(s) = v.extract::<String>() {
        Ok(Value::Text(s))
    } else {
        Ok(Value::Num(v.extract::<f64>()?))
    }
}

/// One run of a sweep: `values` maps `--set` paths (a bare name is a parameter) to values.
/// Returns the summary row as a dict; a failed run is a row, not an exception.
#[pyfunction]
#[pyo3(signature = (path, values, metrics, index=0))]
fn run_one<'py>(
    py: Python<'py>,
    path: PathBuf,
    values: Bound<'py, PyDict>,
    metrics: Bound<'py, PyDict>,
    index: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mut point = Point {
        index,
        values: Vec::new(),
    };
    for (k, v) in values.iter() {
        let k: String = k.extract()?;
        let k = if k.contains('.') {
            k
        } else {
            format!("parameters.{k}")
        };
        point.values.push((k, py_value(&v)?));
    }
    let mut ms = Vec::new();
    for (k, v) in metrics.iter() {
        let name: String = k.extract()?;
        let src: String = v.extract()?;
        ms.push(parse_metric(&name, &src).map_err(other_error)?);
    }
    let file = path.display().to_string();
    let text = std::fs::read_to_string(&path)
        .map_err(|e| other_error(format!("{file}: cannot read the model: {e}")))?;
    let row = py.detach(|| run_point(&file, &text, &bg_sim::registry(), &point, &ms, None, None));
    let d = PyDict::new(py);
    d.set_item("run", point.id())?;
    d.set_item("index", index)?;
    for (k, v) in &point.values {
        match v {
            Value::Num(x) => d.set_item(k, x)?,
            Value::Text(s) => d.set_item(k, s)?,
        }
    }
    for (m, v) in ms.iter().zip(&row.metrics) {
        d.set_item(&m.name, v.unwrap_or(f64::NAN))?;
    }
    d.set_item("status", row.status.as_str())?;
    d.set_item("steps", row.steps)?;
    d.set_item("wall_s", row.wall_s)?;
    d.set_item("error", row.error)?;
    Ok(d)
}

/// The runs of a sweep spec (a TOML file), each as a dict of `--set` path → value.
#[pyfunction]
fn spec_points<'py>(py: Python<'py>, spec: PathBuf) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let (s, _) = read_spec(&spec)?;
    points(&s)
        .iter()
        .map(|p| {
            let d = PyDict::new(py);
            for (k, v) in &p.values {
                match v {
                    Value::Num(x) => d.set_item(k, x)?,
                    Value::Text(t) => d.set_item(k, t)?,
                }
            }
            Ok(d)
        })
        .collect()
}

/// The metrics of a sweep spec, as (name, source) pairs in order.
#[pyfunction]
fn spec_metrics(spec: PathBuf) -> PyResult<Vec<(String, String)>> {
    let (s, _) = read_spec(&spec)?;
    Ok(s.metrics.into_iter().map(|m| (m.name, m.source)).collect())
}

fn read_spec(spec: &Path) -> PyResult<(bg_sim::sweep::Spec, String)> {
    let shown = spec.display().to_string();
    let text = std::fs::read_to_string(spec)
        .map_err(|e| other_error(format!("{shown}: cannot read the sweep spec: {e}")))?;
    let s = parse_spec(&shown, &text).map_err(|e| other_error(e.to_string()))?;
    Ok((s, text))
}

/// Run a sweep on this machine (`bg-sim sweep`); returns (summary path, statistics).
#[pyfunction]
#[pyo3(signature = (model, spec, out_dir, jobs=0))]
fn sweep<'py>(
    py: Python<'py>,
    model: PathBuf,
    spec: PathBuf,
    out_dir: PathBuf,
    jobs: usize,
) -> PyResult<(PathBuf, Bound<'py, PyDict>)> {
    let (s, _) = read_spec(&spec)?;
    let opts = Options {
        jobs,
        out_dir,
        interrupt: None,
    };
    let summary = py
        .detach(|| bg_sim::sweep::sweep(&model, &s, bg_sim::registry, &opts))
        .map_err(|e| other_error(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("total", summary.total)?;
    d.set_item("skipped", summary.skipped)?;
    d.set_item("ok", summary.ok)?;
    d.set_item("not_ok", summary.not_ok)?;
    d.set_item("wall_s", summary.wall_s)?;
    d.set_item("run_s", summary.run_s)?;
    Ok((summary.path, d))
}

/// Bond-graph model files from Python (the compiled half of `bgsim`).
#[pymodule]
mod _bgsim {
    #[pymodule_export]
    use super::fit::fit;
    #[pymodule_export]
    use super::sensitivity::sensitivity;
    #[pymodule_export]
    use super::stepping::{linearize, start, Sim};
    #[pymodule_export]
    use super::{describe, run, run_one, spec_metrics, spec_points, sweep, BgSimError};
}
