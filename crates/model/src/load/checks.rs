//! `[[check]]`: expected results, read with the model and evaluated while it runs
//! ([`CheckSink`]: at every output row and every accepted step) or afterwards on a
//! trajectory ([`verify`]).

use std::collections::HashSet;

use bondgraph::Output;
use indexmap::IndexMap;
use toml::Spanned;

use super::parse::CheckSpec;
use super::source::Source;
use super::Model;
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::Expr;

/// A check of the results: at every output row and every accepted solver step,
/// |value − expected| ≤ tol, where `value` and `expected` are expressions of `t`, parameters
/// and output columns ([`Model::run_into`]).
#[derive(Clone, Debug)]
pub struct Check {
    /// What is checked (a column name or an expression of columns).
    pub value: String,
    /// Expected value.
    pub expected: String,
    /// Absolute tolerance.
    pub tol: f64,
    pub(super) value_expr: Expr,
    pub(super) expected_expr: Expr,
}

/// The result of a [`Check`].
#[derive(Clone, Debug)]
pub struct CheckResult {
    /// What was checked.
    pub value: String,
    /// Largest |value − expected| over the points evaluated.
    pub max_error: f64,
    /// Time of the largest error.
    pub t_worst: f64,
    /// Tolerance.
    pub tol: f64,
    /// `max_error <= tol` (and every value finite).
    pub passed: bool,
    /// How many points were evaluated (output rows, plus accepted steps if `every_step`).
    pub points: usize,
    /// Evaluated at every accepted solver step as well as at every output row
    /// ([`Model::run_into`]); `false`: at the output rows only ([`Model::verify`]).
    pub every_step: bool,
}

/// The worst error of one check so far.
#[derive(Clone, Copy)]
struct Worst {
    error: f64,
    t: f64,
    finite: bool,
}

impl Worst {
    const NONE: Self = Self {
        error: 0.0,
        t: f64::NAN,
        finite: true,
    };
    fn add(&mut self, t: f64, error: f64) {
        if !error.is_finite() {
            self.finite = false;
        }
        if error > self.error || self.t.is_nan() {
            self.error = error;
            self.t = t;
        }
    }
    fn result(self, c: &Check, points: usize, every_step: bool) -> CheckResult {
        CheckResult {
            value: c.value.clone(),
            max_error: self.error,
            t_worst: self.t,
            tol: c.tol,
            passed: points > 0 && self.finite && self.error <= c.tol,
            points,
            every_step,
        }
    }
}

/// Evaluates the checks at every output row and every accepted step, and hands the rows on.
pub(super) struct CheckSink<'a> {
    inner: &'a mut dyn bondgraph::RowSink,
    /// Compiled (value, expected) of each check, reading the columns (`t` first).
    compiled: Vec<(crate::expr::Compiled, crate::expr::Compiled)>,
    worst: Vec<Worst>,
    points: usize,
    /// Per output column (after `t`): read by a check.
    reads: Vec<bool>,
}

impl<'a> CheckSink<'a> {
    pub(super) fn new(
        model: &Model,
        inner: &'a mut dyn bondgraph::RowSink,
    ) -> Result<Self, ModelError> {
        let columns: Vec<String> = std::iter::once("t".to_owned())
            .chain(model.outputs.iter().map(|o| o.name.clone()))
            .collect();
        let constant = |n: &str| {
            if columns.iter().any(|c| c == n) {
                None
            } else {
                model.parameters.get(n).copied()
            }
        };
        let mut compiled = Vec::new();
        let mut reads = vec![false; model.outputs.len()];
        for c in &model.checks {
            for n in c.value_expr.names().iter().chain(&c.expected_expr.names()) {
                if let Some(k) = model.outputs.iter().position(|o| &o.name == n) {
                    reads[k] = true;
                }
            }
            let compile = |e: &Expr| {
                e.compile(&constant, &columns).map_err(|m| {
                    model.source.err(
                        ErrorKind::Settings,
                        None,
                        format!("[[check]] {}: {m}", clip(&c.value)),
                    )
                })
            };
            compiled.push((compile(&c.value_expr)?, compile(&c.expected_expr)?));
        }
        Ok(Self {
            inner,
            worst: vec![Worst::NONE; compiled.len()],
            compiled,
            points: 0,
            reads,
        })
    }
    fn evaluate(&mut self, values: &[f64]) {
        self.points += 1;
        let t = values.first().copied().unwrap_or(f64::NAN);
        for ((v, e), w) in self.compiled.iter().zip(&mut self.worst) {
            w.add(t, (v.eval(values) - e.eval(values)).abs());
        }
    }
    pub(super) fn results(&self, checks: &[Check]) -> Vec<CheckResult> {
        checks
            .iter()
            .zip(&self.worst)
            .map(|(c, w)| w.result(c, self.points, true))
            .collect()
    }
}

