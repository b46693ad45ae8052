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
        unscorable(reference, &r, |name| {
            if name == "t" {
                Some(r.t.as_slice())
            } else {
                r.columns
                    .iter()
                    .find(|c| c.0 == name)
                    .map(|c| c.1.as_slice())
            }
        })?;
        unscorable(results, &r, |name| table.column(name))?;
        let run = table.to_trajectory();
        let errors = r.errors(&run).ok_or_else(|| {
            format!(
                "{} does not cover the time span of {} or lacks one of its columns",
                results.display(),
                reference.display()
            )
        })?;
        if let Some((name, e)) = errors.iter().find(|(_, e)| !e.is_finite()) {
            return Err(format!(
                "the error of column `{name}` is {e}: the comparison cannot be scored"
            ));
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

/// Why the columns `reference` scores cannot be scored in the file `path` (read through
/// `column`): a time or a value that is NaN or infinite, or a column whose range (or
/// scale) overflows f64 (1e308 beside −1e308), named with its first row. A score of NaN or
/// infinity would read as a result; it is an error instead (issue 24, item 9).
fn unscorable<'a>(
    path: &Path,
    reference: &bg_sim::bench::Reference,
    column: impl Fn(&str) -> Option<&'a [f64]>,
) -> Result<(), String> {
    let scored = std::iter::once(("t", None))
        .chain(reference.columns.iter().map(|c| (c.0.as_str(), Some(c.2))));
    for (name, scale) in scored {
        let Some(values) = column(name) else {
            continue;
        };
        let file = path.display();
        if let Some((row, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!(
                "{file}: column `{name}` holds {v} (data row {}): a comparison cannot score a non-finite value\n  hint: the run that wrote it stopped or diverged; compare the rows before it, or rerun",
                row + 1
            ));
        }
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if values.len() > 1 && !(hi - lo).is_finite() {
            return Err(format!(
                "{file}: column `{name}` spans {lo:e} to {hi:e}, a range that overflows f64: its errors cannot be scaled"
            ));
        }
        if let Some(s) = scale.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(format!(
                "{file}: column `{name}` has the scale {s:e} (its range and mean in the reference): its errors cannot be scaled\n  hint: give it an error floor, e.g. --floor {name}=1e-9"
            ));
        }
    }
    Ok(())
}
