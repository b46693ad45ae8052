//! One FMU instance in safe Rust: the model loaded from the FMU's resources, its variables
//! by value reference, and the co-simulation step on a [`Stepping`] whose solver state
//! lives from one communication point to the next. The C entry points ([`crate::fmi2`],
//! [`crate::fmi3`]) only translate pointers into calls of this type; everything an instance
//! needs is in it (no globals), so instances are independent.
//!
//! Life cycle: [`Instance::new`] loads the model (its errors are reported there, with the
//! file, line and hint); parameters and inputs may be set until the start; the run starts at
//! the first read of an output or the end of initialisation ([`Instance::exit_init`]);
//! [`Instance::do_step`] advances it. A parameter set before the start reloads the model
//! with `--set parameters.NAME=VALUE` (the parameters are fixed once the run started).

use std::path::{Path, PathBuf};

use bg_model::{Model, ModelError, Registry, Stepping};
use bondgraph::{Probe, Subset};

use crate::description::{Description, Role};

/// Status of an FMI call (the same codes in FMI 2 and 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum Status {
    /// All well.
    Ok = 0,
    /// Done, with something worth a look in the log.
    Warning = 1,
    /// The step was not done (FMI 2's `fmi2Discard`).
    Discard = 2,
    /// This call failed; the instance may go on from a saved state or be reset.
    Error = 3,
    /// The instance is unusable.
    Fatal = 4,
}

/// Where messages go: `(status, category, message)`; the C layer forwards them to the
/// importer's logger callback.
pub type Log = Box<dyn Fn(Status, &str, &str)>;

/// The manifest in `resources/` naming the model file (relative to `resources/`).
pub const MANIFEST: &str = "bg-sim-fmu.toml";

/// Every element kind this build knows (as `bg_sim::registry`: the core kinds and the
/// domain crates'; bg-sim depends on this crate, so it cannot be asked).
#[must_use]
pub fn registry() -> Registry {
    let mut r = Registry::with_core();
    r.add(bg_hydraulics::KINDS);
    r.add(bg_mechanical::KINDS);
    r.add(bg_manipulator::KINDS);
    r
}

/// An error of the instance: the text logged, and the status to return.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// What went wrong (for a model error: file:line:col, message and hint).
    pub message: String,
    /// The status of the call.
    pub status: Status,
}

impl Failure {
    fn error(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: Status::Error,
        }
    }
}

impl From<ModelError> for Failure {
    fn from(e: ModelError) -> Self {
        Self::error(e.to_string())
    }
}

/// A saved state ([`Instance::get_state`]): enough to start again from it.
#[derive(Clone, Debug)]
pub struct Snapshot {
    t: f64,
    x: Option<Vec<f64>>,
    values: Vec<f64>,
    inputs_set: Vec<bool>,
    params_set: bool,
}

/// One instance of the FMU; see the module doc.
pub struct Instance {
    name: String,
    log: Log,
    logging_on: bool,
    file: String,
    text: String,
    registry: Registry,
    /// The variables (value references).
    pub description: Description,
    /// The model as loaded, until the run starts.
    model: Option<Model>,
    run: Option<Stepping>,
    /// The probes of the output variables (by value reference; `None` for the others).
    probes: Vec<Option<Probe>>,
    /// The stages the output variables need, evaluated alone.
    reads: Subset,
    /// The outputs at the current time and state, evaluated once for all of them (by value
    /// reference); empty when stale (after a step, an input set, a state set).
    outputs: Vec<f64>,
    /// Current values of inputs and parameters (by value reference).
    values: Vec<f64>,
    inputs_set: Vec<bool>,
    params_set: bool,
    start_time: f64,
    /// After a failed step, nothing but reset, a saved state or free.
    failed: bool,
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("name", &self.name)
            .field("file", &self.file)
            .finish_non_exhaustive()
    }
}

