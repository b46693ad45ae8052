//! The stepping and linearising half of `bgsim`: `Sim` (a model advanced call by call,
//! [`bg_model::Stepping`]), `linearize`, and input data (series) for a run or a simulation.

use std::collections::HashMap;
use std::path::PathBuf;

use bg_model::{Model, ModelError, Stepping};
use bondgraph::elements::{Interp, Series};
use bondgraph::{Linearization, Probe};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{model_error, other_error};

/// One input's data: name, times, values, `linear` or `hold`.
pub(crate) type InputData = (String, Vec<f64>, Vec<f64>, String);

/// Give the inputs of `m` their series, checking the names and, unless `extrapolate`, that
/// the data cover [t_start, t_end].
pub(crate) fn set_series(
    m: &mut Model,
    data: Vec<InputData>,
    t_span: Option<(f64, f64)>,
    extrapolate: bool,
) -> Result<(), String> {
    let file = m.file().to_owned();
    for (name, times, values, interp) in data {
        let i = m
            .equations
            .input_index(&name)
            .map_err(|e| format!("{file}: input data: {e}"))?;
        let series = series(&file, &name, times, values, &interp)?;
        if let (Some((t0, t1)), false) = (t_span, extrapolate) {
            check_cover(&file, &name, series.times(), t0, t1)?;
        }
        m.equations
            .set_input_series(i, series)
            .map_err(|e| format!("{file}: input data: {e}"))?;
    }
    Ok(())
}

fn series(
    file: &str,
    name: &str,
    times: Vec<f64>,
    values: Vec<f64>,
    interp: &str,
) -> Result<Series, String> {
    let Some(interp) = Interp::parse(interp) else {
        return Err(format!(
            "{file}: input `{name}`: interpolation `{interp}` is not known (linear or hold)"
        ));
    };
    Series::new(times, values, interp).map_err(|e| format!("{file}: input `{name}`: {e}"))
}

fn check_cover(file: &str, name: &str, times: &[f64], t0: f64, t1: f64) -> Result<(), String> {
    let tol = 1e-9 * (1.0 + t0.abs().max(t1.abs()));
    let (first, last) = (times[0], times[times.len() - 1]);
    if first > t0 + tol {
        return Err(format!(
            "{file}: input `{name}`: the data start at t = {first} s, after the run's start t = {t0} s\n  hint: add a sample at the start, or pass extrapolate=\"hold\" to hold the first value"
        ));
    }
    if last < t1 - tol {
        return Err(format!(
            "{file}: input `{name}`: the data end at t = {last} s, before the run's end t = {t1} s\n  hint: add a sample at the end, or pass extrapolate=\"hold\" to hold the last value"
        ));
    }
    Ok(())
}

/// A model advanced call by call (`bgsim.Simulation` wraps it).
#[pyclass(unsendable, module = "bgsim._bgsim")]
pub struct Sim {
    s: Stepping,
    probes: HashMap<String, Probe>,
}

impl Sim {
    fn probe(&mut self, py: Python<'_>, name: &str) -> PyResult<Probe> {
        if let Some(p) = self.probes.get(name) {
            return Ok(*p);
        }
        let p = self.s.probe(name).map_err(|e| model_error(py, &e))?;
        self.probes.insert(name.to_owned(), p);
        Ok(p)
    }
}

#[pymethods]
impl Sim {
    /// The current time (s).
    #[getter]
    fn t(&self) -> f64 {
        self.s.t()
    }

    /// Advance to `t`, landing on it exactly.
    fn advance_to(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        self.s.advance_to(t).map_err(|e| model_error(py, &e))
    }

    /// Advance by `dt`.
    fn advance(&mut self, py: Python<'_>, dt: f64) -> PyResult<()> {
        self.s.advance(dt).map_err(|e| model_error(py, &e))
    }

    /// The value of an output or variable now.
    fn get(&mut self, py: Python<'_>, name: &str) -> PyResult<f64> {
        let p = self.probe(py, name)?;
        Ok(self.s.read(p))
    }

