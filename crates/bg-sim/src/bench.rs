//! `bg-sim bench`: the speed–accuracy trade of a model, measured on the columns a user reads.
//!
//! A reference first — a results CSV given with `--reference` (e.g. a run at rtol 1e-10), or
//! a run of the model at `--reference-rtol` — then every method at every relative tolerance,
//! each timed as the median of a few repeats.
//!
//! # The score of a run
//! For every scored column j, the largest deviation from the reference over the output rows,
//! divided by the column's *scale*
//!
//! ```text
//! scale_j = max(range_j, |mean_j|, floor_j)       (range and mean of the reference column)
//! ```
//!
//! so that a quantity that barely moves is measured against its typical size rather than its
//! own tiny range. The floor belongs to the *quantity*: columns whose names differ only in
//! their trailing index digits (`qb1_1 … qb2_3`, `rho1 … rho6`, `p_p1`, `p_p2`) are one
//! quantity, and each gets at least 1 % of the largest scale in its quantity
//! ([`QUANTITY_FLOOR`]); `--floor PATTERN=VALUE` sets a floor explicitly (`*` matches any
//! text). The smallest modal coordinate then no longer decides the score alone. The run's
//! score is its worst column, which is named.

use std::path::Path;
use std::time::{Duration, Instant};

use bg_model::Model;
use bondgraph::{Method, Outcome, Trajectory};

use crate::plot::{PlotError, Results};

/// A quantity's floor, as a fraction of the largest scale among its columns.
pub const QUANTITY_FLOOR: f64 = 1e-2;

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct BenchRow {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations (Jacobians are assembled exactly and cost none).
    pub rhs_evals: usize,
    /// Jacobian evaluations.
    pub jac_evals: usize,
    /// LU factorisations.
    pub lu: usize,
    /// Median wall time of the integration.
    pub wall: Duration,
    /// Worst scaled error over the columns, and that column (`None` if the run failed).
    pub error: Option<(f64, String)>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// The reference a run is scored against: its rows and each scored column's scale.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Output times.
    pub t: Vec<f64>,
    /// Scored columns: name, values at `t`, scale.
    pub columns: Vec<(String, Vec<f64>, f64)>,
}

/// The quantity a column measures: its name without trailing index digits and underscores
/// (`qb2_3` → `qb`, `rho6` → `rho`, `p_p1` → `p_p`).
#[must_use]
pub fn quantity(name: &str) -> &str {
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit() || c == '_');
    if stem.is_empty() {
        name
    } else {
        stem
    }
}