/// The model file named by the manifest in `resources`.
///
/// # Errors
/// A missing or unreadable manifest or model file.
pub fn model_file(resources: &Path) -> Result<PathBuf, String> {
    let manifest = resources.join(MANIFEST);
    let text = std::fs::read_to_string(&manifest).map_err(|e| {
        format!(
            "{}: cannot read the FMU's manifest: {e}\n  hint: the resources folder of an FMU written by `bg-sim fmu` holds it; is the resource location right?",
            manifest.display()
        )
    })?;
    let table: toml::Table = toml::from_str(&text)
        .map_err(|e| format!("{}: not a valid manifest: {e}", manifest.display()))?;
    let rel = table
        .get("model")
        .and_then(toml::Value::as_str)
        .ok_or_else(|| format!("{}: no `model = \"…\"` entry", manifest.display()))?;
    Ok(resources.join(rel))
}

impl Instance {
    /// Load the model of the FMU whose `resources/` folder is `resources`, checking the
    /// token of `modelDescription.xml` (`None`: not checked). Errors are logged and returned.
    ///
    /// # Errors
    /// No manifest, a model that does not load (file, line, hint), a token of another model.
    pub fn new(
        name: &str,
        resources: &Path,
        token: Option<&str>,
        log: Log,
        logging_on: bool,
    ) -> Result<Self, Failure> {
        let fail = |m: String| {
            log(Status::Error, "logStatusError", &m);
            Failure::error(m)
        };
        let path = model_file(resources).map_err(fail)?;
        let file = path.display().to_string();
        let text = std::fs::read_to_string(&path)
            .map_err(|e| fail(format!("{file}: cannot read the model: {e}")))?;
        let registry = registry();
        let model =
            Model::from_text(&file, &text, &registry, &[]).map_err(|e| fail(e.to_string()))?;
        let stem = path
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
        let description = Description::of(&model, &text, &stem);
        if let Some(t) = token {
            if t != description.token {
                return Err(fail(format!(
                    "{file}: the model in resources/ has token {}, the FMU's modelDescription.xml says {t}\n  hint: the FMU was changed after export; export it again with `bg-sim fmu`",
                    description.token
                )));
            }
        }
        if model.settings.method != bondgraph::Method::Radau5 {
            log(
                Status::Warning,
                "logStatusWarning",
                &format!(
                    "{file}: the model asks for {:?}; the FMU integrates with Radau IIA (radau5) at the model's tolerances",
                    model.settings.method
                ),
            );
        }
        let values = description
            .variables
            .iter()
            .map(|v| v.start.unwrap_or(0.0))
            .collect();
        let n_inputs = model.equations.n_inputs();
        let start_time = model.settings.t_start;
        Ok(Self {
            name: name.to_owned(),
            log,
            logging_on,
            file,
            text,
            registry,
            description,
            model: Some(model),
            run: None,
            probes: Vec::new(),
            reads: Subset::default(),
            outputs: Vec::new(),
            values,
            inputs_set: vec![false; n_inputs],
            params_set: false,
            start_time,
            failed: false,
        })
    }

    /// The instance's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Log `message` (errors always, the rest when logging is on).
    pub fn log(&self, status: Status, message: &str) {
        if self.logging_on || matches!(status, Status::Error | Status::Fatal) {
            let category = match status {
                Status::Ok => "logAll",
                Status::Warning => "logStatusWarning",
                Status::Discard => "logStatusDiscard",
                Status::Error => "logStatusError",
                Status::Fatal => "logStatusFatal",
            };
            (self.log)(status, category, message);
        }
    }

    /// Log a failure and return its status.
    pub fn report(&self, f: &Failure) -> Status {
        self.log(f.status, &f.message);
        f.status
    }

    /// Turn logging of everything but errors on or off.
    pub fn set_logging(&mut self, on: bool) {
        self.logging_on = on;
    }

    /// The start time of the run (before it starts).
    pub fn setup(&mut self, start_time: f64) {
        self.start_time = start_time;
    }

    /// The running simulation, started now if it was not.
    fn running(&mut self) -> Result<&mut Stepping, Failure> {
        if self.failed {
            return Err(Failure::error(format!(
                "{}: the instance failed earlier; reset it or set a saved state",
                self.file
            )));
        }
        if self.run.is_none() {
            self.start(None)?;
        }
        self.run
            .as_mut()
            .ok_or_else(|| Failure::error("the simulation did not start"))
    }

