//! `bg-sim modes`: the model's time scales, as a table or JSON ([`bg_sim::modes`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::registry;

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim modes` (its summary is on `Command::Modes` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Linearise at this time of a run (s) instead of the initial state.
    #[arg(long, value_name = "T")]
    pub at: Option<f64>,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Write JSON (for scripts) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Dominant states named per mode (those with a participation of at least 5 %).
    #[arg(long, default_value_t = 3)]
    pub top: usize,
}

/// `bg-sim modes`.
pub fn command(a: &Args) -> ExitCode {
    modes(&a.model, a.at, &a.set, a.json, a.top)
}

fn modes(path: &Path, at: Option<f64>, set: &[String], json: bool, top: usize) -> ExitCode {
    let mut model = match Model::load(path, &registry(), set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    // Before any work (the run to --at included): the analysis is dense.
    let n = model.equations.n_states();
    if n > bondgraph::MAX_MODES_STATES {
        tell!(
            "error: {}: {}\n  hint: analyse a smaller variant of the model (fewer segments of a line, fewer modes per link: --set, or the cheaper scenes of `bg-sim reduce`); `bg-sim linearize` writes A for an eigen-solver of its own",
            model.file(),
            bondgraph::ModesError::TooLarge {
                n,
                limit: bondgraph::MAX_MODES_STATES
            }
        );
        return ExitCode::from(BAD_INPUT);
    }
    if let Some(t) = at {
        if !(t.is_finite() && t >= model.settings.t_start) {
            tell!(
                "error: --at must be a finite time from t_start = {} s on, got {t}",
                model.settings.t_start
            );
            return ExitCode::from(BAD_INPUT);
        }
    }
    match bg_sim::modes::analyse(&mut model, at) {
        Ok(r) => {
            if json {
                say!("{}", r.json(top));
            } else {
                if let Some(s) = &model.steady {
                    say!("{s}");
                }
                say!("{}", r.text(top));
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(FAILED)
        }
    }
}
