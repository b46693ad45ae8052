//! `bg-sim reduce --by activity`: reduction by activity (Louca and Stein's MORA).
//!
//! The full model is run once with its energy audit; every element's activity
//! A_i = ∫|P_i| dt and its share of the total rank the elements ([`ElementActivity`]). The
//! kinds declare what an instance can be simplified to ([`Simplification`], beside their
//! parameters in [`bondgraph::kind::KindDecl`]): each simplification names the members whose
//! energy flow it removes, and its share is the sum of theirs. Every simplification of the
//! model file's entries whose share is below the threshold (`--threshold`, default 1 %) and
//! that changes something ([`Candidate`]) is proposed.
//!
//! # Search: all, then back off greedily
//! 1. Every proposed simplification at once: one run. If it stays within the tolerance on the
//!    scored columns (the scoring of `reduce`, [`crate::reduce`]), that is the answer.
//! 2. Else, from the full model, lowest activity first: each simplification is added to those
//!    kept so far and kept if the model still loads, runs and stays within the tolerance.
//!    A simplification that overrides every key of one kept before on the same entry
//!    replaces it (`no_lumped_masses` after `rigid_lumped_masses`).
//!
//! The answer and the full model are then timed alone (median of `repeat` runs), and the
//! speed-up is given in wall time and in accepted steps.
//!
//! The simplifications are applied to the model file's text ([`apply`]): the reducer knows
//! the changes (set a key, remove one, set a key in every entry of a list), never the kind.
//! With `--columns`, every run (the full model's too) keeps only the scored outputs and no
//! `[[check]]` ([`keep_only`]): an output reading a variable that a simplification removes
//! would otherwise stop the reduced model from loading.
//!
//! # Files
//! `mod.rs` ranks, searches and times; `edit.rs` edits the model file's text; `tests.rs`.

use std::path::Path;
use std::time::Duration;

use bg_model::{Model, Registry};
use bondgraph::kind::Simplification;
use bondgraph::{Outcome, Trajectory};

use crate::bench::{matches, Reference};
use crate::reduce::ReduceOptions;

mod edit;
pub use edit::{apply, candidates, keep_only};

/// Default largest activity share of a proposed simplification.
pub const DEFAULT_THRESHOLD: f64 = 1e-2;

/// The activity of one element over the full run (what the energy audit gives).
#[derive(Clone, Debug, PartialEq)]
pub struct ElementActivity {
    /// Global element name (`cyl1_leak`).
    pub name: String,
    /// The model file's entry it belongs to (`cyl1`; its own name for a plain element).
    pub composite: String,
    /// A_i = ∫|P_i| dt, J.
    pub activity: f64,
    /// A_i over the sum of every element's activity.
    pub share: f64,
}

/// The run of the full model with its activity ranking: the seam where the energy audit
/// plugs in. It runs the model as loaded (its settings already set) and returns the outcome
/// and every element's activity.
pub type Audit<'a> = dyn Fn(&mut Model) -> Result<(Outcome, Vec<ElementActivity>), String> + 'a;

/// The energy audit ([`bg_model::Model::run_energy`], `bg-sim energy`) as the [`Audit`] of
/// the reduction: the run's rows kept, every element's activity and share, labelled with its
/// entry of the model file.
///
/// # Errors
/// The model cannot be run.
pub fn energy_audit(m: &mut Model) -> Result<(Outcome, Vec<ElementActivity>), String> {
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let run = m.run_energy(&mut rows).map_err(|e| e.to_string())?;
    let mut outcome = run.outcome;
    outcome.trajectory.rows = rows;
    let ranking = run
        .report
        .elements
        .into_iter()
        .map(|e| ElementActivity {
            name: e.name,
            composite: e.composite,
            activity: e.activity,
            share: e.share,
        })
        .collect();
    Ok((outcome, ranking))
}