/// Whether `name` matches `pattern`, where `*` matches any text.
#[must_use]
pub fn matches(pattern: &str, name: &str) -> bool {
    let parts: Vec<&str> = pattern.split('*').collect();
    if parts.len() == 1 {
        return pattern == name;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if !name.starts_with(first) || name.len() < first.len() + last.len() || !name.ends_with(last) {
        return false;
    }
    let mut rest = &name[first.len()..name.len() - last.len()];
    for p in &parts[1..parts.len() - 1] {
        match rest.find(p) {
            Some(i) => rest = &rest[i + p.len()..],
            None => return false,
        }
    }
    true
}

impl Reference {
    /// Score the columns `columns` of `traj` (all but `t` if `None`), with explicit floors
    /// `floors` (`(pattern, value)`, first match wins) and the quantity floors otherwise.
    ///
    /// # Errors
    /// A named column the reference lacks, or no column to score.
    pub fn new(
        t: Vec<f64>,
        named: Vec<(String, Vec<f64>)>,
        columns: Option<&[String]>,
        floors: &[(String, f64)],
    ) -> Result<Self, String> {
        let chosen: Vec<(String, Vec<f64>)> = match columns {
            None => named,
            Some(list) => {
                let mut v = Vec::new();
                for c in list.iter().filter(|c| c.as_str() != "t") {
                    let Some((_, vals)) = named.iter().find(|(n, _)| n == c) else {
                        let have: Vec<&str> =
                            named.iter().map(|(n, _)| n.as_str()).take(20).collect();
                        return Err(format!(
                            "the reference has no column `{c}`\n  hint: it has {}",
                            have.join(", ")
                        ));
                    };
                    v.push((c.clone(), vals.clone()));
                }
                v
            }
        };
        if chosen.is_empty() {
            return Err("no column to score".into());
        }
        let own: Vec<f64> = chosen
            .iter()
            .map(|(_, v)| {
                let (lo, hi, sum) = v
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY, 0.0), |(a, b, s), &x| {
                        (a.min(x), b.max(x), s + x)
                    });
                let mean = sum / v.len().max(1) as f64;
                (hi - lo).max(mean.abs())
            })
            .collect();
        let mut by_quantity: std::collections::HashMap<&str, f64> = Default::default();
        for ((name, _), &s) in chosen.iter().zip(&own) {
            let e = by_quantity.entry(quantity(name)).or_insert(0.0);
            *e = e.max(s);
        }
        let floors_of: Vec<f64> = chosen
            .iter()
            .map(|(name, _)| {
                floors.iter().find(|(p, _)| matches(p, name)).map_or_else(
                    || QUANTITY_FLOOR * by_quantity.get(quantity(name)).copied().unwrap_or(0.0),
                    |(_, f)| *f,
                )
            })
            .collect();
        let columns = chosen
            .into_iter()
            .zip(own.iter().zip(floors_of))
            .map(|((name, vals), (&s, floor))| (name, vals, s.max(floor)))
            .collect::<Vec<_>>();
        Ok(Self { t, columns })
    }

    /// The reference from a trajectory (e.g. a tight run).
    pub fn from_trajectory(
        traj: &Trajectory,
        columns: Option<&[String]>,
        floors: &[(String, f64)],
    ) -> Result<Self, String> {
        let t = traj.rows.iter().map(|r| r[0]).collect();
        let named = traj
            .columns
            .iter()
            .enumerate()
            .skip(1)
            .map(|(j, n)| (n.clone(), traj.rows.iter().map(|r| r[j]).collect()))
            .collect();
        Self::new(t, named, columns, floors)
    }

    /// The reference from a results CSV written by `bg-sim run`.
    pub fn read(
        path: &Path,
        columns: Option<&[String]>,
        floors: &[(String, f64)],
    ) -> Result<Self, String> {
        let r = Results::read(path).map_err(|e: PlotError| e.to_string())?;
        let t = r.time().to_vec();
        let named = r
            .names()
            .iter()
            .skip(1)
            .filter_map(|n| r.column(n).map(|c| (n.clone(), c.to_vec())))
            .collect();
        Self::new(t, named, columns, floors).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Per scored column, the worst |run − reference| / scale over the run's rows (the
    /// reference interpolated linearly where the output times differ); `None` if the run
    /// lacks a column or covers a different time span.
    #[must_use]
    pub fn errors(&self, run: &Trajectory) -> Option<Vec<(String, f64)>> {
        let (&t0, &t1) = (self.t.first()?, self.t.last()?);
        let rt: Vec<f64> = run.rows.iter().map(|r| r[0]).collect();
        let (&r0, &r1) = (rt.first()?, rt.last()?);
        let tol = 1e-9 * (1.0 + t1.abs());
        if (r0 - t0).abs() > tol || (r1 - t1).abs() > tol {
            return None;
        }
        let aligned = rt.len() == self.t.len()
            && rt
                .iter()
                .zip(&self.t)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + b.abs()));
        let mut out = Vec::with_capacity(self.columns.len());
        for (name, vals, scale) in &self.columns {
            let k = run.columns.iter().position(|c| c == name)?;
            let mut worst = 0.0f64;
            for (i, row) in run.rows.iter().enumerate() {
                let reference = if aligned {
                    vals[i]
                } else {
                    interpolate(&self.t, vals, row[0])
                };
                // A column that is exactly zero in the reference (scale 0) scores 0 where the
                // run equals it and infinity where it does not (compare then names it).
                let d = (row[k] - reference).abs();
                let e = if d == 0.0 { 0.0 } else { d / scale };
                if e.is_nan() || e > worst {
                    worst = e;
                    if e.is_nan() {
                        break;
                    }
                }
            }
            out.push((name.clone(), worst));
        }
        Some(out)
    }

    /// The worst scored column of `run`, and its error.
    #[must_use]
    pub fn worst(&self, run: &Trajectory) -> Option<(f64, String)> {
        self.errors(run)?
            .into_iter()
            .fold(None, |w: Option<(f64, String)>, (n, e)| match w {
                Some((we, _)) if !(e > we || e.is_nan()) => w,
                _ => Some((e, n)),
            })
    }
}

