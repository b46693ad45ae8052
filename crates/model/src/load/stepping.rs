//! A loaded model advanced call by call ([`Model::start`] → [`Stepping`]), for a controller
//! written outside the model: read any variable by name, set the inputs, advance, linearise
//! at the current point. The integrator is [`bondgraph::Simulation`] (Radau IIA), whose
//! step size, Jacobian and LU survive between calls.

use bondgraph::{Linearization, Output, Probe, Simulation, Statistics};

use super::model::Model;
use crate::error::{ErrorKind, ModelError};

/// A model advanced call by call; see [`Model::start`].
#[derive(Debug)]
pub struct Stepping {
    sim: Simulation,
    file: String,
    outputs: Vec<Output>,
    state_names: Vec<String>,
}

/// The error of a request that names something the model does not have.
pub(super) fn request_error(file: &str, message: String, hint: Option<String>) -> ModelError {
    let e = ModelError::new(ErrorKind::Settings, file, message);
    match hint {
        Some(h) => e.hint(h),
        None => e,
    }
}

/// The probe called `name`: an `[outputs]` column, else any variable name of the
/// equations (`mass.p`, `spring.e`, `valve.x.dot`, an input's name).
pub(super) fn resolve(
    eqs: &bondgraph::StateEquations,
    outputs: &[Output],
    file: &str,
    name: &str,
) -> Result<Probe, ModelError> {
    if let Some(o) = outputs.iter().find(|o| o.name == name) {
        return Ok(o.probe);
    }
    if let Some(p) = eqs.probe(name) {
        return Ok(p);
    }
    let names = eqs.probe_names();
    let candidates = outputs
        .iter()
        .map(|o| o.name.as_str())
        .chain(names.iter().map(String::as_str));
    let hint = bondgraph::kind::suggest(name, candidates)
        .map(|s| format!("did you mean `{s}`?"))
        .unwrap_or_else(|| {
            "an [outputs] column, a state (`mass.p`), its derivative (`mass.p.dot`), a signal or a bond variable (`spring.e`, `b3.f`); `bg-sim check` lists them".to_owned()
        });
    Err(request_error(
        file,
        format!("`{name}` is no output or variable of the model"),
        Some(hint),
    ))
}

/// A simulation error as a [`ModelError`] of the model's file.
pub(super) fn run_error(file: &str, e: &bondgraph::SimulationError) -> ModelError {
    let err = ModelError::new(ErrorKind::Settings, file, e.message());
    let err = match e.hint() {
        Some(h) => err.hint(h),
        None => err,
    };
    err.with_source(e.clone())
}

impl Model {
    /// Start the model at `t0` (its `t_start` if `None`) from its initial state, to be
    /// advanced call by call ([`Stepping::advance_to`]) with the model's tolerances, its
    /// events applied on the way. The model is consumed: its equations now belong to the
    /// simulation (load the file again for another).
    ///
    /// # Errors
    /// Bad tolerances, a limit crossed at the start, equations not finite at the start.
    pub fn start(self, t0: Option<f64>) -> Result<Stepping, ModelError> {
        let events = self.events()?;
        let file = self.source.file.clone();
        let t0 = t0.unwrap_or(self.settings.t_start);
        let state_names = self
            .equations
            .states()
            .iter()
            .map(|s| s.name.clone())
            .collect();
        let sim = Simulation::start(self.equations, t0, &self.x0, &self.settings, events)
            .map_err(|e| run_error(&file, &e))?;
        Ok(Stepping {
            sim,
            file,
            outputs: self.outputs,
            state_names,
        })
    }
}

impl Stepping {
    /// The current time (s).
    #[must_use]
    pub fn t(&self) -> f64 {
        self.sim.t()
    }

    /// The current state, in the order of [`Self::state_names`].
    #[must_use]
    pub fn state(&self) -> &[f64] {
        self.sim.state()
    }

    /// The states' names (`mass.p`).
    #[must_use]
    pub fn state_names(&self) -> &[String] {
        &self.state_names
    }

