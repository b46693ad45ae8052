//! `model.sensitivity(params=[…])`: one run with the forward sensitivities of the
//! `[outputs]` columns ([`bg_model::Model::sensitivities`], docs/sensitivity.md), handed to
//! Python as plain values; `python/bgsim/__init__.py` makes the DataFrame.

use std::path::PathBuf;

use bg_model::{Model, ModelError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use super::stepping::{set_series, InputData};
use super::{model_error, other_error, settings};

/// What [`sensitivity`] hands back: the `t`, `y` and `dy/dp` column names, row-major f64
/// values as bytes, and the parameter values with the run's statistics.
type SensitivityResult<'py> = (Vec<String>, Bound<'py, PyBytes>, Bound<'py, PyDict>);

/// Run a model with the sensitivities of its outputs to `params`: (columns — `t`, the
/// outputs, then `dy/dp` for each output and parameter —, row-major values as bytes, info).
#[pyfunction]
#[pyo3(signature = (path, set, params, t_end=None, rtol=None, dt_out=None, inputs=Vec::new(), extrapolate=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sensitivity<'py>(
    py: Python<'py>,
    path: PathBuf,
    set: Vec<String>,
    params: Vec<String>,
    t_end: Option<f64>,
    rtol: Option<f64>,
    dt_out: Option<f64>,
    inputs: Vec<InputData>,
    extrapolate: bool,
) -> PyResult<SensitivityResult<'py>> {
    let all = settings(&set, t_end, rtol, None, dt_out, None);
    let result = py.detach(move || -> Result<_, Result<ModelError, String>> {
        let mut m = Model::load(&path, &bg_sim::registry(), &all).map_err(Ok)?;
        let span = Some((m.settings.t_start, m.settings.t_end));
        set_series(&mut m, inputs, span, extrapolate).map_err(Err)?;
        m.sensitivities(&params).map_err(Ok)
    });
    let s = result.map_err(|e| match e {
        Ok(e) => model_error(py, &e),
        Err(message) => other_error(message),
    })?;
    let (m, np) = (s.outputs.len(), s.params.len());
    let mut columns = vec!["t".to_owned()];
    columns.extend(s.outputs.iter().cloned());
    for o in &s.outputs {
        for p in &s.params {
            columns.push(format!("d{o}/d{p}"));
        }
    }
    let mut bytes = Vec::with_capacity(8 * s.t.len() * columns.len());
    for (r, t) in s.t.iter().enumerate() {
        bytes.extend_from_slice(&t.to_ne_bytes());
        for v in &s.y[r * m..(r + 1) * m] {
            bytes.extend_from_slice(&v.to_ne_bytes());
        }
        for v in &s.dy_dp[r * m * np..(r + 1) * m * np] {
            bytes.extend_from_slice(&v.to_ne_bytes());
        }
    }
    let info = PyDict::new(py);
    info.set_item("params", s.params.clone())?;
    info.set_item("values", s.values.clone())?;
    info.set_item("outputs", s.outputs.clone())?;
    info.set_item("steps", s.steps)?;
    Ok((columns, PyBytes::new(py, &bytes), info))
}
