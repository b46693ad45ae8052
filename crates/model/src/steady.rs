//! `[initial.steady]`: start from a steady state solved by the core
//! ([`bondgraph::solve_steady`]).
//!
//! ```toml
//! [initial.steady]
//! unknowns   = ["lift_chamber_p.p"]              # states to solve for; `x.q[*]`, `x.q[3..]` allowed
//! conditions = ["mass.p.dot = 0"]                # `STATE.dot = value`, `STATE = value`, `VARIABLE = value`
//! keep       = ["lift_chamber_p.p"]              # optional: unknowns the start takes (default all)
//! tol        = 1e-10                             # optional: largest scaled residual
//! ```
//!
//! or several named requests and the one to use (`"none"`: no solve):
//!
//! ```toml
//! [initial.steady]
//! use = "hold"
//! hold = { unknowns = [...], conditions = [...] }
//! rest = { unknowns = [...], conditions = [...] }
//! ```
//!
//! A pattern `x.q[*]` names every component of the vector state `x.q` (none if it has none,
//! so a request fits variants of a model with fewer states); `x.q[3..]` the components from
//! 3 on, `x.q[1..3]` components 1 and 2. Condition values are constant expressions of the
//! parameters.

use bondgraph::{solve_steady, Condition, Equilibrium, Settle, StateEquations, SteadyRequest};
use indexmap::IndexMap;

use crate::expr::Expr;

/// A problem with the request: message and hint.
pub(crate) type Problem = (String, Option<String>);

/// The steady state a model started from, as solved at load time.
#[derive(Clone, Debug)]
pub struct SteadyReport {
    /// The request used (its name under `use`, or `steady`).
    pub name: String,
    /// The unknown states.
    pub unknowns: Vec<String>,
    /// The unknowns the start took from the solution.
    pub kept: Vec<String>,
    /// The solution.
    pub solution: Equilibrium,
}

impl std::fmt::Display for SteadyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "steady start `{}`: {} unknowns solved in {} Newton iterations",
            self.name,
            self.unknowns.len(),
            self.solution.iterations
        )?;
        if let Some((c, r, s)) = self.solution.worst() {
            write!(f, "; largest residual {r:.3e} ({c}; scaled {s:.1e})")?;
        }
        if !self.solution.own_scale.is_empty() {
            let judged: Vec<String> = self
                .solution
                .own_scale
                .iter()
                .map(|(c, r, tol)| format!("{c}: {r:.3e}, within {tol:.1e}"))
                .collect();
            write!(
                f,
                "; judged in their own scale (Newton stalled at rounding; atol + rtol·|x|, a rate over the run's span): {}",
                judged.join(", ")
            )?;
        }
        if self.kept.len() < self.unknowns.len() {
            write!(f, "; the start takes {}", self.kept.join(", "))?;
        }
        Ok(())
    }
}

struct Spec {
    name: String,
    unknowns: Vec<String>,
    conditions: Vec<String>,
    keep: Option<Vec<String>>,
    tol: Option<f64>,
}