    /// The `[outputs]` columns' names.
    #[must_use]
    pub fn output_names(&self) -> Vec<String> {
        self.outputs.iter().map(|o| o.name.clone()).collect()
    }

    /// The simulation underneath.
    #[must_use]
    pub fn simulation(&self) -> &Simulation {
        &self.sim
    }

    /// The simulation underneath, to change it (see [`Simulation::equations_mut`]).
    pub fn simulation_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }

    /// Solver work since the start.
    #[must_use]
    pub fn stats(&self) -> Statistics {
        self.sim.stats()
    }

    /// The probe called `name` (an `[outputs]` column or any variable), for [`Self::read`].
    ///
    /// # Errors
    /// An unknown name, with "did you mean".
    pub fn probe(&self, name: &str) -> Result<Probe, ModelError> {
        resolve(self.sim.equations(), &self.outputs, &self.file, name)
    }

    /// The value of `probe` now.
    #[must_use]
    pub fn read(&self, probe: Probe) -> f64 {
        self.sim.read(probe)
    }

    /// The value of the output or variable `name` now.
    ///
    /// # Errors
    /// An unknown name, with "did you mean".
    pub fn get(&self, name: &str) -> Result<f64, ModelError> {
        Ok(self.read(self.probe(name)?))
    }

    /// The model's inputs, in order.
    #[must_use]
    pub fn input_names(&self) -> Vec<String> {
        self.sim
            .equations()
            .inputs()
            .into_iter()
            .map(|u| u.name)
            .collect()
    }

    /// Hold the input `name` at `value` from now on. A new value changes the equations at
    /// the current time: the integrator evaluates them anew and keeps its step size,
    /// Jacobian and LU (no restart); the same value costs nothing.
    ///
    /// # Errors
    /// An unknown input (with "did you mean"), a value that is not finite.
    pub fn set_input(&mut self, name: &str, value: f64) -> Result<(), ModelError> {
        let bad = |message: String, hint: Option<String>| request_error(&self.file, message, hint);
        if !value.is_finite() {
            return Err(bad(
                format!("input `{name}` set to {value}: it must be finite"),
                None,
            ));
        }
        let i = self
            .sim
            .equations()
            .input_index(name)
            .map_err(|e| bad(e.message(), e.hint()))?;
        self.sim
            .set_input(i, value)
            .map_err(|e| bad(e.message(), e.hint()))
    }

    /// Make the input `name` follow `series` from now on (its samples' times become stops).
    ///
    /// # Errors
    /// An unknown input (with "did you mean").
    pub fn set_input_series(
        &mut self,
        name: &str,
        series: bondgraph::elements::Series,
    ) -> Result<(), ModelError> {
        let bad = |e: bondgraph::GraphError| request_error(&self.file, e.message(), e.hint());
        let i = self.sim.equations().input_index(name).map_err(bad)?;
        self.sim.set_input_series(i, series).map_err(bad)
    }

    /// Advance to `t` (landing on it exactly).
    ///
    /// # Errors
    /// A time behind the current one, or the run failing on the way (see
    /// [`Simulation::advance_to`]); the simulation then refuses to go on.
    pub fn advance_to(&mut self, t: f64) -> Result<(), ModelError> {
        self.sim
            .advance_to(t)
            .map_err(|e| run_error(&self.file, &e))
    }

    /// Advance by `dt`.
    ///
    /// # Errors
    /// As [`Self::advance_to`].
    pub fn advance(&mut self, dt: f64) -> Result<(), ModelError> {
        self.advance_to(self.t() + dt)
    }

    /// The model linearised at the current time and state; see [`Model::linearize`].
    ///
    /// # Errors
    /// As [`Model::linearize`].
    pub fn linearize(
        &self,
        inputs: &[String],
        outputs: &[String],
    ) -> Result<Linearization, ModelError> {
        super::linear::linearize_at(
            self.sim.equations(),
            &self.outputs,
            &self.file,
            self.t(),
            self.state(),
            inputs,
            outputs,
        )
    }
}
