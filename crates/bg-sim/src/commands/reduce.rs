//! `bg-sim reduce`: the cheapest scene of the model's `[scene]` switches within a tolerance
//! ([`bg_sim::reduce`]), or, `--by activity`, the model with the kinds' declared
//! simplifications of its least active elements ([`bg_sim::simplify`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use serde_json::{json, Value};

use super::json::Format;
use super::{parse_floors, BAD_INPUT};

/// What `reduce` searches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum By {
    /// The scenes of the model's `[scene]` switches.
    #[default]
    Switches,
    /// The kinds' declared simplifications of the elements with the smallest activity share.
    Activity,
}

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
    /// What to search: the `[scene]` switches, or the simplifications the kinds declare for
    /// the elements of small activity share (the energy audit's ∫|P| dt).
    #[arg(long, value_enum, default_value_t = By::Switches)]
    pub by: By,
    /// With --by activity: simplify the elements whose activity share is below this
    /// (0.01: 1 % of the total activity).
    #[arg(long, default_value_t = bg_sim::simplify::DEFAULT_THRESHOLD)]
    pub threshold: f64,
    /// Report as text (default) or as one JSON document on stdout.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
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
        by,
        threshold,
        format,
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
    match by {
        By::Switches => reduce(&model, &o, csv.as_deref(), format),
        By::Activity => {
            if csv.is_some() || search != bg_sim::reduce::Search::Auto {
                tell!("error: --csv and --search belong to the switch search\n  hint: drop them with --by activity");
                return ExitCode::from(BAD_INPUT);
            }
            by_activity(&model, &o, threshold, format)
        }
    }
}