/// One proposed simplification of one entry of the model file.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// The entry (`[elements] cyl1`).
    pub instance: String,
    /// Its kind.
    pub kind: String,
    /// What the kind declares.
    pub simplification: Simplification,
    /// The summed activity share of the members it removes.
    pub share: f64,
}

impl Candidate {
    /// `cyl1: no_internal_leakage`.
    #[must_use]
    pub fn label(&self) -> String {
        format!("{}: {}", self.instance, self.simplification.name)
    }
}

/// One reduced model run and its score.
#[derive(Clone, Debug)]
pub struct Trial {
    /// Indices into [`ActivityReduction::candidates`] applied.
    pub applied: Vec<usize>,
    /// States.
    pub states: usize,
    /// Accepted steps.
    pub steps: usize,
    /// Wall time of the integration.
    pub wall: Duration,
    /// Scaled error of every scored column (empty if it failed).
    pub errors: Vec<(String, f64)>,
    /// Why it failed to load or run, if it did.
    pub failure: Option<String>,
}

impl Trial {
    /// The worst scored column and its error.
    #[must_use]
    pub fn worst(&self) -> Option<(&str, f64)> {
        crate::reduce::worst_of(&self.errors)
    }

    /// Whether it ran and its worst column is within `tol`.
    #[must_use]
    pub fn passes(&self, tol: f64) -> bool {
        self.failure.is_none() && self.worst().is_some_and(|(_, e)| e <= tol)
    }
}

/// What `reduce --by activity` found.
#[derive(Clone, Debug)]
pub struct ActivityReduction {
    /// The tolerance.
    pub tol: f64,
    /// The threshold on the activity share.
    pub threshold: f64,
    /// Every element's activity, largest first.
    pub ranking: Vec<ElementActivity>,
    /// Every applicable simplification, lowest share first (those at or above the
    /// threshold too, for the report); the proposed ones are those below it.
    pub candidates: Vec<Candidate>,
    /// The full model's run (index 0) and every reduced model tried, in order.
    pub trials: Vec<Trial>,
    /// Index into `trials` of the answer (0: nothing could be simplified within tol).
    pub answer: usize,
    /// Median wall time of the full model, timed alone.
    pub reference_wall: Duration,
    /// Median wall time of the answer, timed alone.
    pub answer_wall: Duration,
}

impl ActivityReduction {
    /// The answer's trial.
    #[must_use]
    pub fn answer(&self) -> &Trial {
        &self.trials[self.answer]
    }

    /// The proposed candidates (share below the threshold).
    #[must_use]
    pub fn proposed(&self) -> usize {
        self.candidates
            .iter()
            .filter(|c| c.share < self.threshold)
            .count()
    }

    /// Wall-time speed-up of the answer (each timed alone).
    #[must_use]
    pub fn speedup(&self) -> f64 {
        self.reference_wall.as_secs_f64() / self.answer_wall.as_secs_f64().max(1e-9)
    }

    /// Steps of the full model over steps of the answer.
    #[must_use]
    pub fn step_ratio(&self) -> f64 {
        self.trials[0].steps as f64 / self.answer().steps.max(1) as f64
    }

    /// The simplifications of the answer.
    #[must_use]
    pub fn applied(&self) -> Vec<&Candidate> {
        self.answer()
            .applied
            .iter()
            .filter_map(|&i| self.candidates.get(i))
            .collect()
    }

