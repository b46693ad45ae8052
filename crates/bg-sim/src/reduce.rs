//! `bg-sim reduce`: the cheapest scene whose results stay within a tolerance of the richest.
//!
//! A model declares its scene switches in `[scene]` ([`bg_model::Scene`]): a `--set` key and
//! its choices, richest first. The richest scene (every switch at its first choice) is run
//! as the reference; every other scene is scored with the scaled error of `bench --reference`
//! ([`Reference`]: per column, the largest |x − x_ref| over the output rows divided by the
//! column's scale) on the named columns, and it *passes* if its worst column stays at or below
//! the tolerance. The answer is the passing scene with the shortest integration time.
//!
//! # Search
//! * [`Search::Grid`]: every scene of the grid (the product of the choices).
//! * [`Search::Greedy`]: from the richest scene, each round tries, for every switch, each of
//!   its cheaper choices with the other switches kept; of those that pass, the fastest becomes
//!   the current scene; it stops when none passes. A round moves at least one switch down,
//!   so it ends after at most Σ(choices − 1) rounds; the runs are cached.
//! * [`Search::Auto`] (the default): the grid when it has at most [`AUTO_GRID_LIMIT`] scenes,
//!   else greedy.
//!
//! The runs of a round (or of the grid) run on `jobs` threads, each loading the model afresh
//! with its overrides. Their wall times are measured side by side, so the reference and the
//! [`RETIMED`] fastest passing scenes are then timed again one at a time (median of `repeat`
//! runs); the fastest of those is the answer if it beats the reference, and the speed-up is
//! of these times.

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use bg_model::{Model, Scene};
use bondgraph::{Method, Trajectory};

use crate::bench::{matches, Reference};
use crate::registry;

/// How many of the fastest passing scenes are timed again alone.
pub const RETIMED: usize = 4;

/// Largest grid that [`Search::Auto`] runs whole.
pub const AUTO_GRID_LIMIT: usize = 400;

/// How the scenes are searched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Search {
    /// The grid when small, else greedy.
    Auto,
    /// Every scene.
    Grid,
    /// One switch at a time from the richest scene.
    Greedy,
}

impl Search {
    /// Parse `auto`, `grid` or `greedy`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Self::Auto),
            "grid" => Some(Self::Grid),
            "greedy" => Some(Self::Greedy),
            _ => None,
        }
    }

    /// Its name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Grid => "grid",
            Self::Greedy => "greedy",
        }
    }
}

/// What `reduce` is asked.
#[derive(Clone, Debug)]
pub struct ReduceOptions {
    /// Largest scaled error a scene may have on the scored columns.
    pub tol: f64,
    /// Scored columns (every output column if `None`).
    pub columns: Option<Vec<String>>,
    /// Error floors (`PATTERN`, value), as for `bench --floor`.
    pub floors: Vec<(String, f64)>,
    /// Fixed scales (`PATTERN`, value): the error of a matching column is |x − x_ref| / value,
    /// e.g. `x_e3=1` for an error in metres.
    pub scales: Vec<(String, f64)>,
    /// End time, if shorter than the model's.
    pub t_end: Option<f64>,
    /// Solver, if not the model's.
    pub method: Option<Method>,
    /// Relative tolerance, if not the model's.
    pub rtol: Option<f64>,
    /// `--set` overrides applied before every scene's.
    pub set: Vec<String>,
    /// The search.
    pub search: Search,
    /// Threads running scenes side by side.
    pub jobs: usize,
    /// Runs of the reference and of the answer for their timing (median).
    pub repeat: usize,
}

impl ReduceOptions {
    /// Defaults: tolerance `tol`, every column, the model's settings, auto search, as many
    /// jobs as cores, 3 timing runs.
    #[must_use]
    pub fn new(tol: f64) -> Self {
        Self {
            tol,
            columns: None,
            floors: Vec::new(),
            scales: Vec::new(),
            t_end: None,
            method: None,
            rtol: None,
            set: Vec::new(),
            search: Search::Auto,
            jobs: std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
            repeat: 3,
        }
    }
}

/// The worst of scored columns' errors (a NaN counts as worst), shared by the switch search
/// and `--by activity`.
#[must_use]
pub fn worst_of(errors: &[(String, f64)]) -> Option<(&str, f64)> {
    errors
        .iter()
        .fold(None, |w: Option<(&str, f64)>, (n, e)| match w {
            Some((_, we)) if !(*e > we || e.is_nan()) => w,
            _ => Some((n.as_str(), *e)),
        })
}