fn strings(t: &toml::Table, key: &str, what: &str) -> Result<Option<Vec<String>>, Problem> {
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::Array(a)) => a
            .iter()
            .map(|v| {
                v.as_str().map(str::to_owned).ok_or_else(|| {
                    (
                        format!("[initial.steady] `{key}` must be a list of strings ({what})"),
                        None,
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some),
        Some(_) => Err((
            format!("[initial.steady] `{key}` must be a list of strings ({what})"),
            None,
        )),
    }
}

const KEYS: &str = "unknowns, conditions, keep, tol (or `use` and named requests)";

fn read_one(name: &str, t: &toml::Table) -> Result<Spec, Problem> {
    for k in t.keys() {
        if !["unknowns", "conditions", "keep", "tol"].contains(&k.as_str()) {
            return Err((
                format!("[initial.steady] unknown key `{k}`"),
                Some(format!("a steady request has {KEYS}")),
            ));
        }
    }
    let tol = match t.get("tol") {
        None => None,
        Some(v) => match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
            Some(x) if x.is_finite() && x > 0.0 => Some(x),
            _ => return Err(("[initial.steady] tol must be a number > 0".into(), None)),
        },
    };
    Ok(Spec {
        name: name.to_owned(),
        unknowns: strings(t, "unknowns", "state names")?.unwrap_or_default(),
        conditions: strings(
            t,
            "conditions",
            "`STATE.dot = value`, `STATE = value` or `VARIABLE = value`",
        )?
        .unwrap_or_default(),
        keep: strings(t, "keep", "state names")?,
        tol,
    })
}

fn read(value: &toml::Value) -> Result<Option<Spec>, Problem> {
    let toml::Value::Table(t) = value else {
        return Err((
            "[initial] `steady` must be a table".into(),
            Some(format!("[initial.steady] has {KEYS}")),
        ));
    };
    let Some(choice) = t.get("use") else {
        return read_one("steady", t).map(Some);
    };
    let Some(choice) = choice.as_str() else {
        return Err(("[initial.steady] `use` must be a string".into(), None));
    };
    let names: Vec<&str> = t
        .iter()
        .filter(|(_, v)| v.is_table())
        .map(|(k, _)| k.as_str())
        .collect();
    if let Some(k) = t
        .iter()
        .find(|(k, v)| k.as_str() != "use" && !v.is_table())
        .map(|(k, _)| k)
    {
        return Err((
            format!("[initial.steady] `{k}` beside `use`: with `use`, every request is a named sub-table"),
            Some(format!("e.g. [initial.steady.{choice}] with unknowns and conditions")),
        ));
    }
    if choice == "none" {
        return Ok(None);
    }
    match t.get(choice) {
        Some(toml::Value::Table(r)) => read_one(choice, r).map(Some),
        _ => Err((
            format!("[initial.steady] use = \"{choice}\": there is no request `{choice}`"),
            Some(format!(
                "requests here: {}; or \"none\"",
                if names.is_empty() {
                    "(none)".to_owned()
                } else {
                    names.join(", ")
                }
            )),
        )),
    }
}

/// The states a pattern names: `x.q`, `x.q[*]`, `x.q[3..]`, `x.q[1..3]`.
fn expand(eqs: &StateEquations, pattern: &str) -> Result<Vec<usize>, Problem> {
    let states = eqs.states();
    if let Some(i) = states.iter().position(|s| s.name == pattern) {
        return Ok(vec![i]);
    }
    let range = pattern
        .strip_suffix(']')
        .and_then(|p| p.rsplit_once('['))
        .and_then(|(base, r)| {
            if r == "*" {
                return Some((base, 0, usize::MAX));
            }
            let (a, b) = r.split_once("..")?;
            let a = if a.is_empty() { 0 } else { a.parse().ok()? };
            let b = if b.is_empty() {
                usize::MAX
            } else {
                b.parse().ok()?
            };
            Some((base, a, b))
        });
    if let Some((base, a, b)) = range {
        let prefix = format!("{base}[");
        return Ok(states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                let k: usize = s
                    .name
                    .strip_prefix(&prefix)?
                    .strip_suffix(']')?
                    .parse()
                    .ok()?;
                (k >= a && k < b).then_some(i)
            })
            .collect());
    }
    let el = pattern.split('.').next().unwrap_or(pattern);
    let near: Vec<&str> = states
        .iter()
        .filter(|s| s.name.starts_with(&format!("{el}.")))
        .map(|s| s.name.as_str())
        .take(12)
        .collect();
    Err((
        format!("[initial.steady]: there is no state `{pattern}`"),
        Some(if near.is_empty() {
            "states are named `<element>.<state>` (`bg-sim check` lists them); `x.q[*]` names every component of a vector state".to_owned()
        } else {
            format!("states of `{el}`: {}", near.join(", "))
        }),
    ))
}

