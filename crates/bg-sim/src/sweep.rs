//! Many runs of one model: `bg-sim sweep MODEL --spec SWEEP.toml`.
//!
//! A sweep spec names the values to change (any `--set` path; a bare name means
//! `parameters.NAME`), how to combine them (a full grid, or a Latin-hypercube sample with a
//! seed) and the metrics to keep per run. The model file is read once; each run applies its
//! values as `--set` overrides to that text and builds the model anew ([`Model::from_text`]),
//! so runs share nothing and run in parallel on a rayon pool. Each finished run is appended
//! to `summary.csv` at once, so an interrupted sweep keeps what it did; started again on the
//! same folder it skips the runs already there (a run is identified by a hash of its values).
//!
//! ```toml
//! [sweep]
//! design = "grid"                          # or "lhs" (with samples = N, seed = S)
//! [parameters]
//! k = [10.0, 20.0, 40.0]                   # a list
//! c = { from = 0.2, to = 1.0, n = 5 }      # n evenly spaced values, both ends included
//! "simulation.rtol" = [1e-6]               # any --set path
//! [metrics]
//! x_peak = "max(abs(x))"                   # reduction(expression over output columns)
//! t_zero = "first_crossing(v, 0)"
//! ```
//!
//! Metrics are `REDUCTION(EXPR)` or `first_crossing(EXPR, LEVEL)`, where `EXPR` is an
//! expression of the model-file syntax ([`bg_model::expr`]) over the output columns, `t` and
//! the model's parameters. Reductions: `max`, `min`, `mean`, `rms`, `initial`, `final`,
//! `time_of_max`, `time_of_min`, `first_crossing` (linear interpolation between output rows;
//! empty if never crossed). `mean` and `rms` are over the output rows (uniform `dt_out`).

mod csv;
mod design;
pub mod optimize;
mod run;
mod spec;
mod summary;
pub mod uncertainty;

use std::collections::HashMap;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use bg_model::{Model, Registry};
use rayon::prelude::*;

pub use design::{points, Point};
pub use run::{run_point, RunRow, Status};
pub use spec::{parse_metric, parse_spec, Design, Metric, Reduction, Spec, Value, Values};
pub use summary::{header, line, read_summary};

use csv::csv_split;

/// Name of the summary table in the output folder.
pub const SUMMARY: &str = "summary.csv";

/// Most runs one spec may ask for (a guard against a mistyped grid).
pub const MAX_RUNS: usize = 1_000_000;

/// Something wrong with a sweep spec or its output folder (not with one run: a run that fails
/// is a row of the summary).
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct SweepError {
    /// The file concerned (spec, model or summary).
    pub file: String,
    /// What is wrong, and what to do.
    pub message: String,
}

fn err(file: &str, message: impl Into<String>) -> SweepError {
    SweepError {
        file: file.to_owned(),
        message: message.into(),
    }
}

/// Options of [`sweep`].
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Worker threads (0: one per core).
    pub jobs: usize,
    /// Output folder; `summary.csv` (and `runs/`) go there.
    pub out_dir: PathBuf,
    /// Set to stop: running runs stop after their current step and are not recorded.
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// What a sweep did.
#[derive(Debug)]
pub struct Summary {
    /// The summary table.
    pub path: PathBuf,
    /// Runs in the design.
    pub total: usize,
    /// Runs skipped because the summary already had them.
    pub skipped: usize,
    /// Runs done now, by status.
    pub ok: usize,
    /// Runs done now that did not end `ok`.
    pub not_ok: usize,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
    /// Sum of the runs' wall times, s (÷ `wall_s` = the speed-up of the pool).
    pub run_s: f64,
    /// Runs skipped because of an interrupt (to be done by a resume).
    pub interrupted: usize,
    /// The band's files (`band.csv`, `band.png`), if the spec asks for one.
    pub band: Vec<PathBuf>,
}