    /// Start the run at `from.t` and state `from.x` (a saved state), else at the start
    /// time from the model's initial state.
    fn start(&mut self, from: Option<(f64, Option<Vec<f64>>)>) -> Result<(), Failure> {
        let mut model = match self.model.take() {
            Some(m) if !self.params_set && from.is_none() => m,
            _ => self.reload()?,
        };
        let t0 = match &from {
            Some((t, x)) => {
                if let Some(x) = x {
                    model.x0.clone_from(x);
                }
                *t
            }
            None => self.start_time,
        };
        for v in &self.description.variables {
            if let Role::Input(i) = v.role {
                if self.inputs_set.get(i).copied().unwrap_or(false) {
                    model
                        .equations
                        .set_input(i, self.values[v.vr as usize])
                        .map_err(|e| Failure::error(e.message()))?;
                }
            }
        }
        let run = model.start(Some(t0))?;
        let mut probes = vec![None; self.description.variables.len()];
        let names = run.output_names();
        for v in &self.description.variables {
            if let Role::Output(i) = v.role {
                let name = names.get(i).map_or("", String::as_str);
                probes[v.vr as usize] = Some(run.probe(name)?);
            }
        }
        let read: Vec<Probe> = probes.iter().flatten().copied().collect();
        self.reads = run.simulation().equations().subset(&read);
        self.probes = probes;
        self.outputs.clear();
        self.run = Some(run);
        Ok(())
    }

    /// The model loaded again with the parameters set so far.
    fn reload(&self) -> Result<Model, Failure> {
        let mut overrides = Vec::new();
        if self.params_set {
            for v in &self.description.variables {
                if let Role::Parameter(name) = &v.role {
                    let value = self.values[v.vr as usize];
                    if v.start.map(f64::to_bits) != Some(value.to_bits()) {
                        overrides.push(format!("parameters.{name}={value:?}"));
                    }
                }
            }
        }
        Ok(Model::from_text(
            &self.file,
            &self.text,
            &self.registry,
            &overrides,
        )?)
    }

    /// End of initialisation: the run starts (if it has not).
    ///
    /// # Errors
    /// The model failing to start (a limit crossed, a state not finite).
    pub fn exit_init(&mut self) -> Result<(), Failure> {
        self.running().map(|_| ())
    }

    /// The value of variable `vr`.
    ///
    /// # Errors
    /// An unknown value reference; an output before a run that cannot start.
    pub fn get(&mut self, vr: u32) -> Result<f64, Failure> {
        let v = self
            .description
            .variable(vr)
            .ok_or_else(|| Failure::error(format!("no variable has value reference {vr}")))?;
        match v.role {
            Role::Time => Ok(self.run.as_ref().map_or(self.start_time, Stepping::t)),
            Role::Input(_) | Role::Parameter(_) => Ok(self.values[vr as usize]),
            Role::Output(_) => {
                self.running()?;
                if self.outputs.is_empty() {
                    self.evaluate_outputs();
                }
                self.outputs
                    .get(vr as usize)
                    .copied()
                    .ok_or_else(|| Failure::error(format!("output {vr} is not readable")))
            }
        }
    }

    /// Every output at the current time and state: one evaluation, of the stages they need,
    /// for all of them (reading them one by one would evaluate those stages each time).
    fn evaluate_outputs(&mut self) {
        let Some(run) = &self.run else { return };
        let sim = run.simulation();
        let (t, x, eqs) = (sim.t(), sim.state(), sim.equations());
        eqs.evaluate_only(&self.reads, t, x);
        self.outputs = self
            .probes
            .iter()
            .map(|p| p.map_or(f64::NAN, |p| eqs.read(p, t, x)))
            .collect();
    }

