//! `[[events]]`: at a time, some parameters take new values. Planned once at load time
//! (every problem shows then): the values after each event and the entries that use a
//! changed parameter. Running builds those entries alone from their declarations
//! ([`Source::rebuild`]), and afterwards builds them once more with the model's values to
//! restore the elements.

use std::collections::HashSet;
use std::ops::Range;

use bondgraph::{Event, StateEquations};
use indexmap::IndexMap;

use super::source::Source;
use crate::error::{ErrorKind, ModelError};
use crate::reader::RawValue;

/// One event as it will be applied.
#[derive(Clone, Debug)]
pub(super) struct EventPlan {
    pub(super) t: f64,
    pub(super) span: Range<usize>,
    /// Every parameter's value from this event on.
    pub(super) values: IndexMap<String, f64>,
    /// The entries (indices into [`Source::elements`]) to rebuild.
    pub(super) entries: Vec<usize>,
}

/// The events in time order, each checked by building its entries once; problems go to
/// `problems`.
pub(super) fn plan(
    source: &Source,
    parameters: &IndexMap<String, f64>,
    eqs: &StateEquations,
    problems: &mut Vec<ModelError>,
) -> Vec<EventPlan> {
    let mut defs = source.events.clone();
    defs.sort_by(|a, b| a.t.total_cmp(&b.t));
    let mut set: IndexMap<String, RawValue> = IndexMap::new();
    let mut current = parameters.clone();
    let mut plans = Vec::new();
    for ev in defs {
        if !ev.t.is_finite() {
            problems.push(source.err(
                ErrorKind::Settings,
                Some(&ev.span),
                format!("event time {} is not finite", ev.t),
            ));
            continue;
        }
        let mut ok = true;
        for (k, v) in &ev.set {
            if source.param_exprs.contains_key(k) {
                set.insert(k.clone(), v.clone());
                continue;
            }
            ok = false;
            problems.push(
                source
                    .err(
                        ErrorKind::Settings,
                        Some(&v.span),
                        format!("event at t = {}: `{k}` is not a parameter", ev.t),
                    )
                    .hint(format!(
                        "events set names from [parameters]: {}",
                        parameters.keys().cloned().collect::<Vec<_>>().join(", ")
                    )),
            );
        }
        if !ok {
            continue;
        }
        let values = match source.evaluate_parameters(&set) {
            Ok(v) => v,
            Err(e) => {
                problems.push(e);
                continue;
            }
        };
        let changed: HashSet<&String> = values
            .iter()
            .filter(|(k, v)| current.get(*k) != Some(*v))
            .map(|(k, _)| k)
            .collect();
        let entries: Vec<usize> = source
            .elements
            .iter()
            .enumerate()
            .filter(|(_, d)| d.used.iter().any(|u| changed.contains(u)))
            .map(|(i, _)| i)
            .collect();
        // built once here so that an entry refusing its new values shows at load time
        if let Err(e) = source.rebuild(eqs, &values, &entries, Some(&ev.span)) {
            problems.push(e);
            continue;
        }
        current = values.clone();
        plans.push(EventPlan {
            t: ev.t,
            span: ev.span,
            values,
            entries,
        });
    }
    plans
}

/// The events of `plans`, their entries built.
pub(super) fn build(
    source: &Source,
    eqs: &StateEquations,
    plans: &[EventPlan],
) -> Result<Vec<Event>, ModelError> {
    plans
        .iter()
        .map(|p| {
            Ok(Event {
                t: p.t,
                replacements: source.rebuild(eqs, &p.values, &p.entries, Some(&p.span))?,
            })
        })
        .collect()
}

/// Every entry some event rebuilds, once, in order.
pub(super) fn touched(plans: &[EventPlan]) -> Vec<usize> {
    let mut all: Vec<usize> = plans
        .iter()
        .flat_map(|p| p.entries.iter().copied())
        .collect();
    all.sort_unstable();
    all.dedup();
    all
}
