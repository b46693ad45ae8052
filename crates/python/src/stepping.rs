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
    /// Inputs that follow data and may not be stepped past its end: (name, last sample's
    /// time, where the data came from). Data given with `extrapolate="hold"` are not here.
    ends: Vec<(String, f64, &'static str)>,
    /// Inputs driven by the data given to `start`: `set_input` refuses to override them.
    from_start: Vec<String>,
}

/// The tolerance of a comparison of times near `t`.
fn time_tol(t: f64) -> f64 {
    1e-9 * (1.0 + t.abs())
}

impl Sim {
    /// Refuse to advance to `t` past the end of an input's data (unless it was given with
    /// `extrapolate="hold"`), as `run` refuses a run longer than its data.
    fn check_ends(&self, t: f64) -> PyResult<()> {
        for (name, last, origin) in &self.ends {
            if t > last + time_tol(*last) {
                return Err(other_error(format!(
                    "input `{name}`: the {origin} end at t = {last} s; cannot advance to t = {t} s past them\n  hint: add samples up to t = {t} s, or pass extrapolate=\"hold\" to hold the last value"
                )));
            }
        }
        Ok(())
    }

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
        self.check_ends(t)?;
        self.s.advance_to(t).map_err(|e| model_error(py, &e))
    }

    /// Advance by `dt`.
    fn advance(&mut self, py: Python<'_>, dt: f64) -> PyResult<()> {
        self.check_ends(self.s.t() + dt)?;
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
    /// An input driven by the data given to `start` is refused (the data rule it); a
    /// series given by `set_input_series` is replaced (the latest call rules).
    fn set_input(&mut self, py: Python<'_>, name: &str, value: f64) -> PyResult<()> {
        if self.from_start.iter().any(|n| n == name) {
            return Err(other_error(format!(
                "input `{name}` follows the data given to `start`: setting it to {value} would override them\n  hint: leave `{name}` out of the start's inputs to set it call by call, or give it new data with set_inputs({name}=series)"
            )));
        }
        self.s
            .set_input(name, value)
            .map_err(|e| model_error(py, &e))?;
        self.ends.retain(|(n, _, _)| n != name);
        Ok(())
    }

    /// Make the input `name` follow (times, values) from now on. Unless `extrapolate`, the
    /// data must start at or before now, and advancing past their end is refused.
    #[pyo3(signature = (name, times, values, interp, extrapolate=false))]
    fn set_input_series(
        &mut self,
        py: Python<'_>,
        name: &str,
        times: Vec<f64>,
        values: Vec<f64>,
        interp: &str,
        extrapolate: bool,
    ) -> PyResult<()> {
        let series = series("input data", name, times, values, interp).map_err(other_error)?;
        let (first, last) = (series.times()[0], series.times()[series.times().len() - 1]);
        let now = self.s.t();
        if !extrapolate && first > now + time_tol(now) {
            return Err(other_error(format!(
                "input `{name}`: the data start at t = {first} s, after the current time t = {now} s\n  hint: add a sample at t = {now} s, or pass extrapolate=\"hold\" to hold the first value"
            )));
        }
        self.s
            .set_input_series(name, series)
            .map_err(|e| model_error(py, &e))?;
        self.from_start.retain(|n| n != name);
        self.ends.retain(|(n, _, _)| n != name);
        if !extrapolate {
            self.ends
                .push((name.to_owned(), last, "data given to set_inputs"));
        }
        Ok(())
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

/// Load a model (with `--set` overrides and input data) and start it at `t0`. Unless
/// `extrapolate`, the data must start at or before `t0`, and advancing past their end is
/// refused (as `run` refuses a run longer than its data).
#[pyfunction]
#[pyo3(signature = (path, set, t0=None, inputs=Vec::new(), extrapolate=false))]
pub fn start(
    py: Python<'_>,
    path: PathBuf,
    set: Vec<String>,
    t0: Option<f64>,
    inputs: Vec<InputData>,
    extrapolate: bool,
) -> PyResult<Sim> {
    let mut m = Model::load(&path, &bg_sim::registry(), &set).map_err(|e| model_error(py, &e))?;
    let t_start = t0.unwrap_or(m.settings.t_start);
    let from_start: Vec<String> = inputs.iter().map(|d| d.0.clone()).collect();
    let ends = if extrapolate {
        Vec::new()
    } else {
        inputs
            .iter()
            .filter_map(|d| {
                d.1.last()
                    .map(|&last| (d.0.clone(), last, "data given to start"))
            })
            .collect()
    };
    // the start is checked here; the end when advancing (the run has no fixed end)
    set_series(&mut m, inputs, Some((t_start, t_start)), extrapolate).map_err(other_error)?;
    let s = m.start(t0).map_err(|e: ModelError| model_error(py, &e))?;
    Ok(Sim {
        s,
        probes: HashMap::new(),
        ends,
        from_start,
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