fn reduce(
    path: &Path,
    o: &bg_sim::reduce::ReduceOptions,
    csv: Option<&Path>,
    format: Format,
) -> ExitCode {
    let r = match bg_sim::reduce::reduce(path, o) {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    if format == Format::Json {
        let scene = |t: &bg_sim::reduce::SceneRun| {
            let (col, err) = t.worst().map_or((None, None), |(c, e)| (Some(c), Some(e)));
            json!({
                "scene": t.label,
                "set": r.scene.overrides(&t.pick),
                "states": t.states,
                "steps": t.steps,
                "wall_ms": t.wall.as_secs_f64() * 1e3,
                "errors": errors_json(&t.errors),
                "worst_column": col,
                "worst_error": err,
                "passes": t.passes(r.tol),
                "failure": t.failure,
            })
        };
        let doc = json!({
            "model": path.display().to_string(),
            "by": "switches",
            "tol": r.tol,
            "search": r.search.name(),
            "grid_size": r.scene.grid_size(),
            "tried": r.tried.iter().map(scene).collect::<Vec<_>>(),
            "answer": scene(r.answer()),
            "reference_wall_ms": r.reference_wall.as_secs_f64() * 1e3,
            "answer_wall_ms": r.answer_wall.as_secs_f64() * 1e3,
            "speedup": r.speedup(),
        });
        say!("{doc:#}");
        return ExitCode::SUCCESS;
    }
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

/// The scored columns' errors as a JSON object.
fn errors_json(errors: &[(String, f64)]) -> Value {
    Value::Object(errors.iter().map(|(c, e)| (c.clone(), json!(e))).collect())
}

fn by_activity(
    path: &Path,
    o: &bg_sim::reduce::ReduceOptions,
    threshold: f64,
    format: Format,
) -> ExitCode {
    let r = match bg_sim::simplify::reduce_by_activity(
        path,
        &bg_sim::registry(),
        o,
        threshold,
        &bg_sim::simplify::energy_audit,
    ) {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let full = &r.trials[0];
    let a = r.answer();
    if format == Format::Json {
        let candidate = |c: &bg_sim::simplify::Candidate| {
            json!({
                "element": c.instance,
                "kind": c.kind,
                "simplification": c.simplification.name,
                "doc": c.simplification.doc,
                "changes": c.simplification.changes.iter().map(ToString::to_string).collect::<Vec<_>>(),
                "share": c.share,
                "proposed": c.share < r.threshold,
            })
        };
        let trial = |t: &bg_sim::simplify::Trial| {
            let (col, err) = t.worst().map_or((None, None), |(c, e)| (Some(c), Some(e)));
            json!({
                "applied": t.applied.iter().filter_map(|&i| r.candidates.get(i).map(bg_sim::simplify::Candidate::label)).collect::<Vec<_>>(),
                "states": t.states,
                "steps": t.steps,
                "wall_ms": t.wall.as_secs_f64() * 1e3,
                "errors": errors_json(&t.errors),
                "worst_column": col,
                "worst_error": err,
                "passes": t.passes(r.tol),
                "failure": t.failure,
            })
        };
        let doc = json!({
            "model": path.display().to_string(),
            "by": "activity",
            "tol": r.tol,
            "threshold": r.threshold,
            "ranking": r.ranking.iter().map(|e| json!({
                "element": e.name, "entry": e.composite, "activity": e.activity, "share": e.share,
            })).collect::<Vec<_>>(),
            "candidates": r.candidates.iter().map(candidate).collect::<Vec<_>>(),
            "trials": r.trials.iter().map(trial).collect::<Vec<_>>(),
            "answer": trial(a),
            "simplified": r.applied().into_iter().map(candidate).collect::<Vec<_>>(),
            "reference_wall_ms": r.reference_wall.as_secs_f64() * 1e3,
            "answer_wall_ms": r.answer_wall.as_secs_f64() * 1e3,
            "speedup": r.speedup(),
            "step_ratio": r.step_ratio(),
        });
        say!("{doc:#}");
        return ExitCode::SUCCESS;
    }
    say!(
        "{}: activity ranking of the full model ({} states, {} steps); tol {:e}, threshold {:e} of the total activity",
        path.display(),
        full.states,
        full.steps,
        r.tol,
        r.threshold
    );
    say!("| element | entry | activity (J) | share |\n|---|---|---|---|");
    for e in r.ranking.iter().filter(|e| e.share > 0.0) {
        say!(
            "| {} | {} | {:.3e} | {:.2e} |",
            e.name,
            e.composite,
            e.activity,
            e.share
        );
    }
    if r.candidates.is_empty() {
        say!("no element declares a simplification that would change this model");
    } else {
        say!("simplifications the kinds declare (proposed: share < threshold):");
        say!("| element | simplification | share | proposed |\n|---|---|---|---|");
        for c in &r.candidates {
            say!(
                "| {} | {} ({}) | {:.2e} | {} |",
                c.instance,
                c.simplification.name,
                c.simplification.doc,
                c.share,
                if c.share < r.threshold { "yes" } else { "no" }
            );
        }
    }
    say!("{}", r.table().trim_end_matches('\n'));
    if r.answer == 0 {
        say!(
            "answer: the full model: {} of the simplifications proposed keeps the columns within {:e}",
            if r.proposed() == 0 { "none" } else { "no set" },
            r.tol
        );
    } else {
        let (col, err) = a.worst().unwrap_or(("?", f64::NAN));
        say!(
            "answer: {} simplified (worst {col} {err:.2e} ≤ {:e}); {} states, {} steps against {} and {} ({:.2}× fewer steps); {:.1} ms against {:.1} ms, {:.2}× faster (each the median of {} runs alone)",
            r.applied()
                .iter()
                .map(|c| c.label())
                .collect::<Vec<_>>()
                .join(", "),
            r.tol,
            a.states,
            a.steps,
            full.states,
            full.steps,
            r.step_ratio(),
            r.answer_wall.as_secs_f64() * 1e3,
            r.reference_wall.as_secs_f64() * 1e3,
            r.speedup(),
            o.repeat.max(1)
        );
        say!("error per column:");
        for (c, e) in &a.errors {
            say!("  {c}: {e:.2e}");
        }
    }
    ExitCode::SUCCESS
}
