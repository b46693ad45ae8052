//! `bg-sim reduce`: the cheapest scene of the model's `[scene]` switches within a tolerance
//! ([`bg_sim::reduce`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::{parse_floors, BAD_INPUT};

/// The options of `bg-sim reduce` (its summary is on `Command::Reduce` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file (with a `[scene]` table).
    pub model: PathBuf,
    /// Largest scaled error of the scored columns (as in `bench`: |x − x_ref| / scale).
    #[arg(long)]
    pub tol: f64,
    /// Columns to score, comma-separated (default: every output column).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// End time (s), shorter than the model's.
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Solver of every run (default: the model's).
    #[arg(long)]
    pub solver: Option<String>,
    /// Relative tolerance of every run (default: the model's).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Search: auto (the grid up to 400 scenes, else greedy), grid or greedy.
    #[arg(long, default_value = "auto")]
    pub search: String,
    /// Scenes run side by side (default: the number of cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Runs of the reference and of the answer, timed alone (median).
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Error floor of the columns matching PATTERN, repeatable (as for `bench`).
    #[arg(long = "floor", value_name = "PATTERN=VALUE")]
    pub floors: Vec<String>,
    /// Fixed scale of the columns matching PATTERN, repeatable: --scale 'x_e3=1' scores
    /// x_e3 in its own unit (an error of 1e-3 is 1 mm).
    #[arg(long = "scale", value_name = "PATTERN=VALUE")]
    pub scales: Vec<String>,
    /// Also write every scene's error per column to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Override a value of the model file before every scene's (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// `bg-sim reduce`: the options checked, then the search.
pub fn command(a: Args) -> ExitCode {
    let Args {
        model,
        tol,
        columns,
        t_end,
        solver,
        rtol,
        search,
        jobs,
        repeat,
        floors,
        scales,
        csv,
        set,
    } = a;
    let Some(floors) = parse_floors(&floors) else {
        return ExitCode::from(BAD_INPUT);
    };
    let Some(scales) = parse_floors(&scales) else {
        return ExitCode::from(BAD_INPUT);
    };
    let Some(search) = bg_sim::reduce::Search::parse(&search) else {
        tell!("error: unknown search `{search}`\n  hint: auto, grid or greedy");
        return ExitCode::from(BAD_INPUT);
    };
    let method = match solver.as_deref().map(bg_model::solver).transpose() {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}\n  hint: {}", e.hint());
            return ExitCode::from(BAD_INPUT);
        }
    };
    let mut o = bg_sim::reduce::ReduceOptions::new(tol);
    o.columns = columns;
    o.t_end = t_end;
    o.method = method;
    o.rtol = rtol;
    o.search = search;
    if let Some(j) = jobs {
        o.jobs = j.max(1);
    }
    o.repeat = repeat;
    o.floors = floors;
    o.scales = scales;
    o.set = set;
    reduce(&model, &o, csv.as_deref())
}

fn reduce(path: &Path, o: &bg_sim::reduce::ReduceOptions, csv: Option<&Path>) -> ExitCode {
    let r = match bg_sim::reduce::reduce(path, o) {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    say!(
        "{}: {} switches, {} scenes in the grid; {} search, {} scenes run on {} threads; tol {:e}",
        path.display(),
        r.scene.switches.len(),
        r.scene.grid_size(),
        r.search.name(),
        r.tried.len(),
        o.jobs,
        r.tol
    );
    say!("{}", r.table().trim_end_matches('\n'));
    let a = r.answer();
    if r.answer == 0 {
        let passed = (1..r.tried.len())
            .filter(|&i| r.tried[i].passes(r.tol))
            .count();
        say!(
            "answer: the richest scene, {}: of the {} cheaper scenes tried, {passed} stay within {:e} and none of them runs faster",
            a.label,
            r.tried.len() - 1,
            r.tol
        );
    } else {
        let (col, err) = a.worst().unwrap_or(("?", f64::NAN));
        say!(
            "answer: {} (worst {col} {err:.2e} ≤ {:e}); {:.1} ms against {:.1} ms for the richest scene ({}), {:.1}× faster (each the median of {} runs alone)",
            a.label,
            r.tol,
            r.answer_wall.as_secs_f64() * 1e3,
            r.reference_wall.as_secs_f64() * 1e3,
            r.tried[0].label,
            r.speedup(),
            o.repeat.max(1)
        );
        // quoted for a shell where a value is a TOML string
        let sets: Vec<String> = r
            .scene
            .overrides(&a.pick)
            .into_iter()
            .map(|o| {
                if o.contains(['"', ' ', '\'']) {
                    format!("'{}'", o.replace('\'', "'\\''"))
                } else {
                    o
                }
            })
            .collect();
        say!("  --set {}", sets.join(" --set "));
    }
    if let Some(p) = csv {
        if let Err(e) = std::fs::write(p, r.csv()) {
            tell!("error: cannot write {}: {e}", p.display());
            return ExitCode::from(BAD_INPUT);
        }
        say!("wrote {}", p.display());
    }
    ExitCode::SUCCESS
}