    /// The trials as a Markdown table.
    #[must_use]
    pub fn table(&self) -> String {
        let mut s = String::from(
            "| model | states | steps | wall (ms) | worst column | scaled error | within tol |\n|---|---|---|---|---|---|---|\n",
        );
        for (i, t) in self.trials.iter().enumerate() {
            let what = if i == 0 {
                "full".to_owned()
            } else {
                t.applied
                    .iter()
                    .filter_map(|&k| self.candidates.get(k).map(Candidate::label))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let (col, err, ok) = match (&t.failure, t.worst()) {
                (Some(f), _) => (
                    f.lines().next().unwrap_or("").chars().take(70).collect(),
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
            let ok = if i == self.answer && i > 0 {
                format!("{ok} ← answer")
            } else {
                ok.to_owned()
            };
            s.push_str(&format!(
                "| {what} | {} | {} | {:.1} | {col} | {err} | {ok} |\n",
                t.states,
                t.steps,
                t.wall.as_secs_f64() * 1e3
            ));
        }
        s
    }
}

/// Set the options' end time, solver and tolerance on a loaded model.
pub(crate) fn configure(m: &mut Model, o: &ReduceOptions) -> Result<(), String> {
    if let Some(t) = o.t_end {
        m.settings.t_end = t;
    }
    if let Some(me) = o.method {
        m.settings.method = me;
    }
    if let Some(r) = o.rtol {
        m.settings.rtol = r;
    }
    m.settings.validate().map_err(|e| e.to_string())
}

/// Load and run the model `text` (no audit).
fn run_text(
    file: &str,
    text: &str,
    registry: &Registry,
    o: &ReduceOptions,
) -> (Trial, Option<Trajectory>) {
    let mut t = Trial {
        applied: Vec::new(),
        states: 0,
        steps: 0,
        wall: Duration::ZERO,
        errors: Vec::new(),
        failure: None,
    };
    let mut m = match Model::from_text(file, text, registry, &[])
        .map_err(|e| e.to_string())
        .and_then(|mut m| configure(&mut m, o).map(|()| m))
    {
        Ok(m) => m,
        Err(e) => {
            t.failure = Some(format!("does not load: {e}"));
            return (t, None);
        }
    };
    t.states = m.equations.n_states();
    match m.run() {
        Ok(out) => {
            t.steps = out.stats.steps;
            t.wall = out.stats.wall_time;
            match out.error {
                Some(e) => {
                    t.failure = Some(e.to_string());
                    (t, None)
                }
                None => (t, Some(out.trajectory)),
            }
        }
        Err(e) => {
            t.failure = Some(e.to_string());
            (t, None)
        }
    }
}

/// Median integration time of `repeat` runs of `text`, one at a time.
fn time_alone(file: &str, text: &str, registry: &Registry, o: &ReduceOptions) -> Duration {
    let mut walls: Vec<Duration> = (0..o.repeat.max(1))
        .map(|_| run_text(file, text, registry, o).0.wall)
        .collect();
    walls.sort();
    walls[walls.len() / 2]
}

/// Reduce the model at `path` by activity (see the module doc): `audit` runs the full model
/// and ranks its elements; the kinds come from `registry`.
///
/// # Errors
/// Bad options (tol or threshold not finite and > 0, an unknown column), the model does not
/// load, or its full run fails.
pub fn reduce_by_activity(
    path: &Path,
    registry: &Registry,
    o: &ReduceOptions,
    threshold: f64,
    audit: &Audit<'_>,
) -> Result<ActivityReduction, String> {
    if !(o.tol.is_finite() && o.tol > 0.0) {
        return Err(format!(
            "--tol must be finite and > 0, got {}\n  hint: e.g. --tol 1e-2 for 1 % of each column's scale",
            o.tol
        ));
    }
    if !(threshold.is_finite() && threshold > 0.0 && threshold <= 1.0) {
        return Err(format!(
            "--threshold must be in (0, 1], got {threshold}\n  hint: the largest activity share of an element to simplify, e.g. --threshold 0.01 for 1 %"
        ));
    }
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {file}: {e}"))?;
    let mut text = bg_model::overrides::apply(&file, &text, &o.set).map_err(|e| e.to_string())?;
    let mut full = Model::from_text(&file, &text, registry, &[]).map_err(|e| e.to_string())?;
    configure(&mut full, o)?;
    if let Some(cols) = &o.columns {
        let have: Vec<&str> = full.outputs.iter().map(|c| c.name.as_str()).collect();
        if let Some(c) = cols
            .iter()
            .find(|c| c.as_str() != "t" && !have.contains(&c.as_str()))
        {
            return Err(format!(
                "{file} has no output column `{c}`\n  hint: its columns are {}",
                have.join(", ")
            ));
        }
    }
    if let Some(cols) = &o.columns {
        text = keep_only(&text, cols)?;
        full = Model::from_text(&file, &text, registry, &[]).map_err(|e| e.to_string())?;
        configure(&mut full, o)?;
    }
    let states = full.equations.n_states();
    let (out, mut ranking) = audit(&mut full)?;
    if let Some(e) = &out.error {
        return Err(format!("the full model failed: {e}"));
    }
    ranking.sort_by(|a, b| b.share.total_cmp(&a.share));
    let traj = out.trajectory;
    let mut reference = Reference::from_trajectory(&traj, o.columns.as_deref(), &o.floors)?;
    for (name, _, scale) in &mut reference.columns {
        if let Some((_, v)) = o.scales.iter().find(|(p, _)| matches(p, name)) {
            *scale = *v;
        }
    }
    let first = Trial {
        applied: Vec::new(),
        states,
        steps: out.stats.steps,
        wall: out.stats.wall_time,
        errors: reference.errors(&traj).unwrap_or_default(),
        failure: None,
    };
    let candidates = candidates(&text, registry, &ranking)?;
    let proposed: Vec<usize> = (0..candidates.len())
        .filter(|&i| candidates[i].share < threshold)
        .collect();
    let mut trials = vec![first];
    let try_set = |applied: &[usize]| -> Trial {
        let picks: Vec<&Candidate> = applied.iter().map(|&i| &candidates[i]).collect();
        let (mut t, traj) = match apply(&text, &picks) {
            Ok(reduced) => run_text(&file, &reduced, registry, o),
            Err(e) => (
                Trial {
                    applied: Vec::new(),
                    states: 0,
                    steps: 0,
                    wall: Duration::ZERO,
                    errors: Vec::new(),
                    failure: Some(e),
                },
                None,
            ),
        };
        t.applied = applied.to_vec();
        if let Some(traj) = traj {
            match reference.errors(&traj) {
                Some(e) => t.errors = e,
                None => {
                    t.failure =
                        Some("its rows do not match the full model's times or columns".into());
                }
            }
        }
        t
    };
    let mut answer = 0;
    if !proposed.is_empty() {
        let all = try_set(&proposed);
        let passes = all.passes(o.tol);
        trials.push(all);
        if passes {
            answer = 1;
        } else if proposed.len() > 1 {
            let mut kept: Vec<usize> = Vec::new();
            for &c in &proposed {
                // a later simplification that rewrites every key of a kept one on the same
                // entry replaces it
                let mut next: Vec<usize> = kept
                    .iter()
                    .copied()
                    .filter(|&k| {
                        let (a, b) = (&candidates[k], &candidates[c]);
                        !(a.instance == b.instance
                            && a.simplification.changes.iter().all(|x| {
                                b.simplification.changes.iter().any(|y| y.key() == x.key())
                            }))
                    })
                    .collect();
                next.push(c);
                let t = try_set(&next);
                if t.passes(o.tol) {
                    kept = next;
                    answer = trials.len();
                }
                trials.push(t);
            }
        }
    }
    let reference_wall = time_alone(&file, &text, registry, o);
    let (answer, answer_wall) = if answer == 0 {
        (0, reference_wall)
    } else {
        let picks: Vec<&Candidate> = trials[answer]
            .applied
            .iter()
            .map(|&i| &candidates[i])
            .collect();
        let reduced = apply(&text, &picks)?;
        (answer, time_alone(&file, &reduced, registry, o))
    };
    Ok(ActivityReduction {
        tol: o.tol,
        threshold,
        ranking,
        candidates,
        trials,
        answer,
        reference_wall,
        answer_wall,
    })
}

#[cfg(test)]
mod tests;
