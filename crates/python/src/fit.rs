//! `Model.fit` (`bgsim.Model.fit`): `bg-sim fit` from Python, the data as CSV text (the
//! wrapper turns DataFrames into it), the report as the JSON of `bg-sim fit --format json`.

use std::path::PathBuf;

use bg_model::DataFile;
use bg_sim::fit::{self as fitting, LmOptions, Loss, Method, ParamSpec, Problem, RunOptions};
use pyo3::prelude::*;

use super::{model_error, other_error};

/// Fit and return the report as JSON text. `data`: (name, CSV text) per experiment;
/// `params`: (name, lo, hi, start).
#[pyfunction]
#[pyo3(signature = (path, set, data, params, outputs=None, weights=Vec::new(), loss="l2".to_owned(), method="lm".to_owned(), t_end=None, rtol=None, inputs_interp=None, max_iterations=50))]
#[allow(clippy::too_many_arguments, clippy::needless_pass_by_value)]
pub fn fit(
    py: Python<'_>,
    path: PathBuf,
    set: Vec<String>,
    data: Vec<(String, String)>,
    params: Vec<(String, f64, f64, Option<f64>)>,
    outputs: Option<Vec<String>>,
    weights: Vec<(String, f64)>,
    loss: String,
    method: String,
    t_end: Option<f64>,
    rtol: Option<f64>,
    inputs_interp: Option<String>,
    max_iterations: usize,
) -> PyResult<String> {
    let loss = match loss.as_str() {
        "l2" => Loss::L2,
        "huber" => Loss::Huber,
        o => return Err(other_error(format!("loss={o:?}: l2 or huber"))),
    };
    let method = match method.as_str() {
        "lm" => Method::Lm,
        "nelder-mead" => Method::NelderMead,
        o => return Err(other_error(format!("method={o:?}: lm or nelder-mead"))),
    };
    let mut specs = Vec::new();
    for (name, lo, hi, start) in &params {
        let arg = match start {
            Some(s) => format!("{name}={lo:?}..{hi:?}@{s:?}"),
            None => format!("{name}={lo:?}..{hi:?}"),
        };
        let s: ParamSpec = fitting::parse_param(&arg).map_err(other_error)?;
        specs.push(s);
    }
    let mut files = Vec::new();
    for (name, text) in &data {
        files.push(DataFile::parse(text, name).map_err(|e| model_error(py, &e))?);
    }
    let file = path.display().to_string();
    let raw = std::fs::read_to_string(&path)
        .map_err(|e| other_error(format!("{file}: cannot read the model: {e}")))?;
    let text = bg_model::overrides::apply(&file, &raw, &set).map_err(|e| model_error(py, &e))?;
    let run = RunOptions {
        set: Vec::new(),
        t_end,
        rtol,
        interp: inputs_interp,
    };
    let mut problem = Problem::from_parts(
        file,
        text,
        &files,
        specs,
        outputs.as_deref(),
        &weights,
        run,
        bg_sim::registry,
    )
    .map_err(|e| model_error(py, &e))?;
    problem.loss = loss;
    let opts = LmOptions {
        max_iterations,
        loss,
        ..LmOptions::default()
    };
    let result = py
        .detach(|| {
            fitting::fit(
                &problem,
                method,
                fitting::JacobianKind::Exact,
                &opts,
                &mut |_, _, _| {},
            )
        })
        .map_err(other_error)?;
    Ok(result.json().to_string())
}
