//! [`Model`]: a loaded model file, ready to run: the stages put together
//! ([`Model::from_text`]), its settings, outputs and checks, and running it with its events.

use std::path::Path;

use bondgraph::{Event, Output, Settings, StateEquations};
use indexmap::IndexMap;

use super::checks::{self, Check, CheckResult, CheckSink};
use super::events::{self, EventPlan};
use super::parse::{parse, read_model, Parsed};
use super::source::Source;
use super::wire::{build_graph, causal, core_error};
use super::{initial, outputs, settings};
use crate::error::{ErrorKind, ModelError};
use crate::registry::Registry;
use crate::scene::Scene;

/// A loaded model, ready to run.
pub struct Model {
    /// Title from the file.
    pub title: Option<String>,
    /// Description from the file.
    pub description: Option<String>,
    /// The assembled equations.
    pub equations: StateEquations,
    /// Initial state (element initial values, then `[initial]`).
    pub x0: Vec<f64>,
    /// Solver settings.
    pub settings: Settings,
    /// Output columns besides `t`.
    pub outputs: Vec<Output>,
    /// Checks against expected results.
    pub checks: Vec<Check>,
    /// Named parameters and their values.
    pub parameters: IndexMap<String, f64>,
    /// The scene switches the file declares (`[scene]`, [`crate::scene`]).
    pub scene: Scene,
    /// The steady state solved for the start (`[initial.steady]`), if the file asks for one.
    pub steady: Option<crate::steady::SteadyReport>,
    /// Notes from loading: things that load but were likely meant otherwise.
    pub(super) notes: Vec<ModelError>,
    pub(super) source: Source,
    /// The `[[events]]`, planned at load time.
    pub(super) events: Vec<EventPlan>,
}

impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("file", &self.source.file)
            .field("title", &self.title)
            .field("n_states", &self.equations.n_states())
            .finish_non_exhaustive()
    }
}

/// The model of `p` once its equations are assembled: initial values, settings, a steady
/// start, outputs, checks and events, each of their problems reported.
pub(super) fn finish(p: Parsed, mut eqs: StateEquations) -> Result<Model, Vec<ModelError>> {
    let Parsed {
        spec,
        source,
        parameters,
        scene,
        ..
    } = p;
    let mut problems = Vec::new();
    let steady_spec = initial::apply(&spec.initial, &source, &parameters, &mut eqs, &mut problems);
    let sim = spec.simulation.unwrap_or_default();
    let settings = settings::read(&sim, &source, &mut problems);
    if problems.is_empty() {
        super::inputs::apply_files(&source, &eqs, &settings, &mut problems);
    }
    if problems.is_empty() {
        initial::check_lengths(&source, &eqs, settings.t_start, &mut problems);
    }
    let steady = match steady_spec {
        Some(v) if problems.is_empty() => {
            initial::steady(v, &source, &parameters, &settings, &mut eqs).unwrap_or_else(|e| {
                problems.push(e);
                None
            })
        }
        _ => None,
    };
    let (outputs, notes, refused) = outputs::read(&spec.outputs, &source, &eqs, &mut problems);
    let columns = checks::column_names(&outputs, &refused);
    let checks = checks::read(&spec.check, &source, &parameters, &columns, &mut problems);
    let events = events::plan(&source, &parameters, &eqs, &mut problems);
    if !problems.is_empty() {
        return Err(problems);
    }
    Ok(Model {
        title: spec.title,
        description: spec.description,
        x0: eqs.initial_state(),
        equations: eqs,
        settings,
        outputs,
        checks,
        parameters,
        scene,
        steady,
        notes,
        source,
        events,
    })
}

impl Model {
    /// Load a model file with the given element kinds and `--set` overrides.
    pub fn load(
        path: &Path,
        registry: &Registry,
        overrides: &[String],
    ) -> Result<Self, ModelError> {
        let file = path.display().to_string();
        let text = read_model(path, &file)?;
        Self::from_text(&file, &text, registry, overrides)
    }

    /// Load a model from text; `file` names it in errors. The first problem found is the
    /// error ([`crate::inspect`] reports them all).
    pub fn from_text(
        file: &str,
        text: &str,
        registry: &Registry,
        overrides: &[String],
    ) -> Result<Self, ModelError> {
        let mut p = parse(file, text, registry, overrides)?;
        let g = build_graph(&mut p);
        p.first_problem()?;
        let cg = causal(&p.source, g)?;
        let eqs = StateEquations::new(cg).map_err(|e| core_error(&p.source, e))?;
        finish(p, eqs).map_err(|mut v| v.remove(0))
    }

    /// The figures the file declares (`[[plot]]`, [`crate::plots`]).
    #[must_use]
    pub fn plots(&self) -> &[crate::plots::Plot] {
        &self.source.plots
    }

    /// The file the model came from.
    #[must_use]
    pub fn file(&self) -> &str {
        &self.source.file
    }

