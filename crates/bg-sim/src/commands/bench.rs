//! `bg-sim bench`: every solver at every rtol against a reference, and the work–precision
//! diagram ([`bg_sim::bench`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::plot::{work_precision, WorkPrecisionLine};
use bg_sim::registry;
use bondgraph::Method;

use super::parse_floors;

/// The options of `bg-sim bench` (its summary is on `Command::Bench` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Solvers, comma-separated.
    #[arg(long, default_value = "bdf,esdirk34,tr-bdf2", value_delimiter = ',')]
    pub solvers: Vec<String>,
    /// Relative tolerances, comma-separated.
    #[arg(long, default_value = "1e-4,1e-6,1e-8", value_delimiter = ',')]
    pub rtols: Vec<f64>,
    /// A results CSV to score against (e.g. `bg-sim run --rtol 1e-10`); without it, a
    /// BDF run at --reference-rtol is the reference.
    #[arg(long, value_name = "REF.csv")]
    pub reference: Option<PathBuf>,
    /// Relative tolerance of the reference run (when no --reference is given).
    #[arg(long, default_value_t = 1e-10)]
    pub reference_rtol: f64,
    /// Columns to score, comma-separated (default: every column of the reference).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Error floor of the columns matching PATTERN (`*` matches any text), repeatable:
    /// --floor 'qb*=1e-3'. By default a column's floor is 1 % of the largest scale among
    /// the columns of its quantity.
    #[arg(long = "floor", value_name = "PATTERN=VALUE")]
    pub floors: Vec<String>,
    /// Also draw the work–precision diagram (error vs wall time per method) as PNG.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Only time the right-hand side (µs per call) and the Jacobian; no runs.
    #[arg(long)]
    pub rhs: bool,
    /// Runs per configuration (the median wall time is reported).
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// End time (s), shorter than the model's for a quick look.
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Run every configuration with the energy audit too (docs/energy.md): its rows follow,
    /// marked `+energy`, to read the audit's cost side by side.
    #[arg(long)]
    pub energy: bool,
}

/// `bg-sim bench`.
pub fn command(a: Args) -> ExitCode {
    let Args {
        model,
        solvers,
        rtols,
        reference,
        reference_rtol,
        columns,
        floors,
        plot,
        rhs,
        repeat,
        t_end,
        set,
        energy,
    } = a;
    bench(&BenchArgs {
        path: &model,
        solvers: &solvers,
        rtols: &rtols,
        reference: reference.as_deref(),
        reference_rtol,
        columns: columns.as_deref(),
        floors: &floors,
        plot: plot.as_deref(),
        rhs_only: rhs,
        repeat,
        t_end,
        set: &set,
        energy,
    })
}

struct BenchArgs<'a> {
    path: &'a Path,
    solvers: &'a [String],
    rtols: &'a [f64],
    reference: Option<&'a Path>,
    reference_rtol: f64,
    columns: Option<&'a [String]>,
    floors: &'a [String],
    plot: Option<&'a Path>,
    rhs_only: bool,
    repeat: usize,
    t_end: Option<f64>,
    set: &'a [String],
    energy: bool,
}

fn bench(a: &BenchArgs<'_>) -> ExitCode {
    use bg_sim::bench::{bench, bench_audited, reference_run, rhs_cost, table, Reference};
    let mut model = match Model::load(a.path, &registry(), a.set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    };
    if a.rhs_only {
        let c = rhs_cost(&model, 20_000);
        say!(
            "{}: {} states; rhs {:.3} µs per call, Jacobian {:.3} µs per call ({:.1} rhs-equivalents; medians of 7 samples)",
            model.file(),
            c.n,
            c.rhs_us,
            c.jacobian_us,
            c.jacobian_us / c.rhs_us
        );
        return ExitCode::SUCCESS;
    }
    let mut methods = Vec::new();
    for s in a.solvers {
        match bg_model::solver(s) {
            Ok(m) => methods.push(m),
            Err(e) => {
                tell!("error: {e}\n  hint: {}", e.hint());
                return ExitCode::from(2);
            }
        }
    }
    let Some(floors) = parse_floors(a.floors) else {
        return ExitCode::from(2);
    };
    if let Some(t) = a.t_end {
        model.settings.t_end = t;
    }
    for &r in a.rtols.iter().chain(std::iter::once(&a.reference_rtol)) {
        model.settings.rtol = r;
        if let Err(e) = model.settings.validate() {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    }
    let reference = match a.reference {
        Some(p) => Reference::read(p, a.columns, &floors).map(|r| (format!("{}", p.display()), r)),
        None => reference_run(
            &mut model,
            Method::Bdf,
            a.reference_rtol,
            a.columns,
            &floors,
        )
        .map(|(o, r)| {
            (
                format!("bdf at rtol {:e}: {}", a.reference_rtol, o.stats),
                r,
            )
        }),
    };
    let (what, reference) = match reference {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(2);
        }
    };
    say!(
        "{}: {} states, 0 → {} s; reference {what}; {} columns scored",
        model.file(),
        model.equations.n_states(),
        model.settings.t_end,
        reference.columns.len()
    );
    match bench(&mut model, &methods, a.rtols, &reference, a.repeat) {
        Ok(rows) => {
            say!("{}", table(&rows).trim_end_matches('\n'));
            if a.energy {
                match bench_audited(&mut model, &methods, a.rtols, &reference, a.repeat, true) {
                    Ok(audited) => {
                        say!("with the energy audit (+energy):");
                        say!("{}", table(&audited).trim_end_matches('\n'));
                    }
                    Err(e) => {
                        tell!("error: {e}");
                        return ExitCode::from(super::FAILED);
                    }
                }
            }
            if let Some(png) = a.plot {
                let lines: Vec<WorkPrecisionLine> = methods
                    .iter()
                    .map(|m| WorkPrecisionLine {
                        label: m.name().to_owned(),
                        points: rows
                            .iter()
                            .filter(|r| r.method == *m)
                            .filter_map(|r| {
                                r.error
                                    .as_ref()
                                    .map(|(e, _)| (r.wall.as_secs_f64() * 1e3, *e))
                            })
                            .collect(),
                    })
                    .collect();
                let title = format!(
                    "{}: work–precision",
                    model.title.as_deref().unwrap_or(model.file())
                );
                match work_precision(&title, &lines, png) {
                    Ok(p) => say!("wrote {}", p.display()),
                    Err(e) => {
                        tell!("error: {e}");
                        return ExitCode::from(1);
                    }
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(1)
        }
    }
}
