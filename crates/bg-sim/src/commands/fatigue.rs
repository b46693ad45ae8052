//! `bg-sim fatigue RESULTS.csv --column NAME --sn CURVE`: rainflow-count one column of a
//! results CSV (ASTM E1049-85), and its Palmgren–Miner damage on an S–N curve
//! (docs/fatigue.md). The cycles are of the column as written (its unit); the damage takes
//! SCF × range in Pa on the curve.
//!
//! JSON (`--format json`), fixed: `{"cycles": [{"range", "mean", "count"}], "damage",
//! "life_repeats"}` — cycles with equal range and mean merged, largest range first; the
//! damage of one pass of the history; `life_repeats` = 1/damage (`null` for no damage); with
//! `--repeat-per-year N` also `"life_years"` = 1/(N·damage) (and the residue closed by the
//! repetition instead of counted as half cycles).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_fatigue::rainflow::merge;
use bg_fatigue::{count, damage, reversals, Cycle, Residue, SnCurve};
use bg_sim::plot::Results;
use serde_json::json;

use super::BAD_INPUT;

/// The options of `bg-sim fatigue` (its summary is on `Command::Fatigue` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The results CSV (as `bg-sim run` writes it).
    pub results: PathBuf,
    /// The column to count: a stress in Pa (or a force as a stand-in).
    #[arg(long)]
    pub column: String,
    /// The S–N curve: a preset (`ec3-71`, `dnv-d`, … see docs/fatigue.md) or
    /// `m=3,range=71e6,cycles=2e6[,knee=5e6,m2=5,cutoff=1e8]` (range in Pa).
    #[arg(long)]
    pub sn: String,
    /// Stress concentration factor: multiplies every range before the S–N curve.
    #[arg(long, default_value_t = 1.0)]
    pub scf: f64,
    /// The history repeats N times a year: the residue is closed by the repetition, and the
    /// life is also given in years.
    #[arg(long, value_name = "N")]
    pub repeat_per_year: Option<f64>,
    /// Hysteresis gate: reversals smaller than this (column unit) are passed over.
    #[arg(long, default_value_t = 0.0)]
    pub gate: f64,
    /// Output: `text` (a table) or `json`.
    #[arg(long, default_value = "text")]
    pub format: String,
    /// Draw the rainflow histogram and the S–N curve with the spectrum as a PNG here.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// The counted history and its damage.
struct Report {
    cycles: Vec<Cycle>,
    damage: f64,
}

/// `bg-sim fatigue`.
pub fn command(a: &Args) -> ExitCode {
    match run(a) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}

fn run(a: &Args) -> Result<(), String> {
    let json = match a.format.as_str() {
        "text" => false,
        "json" => true,
        f => {
            return Err(format!(
                "--format `{f}`: expected `text` or `json`\n  hint: --format json"
            ))
        }
    };
    let curve = SnCurve::parse(&a.sn).map_err(|e| format!("--sn: {e}"))?;
    if !(a.scf.is_finite() && a.scf > 0.0) {
        return Err(format!(
            "--scf {}: expected a finite factor > 0\n  hint: --scf 1.0",
            a.scf
        ));
    }
    if !(a.gate.is_finite() && a.gate >= 0.0) {
        return Err(format!(
            "--gate {}: expected a finite range ≥ 0\n  hint: --gate 0",
            a.gate
        ));
    }
    if let Some(n) = a.repeat_per_year {
        if !(n.is_finite() && n > 0.0) {
            return Err(format!(
                "--repeat-per-year {n}: expected a finite number > 0\n  hint: --repeat-per-year 2000"
            ));
        }
    }
    let history = read_column(&a.results, &a.column)?;
    let residue = if a.repeat_per_year.is_some() {
        Residue::Repeat
    } else {
        Residue::Half
    };
    let cycles = count(&reversals(&history, a.gate), residue);
    let report = Report {
        damage: damage(&cycles, &curve, a.scf),
        cycles: merge(&cycles),
    };
    let life = (report.damage > 0.0).then(|| 1.0 / report.damage);
    if let Some(path) = &a.plot {
        let title = format!("Rainflow of `{}` and S–N curve {}", a.column, curve.label);
        bg_sim::plot::fatigue(
            &title,
            &report.cycles,
            &curve,
            a.scf,
            life,
            "column unit",
            path,
        )
        .map_err(|e| e.to_string())?;
    }
    if json {
        let cycles: Vec<_> = report
            .cycles
            .iter()
            .map(|c| json!({"range": c.range, "mean": c.mean, "count": c.count}))
            .collect();
        let mut out = json!({"cycles": cycles, "damage": report.damage, "life_repeats": life});
        if let Some(n) = a.repeat_per_year {
            out["life_years"] = json!(life.map(|l| l / n));
        }
        say!("{out}");
    } else {
        say!(
            "rainflow of `{}` in {} ({} samples, {} residue), S–N curve {}, SCF {}",
            a.column,
            a.results.display(),
            history.len(),
            if residue == Residue::Half {
                "half-cycle"
            } else {
                "closed"
            },
            curve.label,
            a.scf
        );
        say!("| range | mean | count |\n|---|---|---|");
        for c in &report.cycles {
            say!("| {:.6e} | {:.6e} | {} |", c.range, c.mean, c.count);
        }
        let n: f64 = report.cycles.iter().map(|c| c.count).sum();
        say!("cycles: {n}");
        say!("damage per pass: {:.6e}", report.damage);
        match life {
            Some(l) => say!("life: {l:.6e} passes"),
            None => say!("life: unlimited (every range below the cut-off)"),
        }
        if let (Some(n), Some(l)) = (a.repeat_per_year, life) {
            say!("life at {n} passes a year: {:.6e} years", l / n);
        }
    }
    Ok(())
}

/// The column `name` of the results CSV at `path`; a missing column names the near miss,
/// a NaN or infinite value names its line.
fn read_column(path: &Path, name: &str) -> Result<Vec<f64>, String> {
    let table = Results::read(path).map_err(|e| e.to_string())?;
    let Some(col) = table.column(name) else {
        let names: Vec<&str> = table.names().iter().map(String::as_str).collect();
        let hint = match bondgraph::kind::suggest(name, names.iter().copied()) {
            Some(s) => format!("did you mean `{s}`? (--column {s})"),
            None => format!("the columns are: {}", names.join(", ")),
        };
        return Err(format!(
            "{}:1: no column `{name}` in the header\n  hint: {hint}",
            path.display()
        ));
    };
    if let Some(k) = col.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "{}:{}: column `{name}` is {} there: a history must be finite\n  hint: cut the run before it failed, or count another column",
            path.display(),
            data_line(path, k).unwrap_or(k + 2),
            col[k]
        ));
    }
    if col.len() < 2 {
        return Err(format!(
            "{}: column `{name}` has {} value: nothing to count\n  hint: a history needs at least two rows",
            path.display(),
            col.len()
        ));
    }
    Ok(col.to_vec())
}

/// The 1-based line of data row `k` (0-based) of the CSV at `path`: blank lines are skipped
/// as the reader skips them.
fn data_line(path: &Path, k: usize) -> Option<usize> {
    let text = std::fs::read_to_string(path).ok()?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .nth(k + 1)
        .map(|(i, _)| i + 1)
}