    /// What loads but was likely meant otherwise, for the current settings: an output that
    /// differs only in case from another variable, events before `t_start` (applied at the
    /// start) or after `t_end` (not reached).
    #[must_use]
    pub fn notes(&self) -> Vec<ModelError> {
        let mut notes = self.notes.clone();
        let s = &self.settings;
        for ev in &self.source.events {
            let when = if ev.t < s.t_start {
                format!(
                    "before t_start = {} s: it is applied at the start",
                    s.t_start
                )
            } else if ev.t > s.t_end {
                format!("after t_end = {} s: it is not reached", s.t_end)
            } else {
                continue;
            };
            notes.push(self.source.err(
                ErrorKind::Settings,
                Some(&ev.span),
                format!("the event at t = {} s is {when}", ev.t),
            ));
        }
        notes
    }

    /// 1-based line where element `name` is defined.
    #[must_use]
    pub fn element_line(&self, name: &str) -> Option<usize> {
        self.source.element_pos(name).map(|p| p.0)
    }

    /// The scheduled events: at each event time the named parameters change (cumulatively),
    /// and every entry that uses a changed parameter is rebuilt, alone, from its declaration.
    pub fn events(&self) -> Result<Vec<Event>, ModelError> {
        events::build(&self.source, &self.equations, &self.events)
    }

    /// Run the model with its settings and keep the rows in memory; the elements are
    /// restored afterwards, so the model can run again. The rows are bounded
    /// ([`bondgraph::MAX_VALUES_IN_MEMORY`]); [`Model::run_into`] streams them instead.
    pub fn run(&mut self) -> Result<bondgraph::Outcome, ModelError> {
        self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate(eqs, x0, s, outputs, events)
        })
    }

    /// Run the model, handing each output row to `sink` as it is computed, and evaluate the
    /// `[[check]]`s at every output row and every accepted solver step (a check must hold
    /// between the rows too). The elements are restored afterwards.
    pub fn run_into(
        &mut self,
        sink: &mut dyn bondgraph::RowSink,
    ) -> Result<(bondgraph::Outcome, Vec<CheckResult>), ModelError> {
        let mut checker = CheckSink::new(self, sink)?;
        let out = self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate_into(eqs, x0, s, outputs, events, &mut checker)
        })?;
        let results = checker.results(&self.checks);
        Ok((out, results))
    }

    /// [`Model::run_into`] keeping the rows in memory (in `trajectory.rows`), bounded as
    /// [`Model::run`].
    pub fn run_checked(&mut self) -> Result<(bondgraph::Outcome, Vec<CheckResult>), ModelError> {
        bondgraph::check_in_memory(&self.settings, self.outputs.len() + 1).map_err(|e| {
            self.source
                .err(
                    ErrorKind::Settings,
                    None,
                    format!("[simulation] {}", e.message()),
                )
                .or_hint(e.hint())
                .with_source(e)
        })?;
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let (mut out, checks) = self.run_into(&mut rows)?;
        out.trajectory.rows = rows;
        Ok((out, checks))
    }

    /// Run `simulate` with the model's events, then restore the elements the events
    /// replaced (those entries alone, built with the model's values).
    pub(super) fn run_events(
        &mut self,
        simulate: impl FnOnce(
            &mut StateEquations,
            &[f64],
            &Settings,
            &[Output],
            Vec<Event>,
        ) -> bondgraph::Outcome,
    ) -> Result<bondgraph::Outcome, ModelError> {
        let events = self.events()?;
        let out = simulate(
            &mut self.equations,
            &self.x0,
            &self.settings,
            &self.outputs,
            events,
        );
        let touched = events::touched(&self.events);
        if !touched.is_empty() {
            let restore = self
                .source
                .rebuild(&self.equations, &self.parameters, &touched, None)?;
            for (id, el) in restore {
                self.equations.replace(id, el).map_err(|e| {
                    self.source
                        .err(ErrorKind::Settings, None, e.message())
                        .or_hint(e.hint())
                        .with_source(e)
                })?;
            }
        }
        Ok(out)
    }

    /// The file's text as `--set` left it, and the kinds it was built with: what a twin of
    /// the model with one value changed is built from (`crate::sensitivity`).
    pub(crate) fn text_and_registry(&self) -> (&str, &Registry) {
        (&self.source.text, &self.source.registry)
    }

    /// Build again, with the model's values, the entries the events replace (after a run
    /// that did not go through [`Model::run`], `crate::sensitivity`).
    pub(crate) fn restore_event_entries(&mut self) -> Result<(), ModelError> {
        let touched = events::touched(&self.events);
        if touched.is_empty() {
            return Ok(());
        }
        let restore = self
            .source
            .rebuild(&self.equations, &self.parameters, &touched, None)?;
        for (id, el) in restore {
            self.equations.replace(id, el).map_err(|e| {
                self.source
                    .err(ErrorKind::Settings, None, e.message())
                    .or_hint(e.hint())
                    .with_source(e)
            })?;
        }
        Ok(())
    }

    /// Compare a trajectory with the model's `[[check]]`s at its output rows only (a sample:
    /// [`Model::run_into`] checks every accepted step too).
    #[must_use]
    pub fn verify(&self, traj: &bondgraph::Trajectory) -> Vec<CheckResult> {
        checks::verify(&self.checks, &self.parameters, traj)
    }
}
