//! What is looked at after every accepted step besides the rows: the elements' limits (as
//! root functions: [`Bound`]) and their watched states' minima ([`Watcher`]).

use super::WatchReport;
use crate::equations::StateEquations;
use crate::error::SimulationError;

/// One side of a [`Limit`](crate::element::Limit), as a root function of the solver.
#[derive(Clone, Debug)]
pub(super) struct Bound {
    pub(super) index: usize,
    pub(super) value: f64,
    pub(super) upper: bool,
    pub(super) element: String,
    pub(super) state: String,
    pub(super) message: String,
    pub(super) hint: Option<String>,
}

impl Bound {
    /// Positive inside the bound, zero on it.
    pub(super) fn margin(&self, x: &[f64]) -> f64 {
        if self.upper {
            self.value - x[self.index]
        } else {
            x[self.index] - self.value
        }
    }
    pub(super) fn error(&self, t: f64) -> SimulationError {
        SimulationError::LimitReached {
            t,
            state: self.state.clone(),
            element: self.element.clone(),
            which: if self.upper { "upper" } else { "lower" },
            limit: self.value,
            message: self.message.clone(),
            hint: self.hint.clone(),
        }
    }
}

pub(super) fn bounds(eqs: &StateEquations) -> Vec<Bound> {
    let mut v = Vec::new();
    for id in 0..eqs.graph().n_elements() {
        let node = eqs.graph().node(id);
        for l in node.element.limits() {
            let Some(index) = eqs.state_index(id, l.state) else {
                continue;
            };
            let info = &eqs.states()[index];
            for (value, upper) in [(l.lower, false), (l.upper, true)] {
                if value.is_finite() {
                    v.push(Bound {
                        index,
                        value,
                        upper,
                        element: node.name.clone(),
                        state: info.name.clone(),
                        message: l.message.clone(),
                        hint: l.hint.clone(),
                    });
                }
            }
        }
    }
    v
}

pub(super) struct Watcher {
    pub(super) index: usize,
    pub(super) report: WatchReport,
    pub(super) warn_below: Option<f64>,
    pub(super) warning: String,
}

pub(super) fn watchers(eqs: &StateEquations) -> Vec<Watcher> {
    let mut v = Vec::new();
    for id in 0..eqs.graph().n_elements() {
        let node = eqs.graph().node(id);
        for w in node.element.watches() {
            let Some(index) = eqs.state_index(id, w.state) else {
                continue;
            };
            let info = &eqs.states()[index];
            v.push(Watcher {
                index,
                report: WatchReport {
                    element: node.name.clone(),
                    state: info.name.clone(),
                    name: w.name,
                    min: f64::INFINITY,
                    t_min: f64::NAN,
                    warning: None,
                },
                warn_below: w.warn_below,
                warning: w.warning,
            });
        }
    }
    v
}

pub(super) fn watch(w: &mut [Watcher], t: f64, x: &[f64]) {
    for w in w {
        if x[w.index] < w.report.min {
            w.report.min = x[w.index];
            w.report.t_min = t;
        }
    }
}

pub(super) fn reports(w: Vec<Watcher>) -> Vec<WatchReport> {
    w.into_iter()
        .map(|w| {
            let mut r = w.report;
            if let Some(lim) = w.warn_below {
                if r.min < lim {
                    r.warning = Some(format!(
                        "{} of `{}` fell to {:.6e} at t = {:.6} s, below {lim:e}: {}",
                        r.name, r.element, r.min, r.t_min, w.warning
                    ));
                }
            }
            r
        })
        .collect()
}