/// One scene run and its score.
#[derive(Clone, Debug)]
pub struct SceneRun {
    /// The choice of each switch (index into its choices).
    pub pick: Vec<usize>,
    /// `name=label …`.
    pub label: String,
    /// States of the scene.
    pub states: usize,
    /// Accepted steps.
    pub steps: usize,
    /// Wall time of the integration.
    pub wall: Duration,
    /// Scaled error of every scored column (empty if the run failed).
    pub errors: Vec<(String, f64)>,
    /// Why the scene failed to load or run, if it did.
    pub failure: Option<String>,
}

impl SceneRun {
    /// The worst scored column and its error.
    #[must_use]
    pub fn worst(&self) -> Option<(&str, f64)> {
        worst_of(&self.errors)
    }

    /// Whether the scene ran and its worst column is within `tol`.
    #[must_use]
    pub fn passes(&self, tol: f64) -> bool {
        self.failure.is_none() && self.worst().is_some_and(|(_, e)| e <= tol)
    }
}

/// What `reduce` found.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// The switches searched.
    pub scene: Scene,
    /// The search used (never `Auto`).
    pub search: Search,
    /// The tolerance.
    pub tol: f64,
    /// Every scene run, the reference first, in the order they were tried.
    pub tried: Vec<SceneRun>,
    /// Index into `tried` of the answer (0, the reference, if no cheaper scene passes).
    pub answer: usize,
    /// Median wall time of the reference timed alone.
    pub reference_wall: Duration,
    /// Median wall time of the answer timed alone.
    pub answer_wall: Duration,
}

impl Reduction {
    /// The answer's run.
    #[must_use]
    pub fn answer(&self) -> &SceneRun {
        &self.tried[self.answer]
    }

    /// How many times faster the answer is than the reference (timed alone).
    #[must_use]
    pub fn speedup(&self) -> f64 {
        self.reference_wall.as_secs_f64() / self.answer_wall.as_secs_f64().max(1e-9)
    }

    /// The table of the scenes tried, as Markdown.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::from("|");
        for sw in &self.scene.switches {
            s.push_str(&format!(" {} |", sw.name));
        }
        s.push_str(" states | steps | wall (ms) | worst column | scaled error | within tol |\n|");
        for _ in 0..self.scene.switches.len() + 6 {
            s.push_str("---|");
        }
        s.push('\n');
        for (i, r) in self.tried.iter().enumerate() {
            s.push('|');
            for (sw, &k) in self.scene.switches.iter().zip(&r.pick) {
                s.push_str(&format!(
                    " {} |",
                    sw.choices.get(k).map_or("?", |c| c.label.as_str())
                ));
            }
            let (col, err, ok) = match (&r.failure, r.worst()) {
                (Some(f), _) => (
                    f.chars().take(70).collect::<String>(),
                    "failed".to_owned(),
                    "no",
                ),
                (None, Some((c, e))) => (
                    c.to_owned(),
                    format!("{e:.2e}"),
                    if i == 0 {
                        "reference"
                    } else if e <= self.tol {
                        "yes"
                    } else {
                        "no"
                    },
                ),
                (None, None) => (String::new(), "–".to_owned(), "no"),
            };
            let ok = if i == self.answer {
                format!("{ok} ← answer")
            } else {
                ok.to_owned()
            };
            s.push_str(&format!(
                " {} | {} | {:.1} | {col} | {err} | {ok} |\n",
                r.states,
                r.steps,
                r.wall.as_secs_f64() * 1e3
            ));
        }
        s
    }

    /// Every scene tried with the error of every scored column, as CSV.
    #[must_use]
    pub fn csv(&self) -> String {
        let cols: Vec<&str> = self
            .tried
            .first()
            .map(|r| r.errors.iter().map(|(n, _)| n.as_str()).collect())
            .unwrap_or_default();
        let mut s = String::new();
        for sw in &self.scene.switches {
            s.push_str(&sw.name);
            s.push(',');
        }
        s.push_str("states,steps,wall_ms,worst_column,worst_error");
        for c in &cols {
            s.push(',');
            s.push_str(c);
        }
        s.push('\n');
        for r in &self.tried {
            for (sw, &k) in self.scene.switches.iter().zip(&r.pick) {
                s.push_str(sw.choices.get(k).map_or("?", |c| c.label.as_str()));
                s.push(',');
            }
            let (wc, we) = r
                .worst()
                .map_or(("failed".to_owned(), f64::NAN), |(c, e)| (c.to_owned(), e));
            s.push_str(&format!(
                "{},{},{:.3},{wc},{we:e}",
                r.states,
                r.steps,
                r.wall.as_secs_f64() * 1e3
            ));
            for c in &cols {
                let e = r
                    .errors
                    .iter()
                    .find(|(n, _)| n == c)
                    .map_or(f64::NAN, |(_, e)| *e);
                s.push_str(&format!(",{e:e}"));
            }
            s.push('\n');
        }
        s
    }
}