/// Why the columns `reference` scores cannot be scored in the file `path` (read through
/// `column`): a time or a value that is NaN or infinite, or a column whose range (or
/// scale) overflows f64 (1e308 beside −1e308), named with its first row. A score of NaN or
/// infinity would read as a result; it is an error instead (issue 24, item 9).
///
/// # Errors
/// The message: file, column, row and why.
pub fn unscorable<'a>(
    path: &Path,
    reference: &Reference,
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
        if let Some(s) = scale.filter(|s| !(s.is_finite() && *s >= 0.0)) {
            return Err(format!(
                "{file}: column `{name}` has the scale {s:e} (its range and mean in the reference): its errors cannot be scaled\n  hint: give it an error floor, e.g. --floor {name}=1e-9"
            ));
        }
    }
    Ok(())
}

fn interpolate(t: &[f64], v: &[f64], x: f64) -> f64 {
    let i = t.partition_point(|&ti| ti <= x);
    if i == 0 {
        return v[0];
    }
    if i >= t.len() {
        return v[t.len() - 1];
    }
    let (ta, tb) = (t[i - 1], t[i]);
    let w = if tb > ta { (x - ta) / (tb - ta) } else { 0.0 };
    v[i - 1] + w * (v[i] - v[i - 1])
}

fn run_once(model: &mut Model, method: Method, rtol: f64) -> Result<Outcome, String> {
    run_maybe_audited(model, method, rtol, false)
}

/// One run, with the energy audit (`bg-sim bench --energy`: its cost) or without.
fn run_maybe_audited(
    model: &mut Model,
    method: Method,
    rtol: f64,
    energy: bool,
) -> Result<Outcome, String> {
    model.settings.method = method;
    model.settings.rtol = rtol;
    if energy {
        model
            .run_audited()
            .map(|(o, _)| o)
            .map_err(|e| e.to_string())
    } else {
        model.run().map_err(|e| e.to_string())
    }
}

/// Measure `methods` × `rtols` against `reference`, each timed as the median of `repeat`
/// runs.
pub fn bench(
    model: &mut Model,
    methods: &[Method],
    rtols: &[f64],
    reference: &Reference,
    repeat: usize,
) -> Result<Vec<BenchRow>, String> {
    bench_audited(model, methods, rtols, reference, repeat, false)
}

/// [`bench`], each run with the energy audit when `energy` (`bg-sim bench --energy`: the
/// audit's cost, side by side with a run without it).
pub fn bench_audited(
    model: &mut Model,
    methods: &[Method],
    rtols: &[f64],
    reference: &Reference,
    repeat: usize,
    energy: bool,
) -> Result<Vec<BenchRow>, String> {
    let mut rows = Vec::new();
    for &method in methods {
        for &rtol in rtols {
            let mut walls = Vec::new();
            let mut last = None;
            for _ in 0..repeat.max(1) {
                let out = run_maybe_audited(model, method, rtol, energy)?;
                walls.push(out.stats.wall_time);
                let failed = out.error.is_some();
                last = Some(out);
                if failed {
                    break;
                }
            }
            let Some(out) = last else { continue };
            walls.sort();
            rows.push(BenchRow {
                method,
                rtol,
                steps: out.stats.steps,
                rhs_evals: out.stats.rhs_evals,
                jac_evals: out.stats.jac_evals,
                lu: out.stats.lu_factorisations,
                wall: walls[walls.len() / 2],
                error: out
                    .error
                    .is_none()
                    .then(|| reference.worst(&out.trajectory))
                    .flatten(),
                failure: out.error.map(|e| e.to_string()),
            });
        }
    }
    Ok(rows)
}

/// Run `model` at `rtol` with `method` and make the reference of its results.
pub fn reference_run(
    model: &mut Model,
    method: Method,
    rtol: f64,
    columns: Option<&[String]>,
    floors: &[(String, f64)],
) -> Result<(Outcome, Reference), String> {
    let out = run_once(model, method, rtol)?;
    if let Some(e) = &out.error {
        return Err(format!(
            "the reference run ({}, rtol {rtol:e}) failed: {e}",
            method.name()
        ));
    }
    let r = Reference::from_trajectory(&out.trajectory, columns, floors)?;
    Ok((out, r))
}