    /// Set variable `vr` to `value`: an input (from now on), a parameter (before the run
    /// starts).
    ///
    /// # Errors
    /// An unknown value reference, time or an output, a value not finite, a parameter once
    /// the run started.
    pub fn set(&mut self, vr: u32, value: f64) -> Result<(), Failure> {
        let v = self
            .description
            .variable(vr)
            .ok_or_else(|| Failure::error(format!("no variable has value reference {vr}")))?;
        if !value.is_finite() {
            return Err(Failure::error(format!(
                "`{}` set to {value}: it must be finite",
                v.name
            )));
        }
        match &v.role {
            Role::Time | Role::Output(_) => Err(Failure::error(format!(
                "`{}` is {}: it cannot be set",
                v.name,
                if v.role == Role::Time {
                    "the time"
                } else {
                    "an output"
                }
            ))),
            Role::Input(i) => {
                let (i, name) = (*i, v.name.clone());
                self.values[vr as usize] = value;
                self.inputs_set[i] = true;
                if let Some(run) = self.run.as_mut() {
                    let input = run.input_names().get(i).cloned().unwrap_or(name);
                    run.set_input(&input, value)?;
                    self.outputs.clear();
                }
                Ok(())
            }
            Role::Parameter(name) => {
                if self.run.is_some() && !self.failed {
                    let same = self.values[vr as usize].to_bits() == value.to_bits();
                    if same {
                        return Ok(());
                    }
                    return Err(Failure::error(format!(
                        "parameter `{name}` is fixed once the run started (t = {})\n  hint: set it before fmi2ExitInitializationMode / fmi3ExitInitializationMode, or reset the instance",
                        self.t()
                    )));
                }
                self.values[vr as usize] = value;
                self.params_set = true;
                self.run = None;
                Ok(())
            }
        }
    }

    /// The current time.
    #[must_use]
    pub fn t(&self) -> f64 {
        self.run.as_ref().map_or(self.start_time, Stepping::t)
    }

    /// One communication step: from `t` (the current time) by `h`, with the model's method
    /// and tolerances, the solver's state kept.
    ///
    /// # Errors
    /// `t` not the current time, `h` negative, the run failing on the way (the instance
    /// then refuses to go on until reset or set to a saved state).
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), Failure> {
        if !(h.is_finite() && h >= 0.0 && t.is_finite()) {
            return Err(Failure::error(format!(
                "step from {t} by {h}: both must be finite and the step ≥ 0"
            )));
        }
        let file = self.file.clone();
        self.outputs.clear();
        let run = self.running()?;
        let now = run.t();
        if (t - now).abs() > 1e-9 * now.abs().max(1.0) {
            return Err(Failure::error(format!(
                "{file}: step from t = {t}, but the instance is at t = {now}\n  hint: the communication point must be where the last step ended"
            )));
        }
        // to the importer's next communication point (its grid, not ours, defines time)
        if let Err(e) = run.advance_to((t + h).max(now)) {
            self.failed = true;
            return Err(e.into());
        }
        Ok(())
    }

    /// Back to the state after instantiation (parameters and inputs at their starts).
    ///
    /// # Errors
    /// The model failing to load again.
    pub fn reset(&mut self) -> Result<(), Failure> {
        self.run = None;
        self.failed = false;
        self.params_set = false;
        self.inputs_set.iter_mut().for_each(|s| *s = false);
        self.values = self
            .description
            .variables
            .iter()
            .map(|v| v.start.unwrap_or(0.0))
            .collect();
        self.model = Some(self.reload()?);
        Ok(())
    }

    /// The state now: time, the model's state, inputs and parameters.
    #[must_use]
    pub fn get_state(&self) -> Snapshot {
        Snapshot {
            t: self.t(),
            x: self.run.as_ref().map(|r| r.state().to_vec()),
            values: self.values.clone(),
            inputs_set: self.inputs_set.clone(),
            params_set: self.params_set,
        }
    }

    /// Go back (or forth) to a saved state. The integrator starts afresh there (its
    /// Jacobian and step size are computed again); the model is loaded again, its events
    /// after the state's time still to come.
    ///
    /// # Errors
    /// The model failing to load or start there.
    pub fn set_state(&mut self, s: &Snapshot) -> Result<(), Failure> {
        self.values.clone_from(&s.values);
        self.inputs_set.clone_from(&s.inputs_set);
        self.params_set = s.params_set;
        self.failed = false;
        self.run = None;
        self.model = None;
        match &s.x {
            Some(x) => self.start(Some((s.t, Some(x.clone())))),
            None => {
                self.start_time = s.t;
                Ok(())
            }
        }
    }
}