/// Load `path` with the user's overrides, then those of scene `pick`, and apply the options'
/// settings.
fn load_scene(
    path: &Path,
    scene: &Scene,
    pick: &[usize],
    o: &ReduceOptions,
) -> Result<Model, String> {
    let mut set = o.set.clone();
    set.extend(scene.overrides(pick));
    let mut m = Model::load(path, &registry(), &set).map_err(|e| e.to_string())?;
    if let Some(t) = o.t_end {
        m.settings.t_end = t;
    }
    if let Some(me) = o.method {
        m.settings.method = me;
    }
    if let Some(r) = o.rtol {
        m.settings.rtol = r;
    }
    m.settings.validate().map_err(|e| e.to_string())?;
    Ok(m)
}

/// Load and run one scene; the trajectory if it completed.
fn run_scene(
    path: &Path,
    scene: &Scene,
    pick: &[usize],
    o: &ReduceOptions,
) -> (SceneRun, Option<Trajectory>) {
    let mut r = SceneRun {
        pick: pick.to_vec(),
        label: scene.describe(pick),
        states: 0,
        steps: 0,
        wall: Duration::ZERO,
        errors: Vec::new(),
        failure: None,
    };
    let mut model = match load_scene(path, scene, pick, o) {
        Ok(m) => m,
        Err(e) => {
            r.failure = Some(format!("does not load: {e}"));
            return (r, None);
        }
    };
    r.states = model.equations.n_states();
    match model.run() {
        Ok(out) => {
            r.steps = out.stats.steps;
            r.wall = out.stats.wall_time;
            if let Some(e) = out.error {
                r.failure = Some(e.to_string());
                (r, None)
            } else {
                (r, Some(out.trajectory))
            }
        }
        Err(e) => {
            r.failure = Some(e.to_string());
            (r, None)
        }
    }
}

/// Run `picks` on `jobs` threads and score them against `reference`.
fn run_all(
    path: &Path,
    scene: &Scene,
    picks: &[Vec<usize>],
    o: &ReduceOptions,
    reference: &Reference,
) -> Vec<SceneRun> {
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<Option<SceneRun>>> = Mutex::new(vec![None; picks.len()]);
    let jobs = o.jobs.clamp(1, picks.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(pick) = picks.get(i) else { break };
                let (mut r, traj) = run_scene(path, scene, pick, o);
                if let Some(t) = traj {
                    match reference.errors(&t) {
                        Some(e) => r.errors = e,
                        None => {
                            r.failure = Some(
                                "its rows do not match the reference's times or columns".into(),
                            );
                        }
                    }
                }
                if let Ok(mut d) = done.lock() {
                    d[i] = Some(r);
                }
            });
        }
    });
    done.into_inner()
        .unwrap_or_default()
        .into_iter()
        .flatten()
        .collect()
}

/// Median integration time of `repeat` runs of scene `pick`, one at a time.
fn time_alone(path: &Path, scene: &Scene, pick: &[usize], o: &ReduceOptions) -> Duration {
    let mut walls: Vec<Duration> = (0..o.repeat.max(1))
        .map(|_| run_scene(path, scene, pick, o).0.wall)
        .collect();
    walls.sort();
    walls[walls.len() / 2]
}