/// The rows as a Markdown table.
#[must_use]
pub fn table(rows: &[BenchRow]) -> String {
    let mut s = String::from("| solver | rtol | steps | rhs evals | Jacobians | LU | wall (ms) | worst scaled error | column |\n|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let (err, col) = match (&r.error, &r.failure) {
            (Some((e, c)), _) => (format!("{e:.2e}"), c.clone()),
            (None, Some(f)) => ("failed".to_owned(), f.chars().take(60).collect()),
            (None, None) => ("–".to_owned(), String::new()),
        };
        s.push_str(&format!(
            "| {} | {:.0e} | {} | {} | {} | {} | {:.2} | {err} | {col} |\n",
            r.method.name(),
            r.rtol,
            r.steps,
            r.rhs_evals,
            r.jac_evals,
            r.lu,
            r.wall.as_secs_f64() * 1e3
        ));
    }
    s
}

/// The cost of one right-hand side and of one Jacobian.
#[derive(Clone, Debug)]
pub struct RhsCost {
    /// Number of states.
    pub n: usize,
    /// Median µs per rhs evaluation.
    pub rhs_us: f64,
    /// Median µs per exact Jacobian ([`StateEquations::jacobian`](bondgraph::StateEquations::jacobian)).
    pub jacobian_us: f64,
}

/// Time the model's right-hand side and Jacobian near its initial state, `calls` rhs calls per
/// sample, median of 7 samples. Every component of the state is nudged before every call, as
/// in a run, where each of Radau's stage evaluations sees a new state: an element that caches
/// work per configuration (the flexible arm caches its frames and mass matrix per `q`) must not
/// answer from its cache here either, or the rhs looks cheaper than a run makes it.
#[must_use]
pub fn rhs_cost(model: &Model, calls: usize) -> RhsCost {
    let eqs = &model.equations;
    let x0 = eqs.initial_state();
    let n = x0.len();
    let mut dx = vec![0.0; n];
    let t = model.settings.t_start;
    let calls = calls.max(1);
    eqs.rhs(t, &x0, &mut dx);
    let mut samples = Vec::new();
    for _ in 0..7 {
        let mut x = x0.clone();
        let start = Instant::now();
        for _ in 0..calls {
            nudge(&mut x);
            eqs.rhs(t, &x, &mut dx);
        }
        samples.push(start.elapsed().as_secs_f64() * 1e6 / calls as f64);
    }
    samples.sort_by(f64::total_cmp);
    let rhs_us = samples[samples.len() / 2];
    let mut jac = bondgraph::DMatrix::zeros(n, n);
    eqs.jacobian(t, &x0, &mut jac);
    let jac_calls = (calls / 20).max(1);
    let mut samples = Vec::new();
    for _ in 0..7 {
        let mut x = x0.clone();
        let start = Instant::now();
        for _ in 0..jac_calls {
            nudge(&mut x);
            eqs.jacobian(t, &x, &mut jac);
        }
        samples.push(start.elapsed().as_secs_f64() * 1e6 / jac_calls as f64);
    }
    samples.sort_by(f64::total_cmp);
    RhsCost {
        n,
        rhs_us,
        jacobian_us: samples[samples.len() / 2],
    }
}

/// Move every component of `x` by a relative 1e-12: a new state for every element's cache, the
/// same operating point for the physics.
fn nudge(x: &mut [f64]) {
    for v in x {
        *v += 1e-12 * (1.0 + v.abs());
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn quantities_and_patterns() {
        assert_eq!(quantity("qb2_3"), "qb");
        assert_eq!(quantity("rho6"), "rho");
        assert_eq!(quantity("p_p1"), "p_p");
        assert_eq!(quantity("T"), "T");
        assert_eq!(quantity("12"), "12");
        assert!(matches("qb*", "qb1_2"));
        assert!(matches("*_p1", "p_p1"));
        assert!(matches("a*c*e", "abcde"));
        assert!(!matches("a*c*e", "abde"));
        assert!(!matches("qb", "qb1"));
        assert!(matches("qb1_1", "qb1_1"));
    }
}
