//! `[initial]`: initial values of states (numbers or constant expressions), and a steady
//! start solved for (`[initial.steady]`, [`crate::steady`]).

use std::ops::Range;

use bondgraph::{Settings, StateEquations};
use indexmap::IndexMap;
use toml::Spanned;

use super::parse::SpannedMap;
use super::source::Source;
use crate::error::{ErrorKind, ModelError};
use crate::expr::Expr;

/// Set the initial values `[initial]` gives; problems go to `problems`. Returns the
/// `[initial.steady]` table, if there is one.
pub(super) fn apply<'a>(
    initial: &'a SpannedMap<toml::Value>,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    eqs: &mut StateEquations,
    problems: &mut Vec<ModelError>,
) -> Option<&'a Spanned<toml::Value>> {
    let mut flat = Vec::new();
    let mut steady_spec = None;
    for (k, v) in initial {
        if k.get_ref() == "steady" && v.get_ref().is_table() {
            steady_spec = Some(v);
        } else {
            let mut one = SpannedMap::default();
            one.insert(k.clone(), v.clone());
            flatten("", &one, &mut flat);
        }
    }
    for (name, value, span) in flat {
        if let Err(e) = set_one(&name, &value, &span, source, parameters, eqs) {
            problems.push(e);
        }
    }
    steady_spec
}

/// Set state `name` to `value`.
fn set_one(
    name: &str,
    value: &toml::Value,
    span: &Range<usize>,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    eqs: &mut StateEquations,
) -> Result<(), ModelError> {
    let v = match value {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::String(s) => Expr::parse(s)
            .ok()
            .and_then(|e| e.eval(&|n| parameters.get(n).copied()).ok()),
        _ => None,
    }
    .filter(|v| v.is_finite())
    .ok_or_else(|| {
        source.err(
            ErrorKind::BadParameter,
            Some(span),
            format!("initial value of `{name}` must be a finite number or a constant expression"),
        )
    })?;
    eqs.set_initial(name, v).map_err(|_| {
        let el = name.split('.').next().unwrap_or("");
        let states: Vec<String> = eqs
            .states()
            .iter()
            .filter(|s| s.name.starts_with(&format!("{el}.")))
            .map(|s| s.name.clone())
            .collect();
        source
            .err(
                ErrorKind::Settings,
                Some(span),
                format!("[initial]: there is no state `{name}`"),
            )
            .hint(if states.is_empty() {
                "states are named `<element>.<state>`, e.g. `mass.p`, `spring.q`".to_owned()
            } else {
                format!("states of `{el}`: {}", states.join(", "))
            })
    })
}

/// Solve the steady start `[initial.steady]` asks for, from the initial values set, and
/// take it as the initial state.
pub(super) fn steady(
    v: &Spanned<toml::Value>,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    settings: &Settings,
    eqs: &mut StateEquations,
) -> Result<Option<crate::steady::SteadyReport>, ModelError> {
    let x0 = eqs.initial_state();
    // each condition's own scale: the run's tolerances over its span (issue 24, item 1)
    let settle = bondgraph::Settle {
        atol: settings.atol,
        rtol: settings.rtol,
        span: settings.t_end - settings.t_start,
    };
    let report = crate::steady::solve(v.get_ref(), eqs, parameters, settings.t_start, &x0, settle)
        .map_err(|(message, hint)| {
            source
                .err(ErrorKind::Settings, Some(&v.span()), message)
                .or_hint(hint)
        })?;
    if let Some(r) = &report {
        for name in &r.kept {
            if let Some(i) = eqs.states().iter().position(|s| &s.name == name) {
                let value = r.solution.x[i];
                eqs.set_initial(name, value).map_err(|e| {
                    source
                        .err(ErrorKind::Settings, None, e.message())
                        .or_hint(e.hint())
                        .with_source(e)
                })?;
            }
        }
    }
    Ok(report)
}

fn flatten(
    prefix: &str,
    map: &SpannedMap<toml::Value>,
    out: &mut Vec<(String, toml::Value, Range<usize>)>,
) {
    for (k, v) in map {
        let name = if prefix.is_empty() {
            k.get_ref().clone()
        } else {
            format!("{prefix}.{}", k.get_ref())
        };
        flatten_value(&name, v.get_ref(), v.span(), out);
    }
}

fn flatten_value(
    name: &str,
    v: &toml::Value,
    span: Range<usize>,
    out: &mut Vec<(String, toml::Value, Range<usize>)>,
) {
    match v {
        toml::Value::Table(t) => {
            for (k, v) in t {
                flatten_value(&format!("{name}.{k}"), v, span.clone(), out);
            }
        }
        other => out.push((name.to_owned(), other.clone(), span)),
    }
}

/// Refuse geometry that cannot be assembled: every pair of lengths of one distance
/// ([`StateEquations::length_mismatches`]: a cylinder's l0 + s0 and the distance between the
/// pins it is attached to, in the initial pose) that disagree at the initial state (before
/// a steady start) by more than 1 mm + 1e-6·length.
pub(super) fn check_lengths(
    source: &Source,
    eqs: &StateEquations,
    t0: f64,
    problems: &mut Vec<ModelError>,
) {
    let x0 = eqs.initial_state();
    let entry = |member: &str| {
        let m = member.rsplit_once('.').map_or(member, |(e, _)| e);
        source
            .elements
            .iter()
            .find(|e| e.name == m || e.members.iter().any(|n| n == m))
    };
    for mm in eqs.length_mismatches(t0, &x0) {
        let (a, b) = (entry(&mm.a.1), entry(&mm.b.1));
        let is_cyl = |d: Option<&super::source::ElementDef>| {
            d.is_some_and(|d| d.kind == "hydraulics.cylinder" || d.params.contains_key("s0"))
        };
        // the cylinder (the side with a stroke s0) first
        let ((cyl, cyl_sig, l_cyl), (other, other_sig, l_other)) = if !is_cyl(a) && is_cyl(b) {
            ((b, &mm.b.1, mm.b_length), (a, &mm.a.1, mm.a_length))
        } else {
            ((a, &mm.a.1, mm.a_length), (b, &mm.b.1, mm.b_length))
        };
        let name = |d: Option<&super::source::ElementDef>, sig: &str| {
            d.map_or_else(|| sig.to_owned(), |d| d.name.clone())
        };
        let (cyl_name, other_name) = (name(cyl, cyl_sig), name(other, other_sig));
        let fix = if is_cyl(cyl) {
            format!(
                "give `{cyl_name}` the stroke that fits: s0 = \"{l_other:.6} - l0\" (or from the \
                 pin geometry, as models/knuckle_boom.toml writes s0 = \"l1_0 - l0\"), or move the \
                 pins or the initial pose (q0) of `{other_name}`"
            )
        } else {
            format!("change the initial state of `{cyl_name}` or `{other_name}` so that they agree")
        };
        problems.push(
            source
                .err(
                    ErrorKind::BadParameter,
                    cyl.map(|d| &d.name_span),
                    format!(
                    "geometry that cannot be assembled: `{cyl_name}` is {l_cyl:.6} m long at the \
                     start ({cyl_sig}) but the pins it is attached to are {l_other:.6} m apart \
                     ({other_sig}, `{other_name}` in its initial pose): they differ by {:.6} m, \
                     more than the tolerance of 1 mm + 1e-6 of the length",
                    (l_cyl - l_other).abs()
                ),
                )
                .element(&cyl_name)
                .hint(fix),
        );
    }
}
