//! `bg-sim compare`: score a results CSV against a reference, column by column, with the
//! scaled error of `bench`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_sim::plot::Results;

use super::parse_floors;

/// The options of `bg-sim compare` (its summary is on `Command::Compare` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The results to score.
    pub results: PathBuf,
    /// The reference results (same time span).
    pub reference: PathBuf,
    /// Columns to score, comma-separated (default: every column of the reference).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Error floor of the columns matching PATTERN, repeatable (as for `bench`).
    #[arg(long = "floor", value_name = "PATTERN=VALUE")]
    pub floors: Vec<String>,
}

/// `bg-sim compare`.
pub fn command(a: &Args) -> ExitCode {
    compare(&a.results, &a.reference, a.columns.as_deref(), &a.floors)
}

fn compare(
    results: &Path,
    reference: &Path,
    columns: Option<&[String]>,
    floors: &[String],
) -> ExitCode {
    let Some(floors) = parse_floors(floors) else {
        return ExitCode::from(2);
    };
    let scored = bg_sim::bench::Reference::read(reference, columns, &floors).and_then(|r| {
        let table = Results::read(results).map_err(|e| e.to_string())?;
        bg_sim::bench::unscorable(reference, &r, |name| {
            if name == "t" {
                Some(r.t.as_slice())
            } else {
                r.columns
                    .iter()
                    .find(|c| c.0 == name)
                    .map(|c| c.1.as_slice())
            }
        })?;
        bg_sim::bench::unscorable(results, &r, |name| table.column(name))?;
        let run = table.to_trajectory();
        let errors = r.errors(&run).ok_or_else(|| {
            format!(
                "{} does not cover the time span of {} or lacks one of its columns",
                results.display(),
                reference.display()
            )
        })?;
        if let Some((name, e)) = errors.iter().find(|(_, e)| !e.is_finite()) {
            let zero = r.columns.iter().any(|c| &c.0 == name && c.2 == 0.0);
            return Err(if zero {
                format!(
                    "column `{name}` is zero throughout {} (scale 0e0) but not in {}: its errors cannot be scaled\n  hint: give it an error floor, e.g. --floor {name}=1e-9",
                    reference.display(),
                    results.display()
                )
            } else {
                format!("the error of column `{name}` is {e}: the comparison cannot be scored")
            });
        }
        Ok((r, errors))
    });
    match scored {
        Ok((r, errors)) => {
            say!("| column | scale | scaled error |\n|---|---|---|");
            for ((name, e), (_, _, scale)) in errors.iter().zip(&r.columns) {
                say!("| {name} | {scale:.4e} | {e:.3e} |");
            }
            if let Some((name, e)) = errors.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
                say!("worst: {name} {e:.3e}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(2)
        }
    }
}