/// Search the scenes of the model at `path` (see the module doc).
///
/// # Errors
/// The model does not load, declares no `[scene]`, the options are invalid, or the
/// reference (richest) scene fails.
pub fn reduce(path: &Path, o: &ReduceOptions) -> Result<Reduction, String> {
    if !(o.tol.is_finite() && o.tol > 0.0) {
        return Err(format!(
            "--tol must be finite and > 0, got {}\n  hint: e.g. --tol 1e-2 for 1 % of each column's scale",
            o.tol
        ));
    }
    let base = Model::load(path, &registry(), &o.set).map_err(|e| e.to_string())?;
    let scene = base.scene.clone();
    if scene.is_empty() {
        return Err(format!(
            "{} declares no scene switches\n  hint: add a [scene] table, e.g. `modes = {{ set = \"parameters.modes\", choices = [10, 5, 0] }}` (docs/model-format.md)",
            base.file()
        ));
    }
    let n = scene.switches.len();
    let richest = vec![0; n];
    let (mut first, traj) = run_scene(path, &scene, &richest, o);
    let traj = match (traj, &first.failure) {
        (Some(t), _) => t,
        (None, f) => {
            return Err(format!(
                "the richest scene ({}) failed: {}",
                first.label,
                f.as_deref().unwrap_or("no rows")
            ))
        }
    };
    let mut reference = Reference::from_trajectory(&traj, o.columns.as_deref(), &o.floors)?;
    for (name, _, scale) in &mut reference.columns {
        if let Some((_, v)) = o.scales.iter().find(|(p, _)| matches(p, name)) {
            *scale = *v;
        }
    }
    first.errors = reference.errors(&traj).unwrap_or_default();
    let search = match o.search {
        Search::Auto if scene.grid_size() <= AUTO_GRID_LIMIT => Search::Grid,
        Search::Auto => Search::Greedy,
        s => s,
    };
    let mut tried = vec![first];
    match search {
        Search::Grid | Search::Auto => {
            let mut picks = Vec::new();
            let mut pick = richest.clone();
            'grid: loop {
                // next in odometer order, the last switch fastest
                let mut i = n;
                loop {
                    if i == 0 {
                        break 'grid;
                    }
                    i -= 1;
                    pick[i] += 1;
                    if pick[i] < scene.switches[i].choices.len() {
                        break;
                    }
                    pick[i] = 0;
                }
                picks.push(pick.clone());
            }
            tried.extend(run_all(path, &scene, &picks, o, &reference));
        }
        Search::Greedy => {
            let mut seen: HashMap<Vec<usize>, usize> = HashMap::new();
            seen.insert(richest.clone(), 0);
            let mut current = richest;
            loop {
                let mut candidates = Vec::new();
                for i in 0..n {
                    for k in current[i] + 1..scene.switches[i].choices.len() {
                        let mut p = current.clone();
                        p[i] = k;
                        candidates.push(p);
                    }
                }
                let fresh: Vec<Vec<usize>> = candidates
                    .iter()
                    .filter(|p| !seen.contains_key(*p))
                    .cloned()
                    .collect();
                for r in run_all(path, &scene, &fresh, o, &reference) {
                    seen.insert(r.pick.clone(), tried.len());
                    tried.push(r);
                }
                let best = candidates
                    .iter()
                    .filter_map(|p| seen.get(p).copied())
                    .filter(|&i| tried[i].passes(o.tol))
                    .min_by_key(|&i| tried[i].wall);
                match best {
                    Some(i) => current = tried[i].pick.clone(),
                    None => break,
                }
            }
        }
    }
    // Times measured side by side are noisy: the fastest few passing scenes are timed again
    // alone, and the fastest of those is the answer if it beats the reference.
    let mut passing: Vec<usize> = (1..tried.len())
        .filter(|&i| tried[i].passes(o.tol))
        .collect();
    passing.sort_by_key(|&i| tried[i].wall);
    passing.truncate(RETIMED);
    let reference_wall = time_alone(path, &scene, &tried[0].pick, o);
    let (answer, answer_wall) = passing
        .into_iter()
        .map(|i| (i, time_alone(path, &scene, &tried[i].pick, o)))
        .min_by_key(|&(_, w)| w)
        .filter(|&(_, w)| w < reference_wall)
        .unwrap_or((0, reference_wall));
    Ok(Reduction {
        scene,
        search,
        tol: o.tol,
        tried,
        answer,
        reference_wall,
        answer_wall,
    })
}