fn conditions(
    eqs: &StateEquations,
    text: &str,
    parameters: &IndexMap<String, f64>,
) -> Result<Vec<Condition>, Problem> {
    let (lhs, rhs) = match text.split_once('=') {
        Some((l, r)) => (l.trim(), r.trim()),
        None => (text.trim(), "0"),
    };
    let value = Expr::parse(rhs)
        .ok()
        .and_then(|e| e.eval(&|n| parameters.get(n).copied()).ok())
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            (
                format!("[initial.steady] condition `{text}`: `{rhs}` must be a constant expression of the parameters"),
                None,
            )
        })?;
    let (pattern, derivative) = match lhs.strip_suffix(".dot") {
        Some(p) => (p, true),
        None => (lhs, false),
    };
    // not a state: any other variable the equations compute (effort, flow, signal)
    let is_state = expand(eqs, pattern).is_ok();
    if !is_state {
        if let Some(probe) = eqs.probe(lhs) {
            return Ok(vec![Condition::Variable {
                probe,
                label: lhs.to_owned(),
                value,
            }]);
        }
    }
    Ok(expand(eqs, pattern)?
        .into_iter()
        .map(|state| {
            if derivative {
                Condition::Derivative { state, value }
            } else {
                Condition::State { state, value }
            }
        })
        .collect())
}

/// Solve the `[initial.steady]` request in `value` at time `t` from `x0`; `Ok(None)` when
/// the request is `use = "none"`. `settle`: the run's tolerances and span, each condition's
/// own scale should Newton stall at rounding ([`Settle`]).
pub(crate) fn solve(
    value: &toml::Value,
    eqs: &StateEquations,
    parameters: &IndexMap<String, f64>,
    t: f64,
    x0: &[f64],
    settle: Settle,
) -> Result<Option<SteadyReport>, Problem> {
    let Some(spec) = read(value)? else {
        return Ok(None);
    };
    let mut unknowns = Vec::new();
    for u in &spec.unknowns {
        unknowns.extend(expand(eqs, u)?);
    }
    if let Some(m) = bondgraph::steady_size_error(eqs.n_states(), unknowns.len()) {
        return Err((
            format!("[initial.steady] `{}`: {m}", spec.name),
            Some("give the start in [initial] instead (e.g. the end of a settling run: `bg-sim run` with its t_end, then the last row), or solve a smaller variant of the model (fewer segments of a line) and take its values".into()),
        ));
    }
    let mut conds = Vec::new();
    for c in &spec.conditions {
        conds.extend(conditions(eqs, c, parameters)?);
    }
    let keep: Vec<usize> = match &spec.keep {
        None => unknowns.clone(),
        Some(k) => {
            let mut out = Vec::new();
            for p in k {
                for i in expand(eqs, p)? {
                    if !unknowns.contains(&i) {
                        return Err((
                            format!(
                                "[initial.steady] keep: `{}` is not an unknown",
                                eqs.states()[i].name
                            ),
                            Some(
                                "`keep` lists unknowns whose solved values the start takes".into(),
                            ),
                        ));
                    }
                    out.push(i);
                }
            }
            out
        }
    };
    let mut req = SteadyRequest::new(unknowns.clone(), conds);
    req.settle = Some(settle);
    if let Some(tol) = spec.tol {
        req.tol = tol;
    }
    let solution = solve_steady(eqs, t, x0, &req).map_err(|e| {
        (
            format!("[initial.steady] `{}`: {e}", spec.name),
            Some("check that the unknowns can balance the conditions (a load the supply cannot hold, a state no condition depends on), or give a better start in [initial]".into()),
        )
    })?;
    let name = |i: &usize| eqs.states()[*i].name.clone();
    Ok(Some(SteadyReport {
        name: spec.name,
        unknowns: unknowns.iter().map(name).collect(),
        kept: keep.iter().map(name).collect(),
        solution,
    }))
}
