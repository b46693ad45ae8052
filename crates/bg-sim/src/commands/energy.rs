//! `bg-sim energy`: run a model with its energy audit and report where the energy went, by
//! composite or (`--expand`) by element, as text, JSON or CSV, with the figure
//! (`--plot energy.png`). The tables and the figure are the library's ([`bg_sim::energy`],
//! [`bg_sim::plot::energy_bars`]); the audit is the core's ([`bondgraph::energy`]).

use std::path::PathBuf;
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::registry;

use super::{interrupt_on_signals, BAD_INPUT, FAILED};

/// How `bg-sim energy` reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum EnergyFormat {
    /// A table for a person.
    #[default]
    Text,
    /// One JSON document.
    Json,
    /// CSV, one row per composite (or element).
    Csv,
}

/// The options of `bg-sim energy` (its summary is on `Command::Energy` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// End time (s).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Relative tolerance.
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance (scaled per state by its nominal magnitude).
    #[arg(long)]
    pub atol: Option<f64>,
    /// Integration method: bdf, esdirk34, tr-bdf2, tsit45 or radau5.
    #[arg(long)]
    pub solver: Option<String>,
    /// Override a value of the model file: --set parameters.k=5 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// text, json or csv.
    #[arg(long, value_enum, default_value_t = EnergyFormat::Text)]
    pub format: EnergyFormat,
    /// Every element (and the junctions, TF, MTF) instead of one row per composite.
    #[arg(long)]
    pub expand: bool,
    /// Also draw where the energy came from and went to as a PNG.
    #[arg(long, value_name = "PNG")]
    pub plot: Option<PathBuf>,
}

/// `bg-sim energy`.
pub fn command(a: &Args) -> ExitCode {
    let mut model = match Model::load(&a.model, &registry(), &a.set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    if let Some(s) = &a.solver {
        match bg_model::solver(s) {
            Ok(m) => model.settings.method = m,
            Err(e) => {
                tell!("error: {e}\n  hint: {}", e.hint());
                return ExitCode::from(BAD_INPUT);
            }
        }
    }
    if let Some(v) = a.t_end {
        model.settings.t_end = v;
    }
    if let Some(v) = a.rtol {
        model.settings.rtol = v;
    }
    if let Some(v) = a.atol {
        model.settings.atol = v;
    }
    if let Err(e) = model.settings.validate() {
        tell!("error: {}: {e}", model.file());
        return ExitCode::from(BAD_INPUT);
    }
    model.settings.interrupt = Some(interrupt_on_signals());
    let run = match model.energy() {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let mut code = ExitCode::SUCCESS;
    if let Some(e) = &run.outcome.error {
        tell!(
            "error: {}: the run stopped early: {e}\n  the audit covers t = {} … {} s",
            model.file(),
            run.report.t_start,
            run.report.t_end
        );
        code = ExitCode::from(FAILED);
    }
    match a.format {
        EnergyFormat::Text => say!("{}", bg_sim::energy::text(&run.report, a.expand)),
        EnergyFormat::Json => say!("{:#}", bg_sim::energy::json(&run.report, a.expand)),
        EnergyFormat::Csv => say!("{}", bg_sim::energy::csv(&run.report, a.expand).trim_end()),
    }
    if let Some(png) = &a.plot {
        let title = format!(
            "Where the energy goes: {}",
            model.title.as_deref().unwrap_or(model.file())
        );
        match bg_sim::plot::energy_bars(&title, &run.report, a.expand, png) {
            Ok(p) => tell!("wrote {}", p.display()),
            Err(e) => {
                tell!("error: {e}");
                code = ExitCode::from(FAILED);
            }
        }
    }
    code
}
