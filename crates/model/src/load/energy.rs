//! A model run with its energy audit ([`bondgraph::energy`]): [`Model::run_energy`] and
//! [`Model::energy`], each element's record labelled with the model file's entry it belongs
//! to (a composite's name, so that the report can be summed by composite).

use bondgraph::{EnergyAudit, EnergyReport};

use super::checks::{CheckResult, CheckSink};
use super::model::Model;
use crate::error::ModelError;
use crate::registry::Registry;

/// A run and its energy audit.
#[derive(Debug)]
pub struct EnergyRun {
    /// The run (rows, statistics, error if it stopped early).
    pub outcome: bondgraph::Outcome,
    /// The `[[check]]`s, at every output row and accepted step.
    pub checks: Vec<CheckResult>,
    /// Where the energy went, per element (`composite` set to its entry in the file).
    pub report: EnergyReport,
}

/// A sink that keeps nothing.
struct Discard;

impl bondgraph::RowSink for Discard {
    fn row(&mut self, _: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

impl Model {
    /// Run the model as [`Model::run_into`] does (rows to `sink`, checks at every step) and
    /// audit its energy ([`bondgraph::energy`]): per element supplied, stored, dissipated,
    /// activity and share, labelled with its entry of the model file.
    pub fn run_energy(
        &mut self,
        sink: &mut dyn bondgraph::RowSink,
    ) -> Result<EnergyRun, ModelError> {
        let mut audit = EnergyAudit::new(&self.equations);
        let mut checker = CheckSink::new(self, sink)?;
        let outcome = self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate_audited(eqs, x0, s, outputs, events, &mut checker, Some(&mut audit))
        })?;
        let checks = checker.results(&self.checks);
        let mut report = audit.report(&self.equations);
        for e in &mut report.elements {
            e.composite = self.entry_of(&e.name);
        }
        Ok(EnergyRun {
            outcome,
            checks,
            report,
        })
    }

    /// [`Model::run`] (rows in memory, no checks) with the energy audit: what `bg-sim bench
    /// --energy` times against [`Model::run`].
    pub fn run_audited(&mut self) -> Result<(bondgraph::Outcome, EnergyReport), ModelError> {
        let mut audit = EnergyAudit::new(&self.equations);
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut out = self.run_events(|eqs, x0, s, outputs, events| {
            bondgraph::simulate_audited(eqs, x0, s, outputs, events, &mut rows, Some(&mut audit))
        })?;
        out.trajectory.rows = rows;
        let mut report = audit.report(&self.equations);
        for e in &mut report.elements {
            e.composite = self.entry_of(&e.name);
        }
        Ok((out, report))
    }

    /// [`Model::run_energy`] keeping the rows in memory (in `outcome.trajectory.rows`),
    /// bounded as [`Model::run_checked`].
    pub fn run_energy_checked(&mut self) -> Result<EnergyRun, ModelError> {
        bondgraph::check_in_memory(&self.settings, self.outputs.len() + 1).map_err(|e| {
            self.source
                .err(
                    crate::error::ErrorKind::Settings,
                    None,
                    format!("[simulation] {}", e.message()),
                )
                .or_hint(e.hint())
                .with_source(e)
        })?;
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut run = self.run_energy(&mut rows)?;
        run.outcome.trajectory.rows = rows;
        Ok(run)
    }

    /// [`Model::run_energy`] keeping no rows.
    pub fn energy(&mut self) -> Result<EnergyRun, ModelError> {
        self.run_energy(&mut Discard)
    }

    /// The `[elements]` entry element `name` belongs to (a composite's name, or its own).
    #[must_use]
    pub fn entry_of(&self, name: &str) -> String {
        self.source
            .elements
            .iter()
            .find(|e| e.name == name || e.members.iter().any(|m| m == name))
            .map_or_else(|| name.to_owned(), |e| e.name.clone())
    }
}

/// Load `path` with `overrides` (`--set`), run it and audit its energy: the one call a tool
/// needs (`bg-sim energy`, `reduce --by activity`, Python).
pub fn energy_audit(
    path: &std::path::Path,
    registry: &Registry,
    overrides: &[String],
) -> Result<EnergyRun, ModelError> {
    Model::load(path, registry, overrides)?.energy()
}