impl bondgraph::RowSink for CheckSink<'_> {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.evaluate(row);
        self.inner.row(row)
    }
    fn wants_steps(&self) -> bool {
        !self.compiled.is_empty() || self.inner.wants_steps()
    }
    fn step(&mut self, values: &[f64]) {
        self.evaluate(values);
        if self.inner.wants_steps() {
            self.inner.step(values);
        }
    }
    fn step_reads(&self, column: usize) -> bool {
        self.reads.get(column).copied().unwrap_or(false)
            || (self.inner.wants_steps() && self.inner.step_reads(column))
    }
}

/// The `[[check]]` tables: expressions of `t`, parameters and output columns (`columns`,
/// which includes those whose own problem is reported already).
pub(super) fn read(
    specs: &[Spanned<CheckSpec>],
    source: &Source,
    parameters: &IndexMap<String, f64>,
    columns: &HashSet<String>,
    problems: &mut Vec<ModelError>,
) -> Vec<Check> {
    let mut checks = Vec::new();
    for c in specs {
        match read_one(c.get_ref(), source, parameters, columns) {
            Ok(c) => checks.push(c),
            Err(e) => problems.push(e),
        }
    }
    checks
}

fn read_one(
    cs: &CheckSpec,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    columns: &HashSet<String>,
) -> Result<Check, ModelError> {
    let parse_checked = |what: &str, text: &Spanned<String>| -> Result<Expr, ModelError> {
        let span = text.span();
        let e = Expr::parse(text.get_ref()).map_err(|e| {
            source.err(
                ErrorKind::Settings,
                Some(&span),
                format!("[[check]] {what} = \"{}\": {e}", clip(text.get_ref())),
            )
        })?;
        for n in e.names() {
            if n != "t" && n != "pi" && !parameters.contains_key(&n) && !columns.contains(&n) {
                return Err(source
                    .err(ErrorKind::Settings, Some(&span), format!("[[check]] {what} uses `{n}`, which is neither `t`, a parameter nor an output column"))
                    .hint("name output columns in [outputs] with plain names (letters, digits, _) to use them in checks"));
            }
        }
        Ok(e)
    };
    let value_expr = parse_checked("value", &cs.value)?;
    let expected_expr = parse_checked("expected", &cs.expected)?;
    let tol = *cs.tol.get_ref();
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(source.err(
            ErrorKind::Settings,
            Some(&cs.tol.span()),
            format!("[[check]] tol must be finite and >= 0, got {tol}"),
        ));
    }
    Ok(Check {
        value: cs.value.get_ref().clone(),
        expected: cs.expected.get_ref().clone(),
        tol,
        value_expr,
        expected_expr,
    })
}

/// The checks evaluated on `traj` at its rows only.
pub(super) fn verify(
    checks: &[Check],
    parameters: &IndexMap<String, f64>,
    traj: &bondgraph::Trajectory,
) -> Vec<CheckResult> {
    checks
        .iter()
        .map(|c| {
            let mut worst = Worst::NONE;
            for row in &traj.rows {
                let t = row[0];
                let lookup = |n: &str| {
                    if n == "t" {
                        Some(t)
                    } else if let Some(k) = traj.columns.iter().position(|col| col == n) {
                        Some(row[k])
                    } else {
                        parameters.get(n).copied()
                    }
                };
                let err = match (c.value_expr.eval(&lookup), c.expected_expr.eval(&lookup)) {
                    (Ok(v), Ok(e)) => (v - e).abs(),
                    _ => f64::NAN,
                };
                worst.add(t, err);
            }
            worst.result(c, traj.rows.len(), false)
        })
        .collect()
}

/// The names a check may use as columns: the outputs, and those refused (reported already).
pub(super) fn column_names(outputs: &[Output], refused: &[String]) -> HashSet<String> {
    outputs
        .iter()
        .map(|o| o.name.clone())
        .chain(refused.iter().cloned())
        .collect()
}