    /// The values of several outputs or variables now.
    fn get_many(&mut self, py: Python<'_>, names: Vec<String>) -> PyResult<Vec<f64>> {
        let probes = names
            .iter()
            .map(|n| self.probe(py, n))
            .collect::<PyResult<Vec<_>>>()?;
        let sim = self.s.simulation();
        let (t, x) = (sim.t(), sim.state());
        sim.equations().evaluate(t, x);
        Ok(probes
            .iter()
            .map(|&p| sim.equations().read(p, t, x))
            .collect())
    }

    /// (state names, state values).
    fn state(&self) -> (Vec<String>, Vec<f64>) {
        (self.s.state_names().to_vec(), self.s.state().to_vec())
    }

    /// Hold the input `name` at `value`.
    fn set_input(&mut self, py: Python<'_>, name: &str, value: f64) -> PyResult<()> {
        self.s
            .set_input(name, value)
            .map_err(|e| model_error(py, &e))
    }

    /// Make the input `name` follow (times, values) from now on.
    fn set_input_series(
        &mut self,
        py: Python<'_>,
        name: &str,
        times: Vec<f64>,
        values: Vec<f64>,
        interp: &str,
    ) -> PyResult<()> {
        let series = series("input data", name, times, values, interp).map_err(other_error)?;
        self.s
            .set_input_series(name, series)
            .map_err(|e| model_error(py, &e))
    }

    /// The inputs' names.
    fn input_names(&self) -> Vec<String> {
        self.s.input_names()
    }

    /// The [outputs] columns' names.
    fn output_names(&self) -> Vec<String> {
        self.s.output_names()
    }

    /// Solver work since the start.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.s.stats();
        let d = PyDict::new(py);
        d.set_item("steps", s.steps)?;
        d.set_item("rhs_evals", s.rhs_evals)?;
        d.set_item("jac_evals", s.jac_evals)?;
        d.set_item("lu_factorisations", s.lu_factorisations)?;
        d.set_item("error_test_failures", s.error_test_failures)?;
        d.set_item("newton_failures", s.newton_failures)?;
        d.set_item("events", s.events)?;
        d.set_item("wall_s", s.wall_time.as_secs_f64())?;
        Ok(d)
    }

    /// The linear model at the current time and state.
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        inputs: Vec<String>,
        outputs: Vec<String>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let lin = self
            .s
            .linearize(&inputs, &outputs)
            .map_err(|e| model_error(py, &e))?;
        lin_dict(py, &lin)
    }
}

fn rows(m: &bondgraph::DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

fn lin_dict<'py>(py: Python<'py>, lin: &Linearization) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t", lin.t)?;
    d.set_item("x", lin.x.clone())?;
    d.set_item("states", lin.states.clone())?;
    d.set_item("inputs", lin.inputs.clone())?;
    d.set_item("outputs", lin.outputs.clone())?;
    d.set_item("A", rows(&lin.a))?;
    d.set_item("B", rows(&lin.b))?;
    d.set_item("C", rows(&lin.c))?;
    d.set_item("D", rows(&lin.d))?;
    Ok(d)
}

/// Load a model (with `--set` overrides and input data) and start it at `t0`.
#[pyfunction]
#[pyo3(signature = (path, set, t0=None, inputs=Vec::new()))]
pub fn start(
    py: Python<'_>,
    path: PathBuf,
    set: Vec<String>,
    t0: Option<f64>,
    inputs: Vec<InputData>,
) -> PyResult<Sim> {
    let mut m = Model::load(&path, &bg_sim::registry(), &set).map_err(|e| model_error(py, &e))?;
    set_series(&mut m, inputs, None, true).map_err(other_error)?;
    let s = m.start(t0).map_err(|e: ModelError| model_error(py, &e))?;
    Ok(Sim {
        s,
        probes: HashMap::new(),
    })
}

/// Load a model and linearise it at `at` (its start if `None`).
#[pyfunction]
#[pyo3(signature = (path, set, at, inputs, outputs))]
pub fn linearize<'py>(
    py: Python<'py>,
    path: PathBuf,
    set: Vec<String>,
    at: Option<f64>,
    inputs: Vec<String>,
    outputs: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut m = Model::load(&path, &bg_sim::registry(), &set).map_err(|e| model_error(py, &e))?;
    let lin = m
        .linearize(at, &inputs, &outputs)
        .map_err(|e| model_error(py, &e))?;
    lin_dict(py, &lin)
}