/// Run a sweep of the model at `model_path`; see the module doc. Runs already in
/// `out_dir/summary.csv` (same header, same run id) are skipped.
pub fn sweep(
    model_path: &Path,
    spec: &Spec,
    registry: fn() -> Registry,
    opts: &Options,
) -> Result<Summary, SweepError> {
    let file = model_path.display().to_string();
    // the model must load as written: a mistake common to every run is an error, not N
    // rows; read as the loader reads (a FIFO or a directory refused, not waited on)
    Model::load(model_path, &registry(), &[]).map_err(|e| {
        let m = e.to_string();
        let m = m
            .strip_prefix(&format!("{file}: "))
            .map_or(m.clone(), str::to_owned);
        err(&file, m)
    })?;
    let text = fs::read_to_string(model_path)
        .map_err(|e| err(&file, format!("cannot read the model: {e}")))?;
    // a spec parameter the model lacks is a mistake common to every run (issue 24, item 8):
    // the path is checked once, with any value, before a run starts
    for (path, _) in &spec.parameters {
        bg_model::overrides::apply(&file, &text, &[format!("{path}=0")]).map_err(|e| {
            err(
                &file,
                format!("the sweep's parameter `{path}` is not in the model, so no run could use it: {e}"),
            )
        })?;
    }
    let all = points(spec);
    fs::create_dir_all(&opts.out_dir).map_err(|e| {
        err(
            &opts.out_dir.display().to_string(),
            format!("cannot create the output folder: {e}"),
        )
    })?;
    let path = opts.out_dir.join(SUMMARY);
    let shown = path.display().to_string();
    let head = header(spec).join(",");
    let mut done: HashMap<String, String> = HashMap::new();
    if path.exists() {
        let old = fs::read_to_string(&path).map_err(|e| err(&shown, e.to_string()))?;
        let mut lines = old.lines();
        if lines.next() != Some(head.as_str()) {
            return Err(err(
                &shown,
                "was written by a different sweep spec (its header differs); use another -o folder or remove it",
            ));
        }
        let width = header(spec).len();
        for l in lines {
            let f = csv_split(l);
            // a line cut short by an interrupt is not a run done
            if f.len() == width {
                done.insert(f[0].clone(), l.to_owned());
            }
        }
    }
    let todo: Vec<&Point> = all.iter().filter(|p| !done.contains_key(&p.id())).collect();
    let skipped = all.len() - todo.len();
    let keep = if spec.keep_runs || !spec.band.is_empty() {
        let d = opts.out_dir.join("runs");
        fs::create_dir_all(&d).map_err(|e| err(&d.display().to_string(), e.to_string()))?;
        Some(d)
    } else {
        None
    };
    // rows are appended as runs end, so an interrupted sweep keeps them
    let mut f = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| err(&shown, e.to_string()))?;
    if done.is_empty() {
        f.set_len(0).map_err(|e| err(&shown, e.to_string()))?;
        writeln!(f, "{head}").map_err(|e| err(&shown, e.to_string()))?;
    }
    let sink = Mutex::new((f, HashMap::<String, String>::new(), 0usize, 0usize, 0.0f64));
    let write_error: Mutex<Option<String>> = Mutex::new(None);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| err(&file, format!("cannot start the worker threads: {e}")))?;
    let start = Instant::now();
    let stopped = || {
        opts.interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    };
    pool.install(|| {
        todo.par_iter().for_each_init(registry, |reg, p| {
            if stopped() {
                return;
            }
            let row = run_point(
                &file,
                &text,
                reg,
                p,
                &spec.metrics,
                keep.as_deref(),
                opts.interrupt.as_ref(),
            );
            if stopped() {
                return; // cut short: not a result
            }
            let l = line(&row);
            if let Ok(mut s) = sink.lock() {
                if let Err(e) = writeln!(s.0, "{l}").and_then(|()| s.0.flush()) {
                    if let Ok(mut w) = write_error.lock() {
                        w.get_or_insert(e.to_string());
                    }
                }
                s.1.insert(p.id(), l);
                if row.status == Status::Ok {
                    s.2 += 1;
                } else {
                    s.3 += 1;
                }
                s.4 += row.wall_s;
            }
        });
    });
    let wall_s = start.elapsed().as_secs_f64();
    if let Some(e) = write_error.into_inner().ok().flatten() {
        return Err(err(&shown, format!("cannot write the summary: {e}")));
    }
    let (_, new, ok, not_ok, run_s) = sink
        .into_inner()
        .map_err(|_| err(&shown, "a worker panicked"))?;
    let interrupted = todo.len() - ok - not_ok;
    done.extend(new);
    // rewrite in design order, atomically
    let tmp = opts.out_dir.join(format!("{SUMMARY}.tmp"));
    let mut out = String::with_capacity(64 * (done.len() + 1));
    out.push_str(&head);
    out.push('\n');
    for p in &all {
        if let Some(l) = done.get(&p.id()) {
            out.push_str(l);
            out.push('\n');
        }
    }
    fs::write(&tmp, out)
        .and_then(|()| fs::rename(&tmp, &path))
        .map_err(|e| err(&shown, format!("cannot write the summary: {e}")))?;
    // the band over time of the runs kept ([band], docs/sweeps.md)
    let band = if spec.band.is_empty() || interrupted > 0 {
        Vec::new()
    } else {
        uncertainty::write_band(&opts.out_dir, &spec.band)?.0
    };
    Ok(Summary {
        band,
        path,
        total: all.len(),
        skipped,
        ok,
        not_ok,
        wall_s,
        run_s,
        interrupted,
    })
}
