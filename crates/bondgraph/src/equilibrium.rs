//! Steady states as a solve: Newton's method on chosen unknown states and conditions.
//!
//! Some states are unknown (e.g. the chamber pressures that hold a load, a beam's modal
//! coordinates under gravity); as many conditions fix them, each a state derivative
//! (`mass.p.dot = 0`: an acceleration, or any rate, held at a value), a state itself, or any
//! other variable of the equations (an effort, flow or signal). The other states keep their
//! values. The conditions are solved by Newton's method with the exact Jacobian of
//! [`StateEquations::jacobian`] (its rows for the derivative conditions, unit rows for the
//! state conditions; central differences over the unknowns for other variables) and a
//! backtracking (Armijo) line search on the sum of squared scaled residuals.
//!
//! **Scaling.** An unknown is measured in units of its scale c_j = max(|x_j|, nominal_j) at
//! the start; a condition in units of its row scale s_i = max_j |∂r_i/∂x_j|·c_j there (what a
//! change of one scale of the most effective unknown does to it). The scaled residual
//! r_i/s_i is therefore the change of unknowns, in their scales, still needed; the solve
//! stops when every scaled residual is below `tol`.
//!
//! **Each condition in its own scale.** A row whose unknowns move it little next to the
//! terms it sums (a hose's pressure rate: a pump flow in, nearly as much out, a small leak
//! set by the pressure) has a rounding floor above `tol` in the scaled measure: Newton
//! converges and then cannot reduce the residual further. So when Newton stalls, each
//! condition is judged in its own scale too ([`Settle`]): a rate condition on a state is
//! met when the residual would move that state by less than its error weight
//! (`atol + rtol·|x|`, the integrator's own) over the whole run; a state condition when it
//! is within that weight; a variable condition when it is within
//! `atol + rtol·max(|v|, |value|)` (each times [`OWN_SCALE_FRACTION`], 1). A start accepted
//! so drifts by less over the run than the integrator resolves in one step; the conditions
//! so judged are listed ([`Equilibrium::own_scale`]). The crane's full rest asked for
//! tol = 1e-16 stalls with its arm's momentum rates at 5e-11 N·m, 0.1 of their own scale. A converged solve is judged as before, so a start that
//! solved before is unchanged to the bit.
//!
//! A system without an equilibrium is refused ([`EquilibriumError`]): the counts differ, a
//! condition depends on no unknown, the scaled Jacobian is singular (the unknowns of its
//! null direction are named), or the line search cannot reduce the residuals (the largest
//! ones are named).

use nalgebra::{DMatrix, DVector};

use crate::equations::{Probe, StateEquations};

mod error;

pub use error::EquilibriumError;

/// One condition of a steady state.
#[derive(Clone, Debug, PartialEq)]
pub enum Condition {
    /// dx_i/dt = value (e.g. 0: the state is at rest).
    Derivative {
        /// State index.
        state: usize,
        /// Required rate.
        value: f64,
    },
    /// x_i = value.
    State {
        /// State index.
        state: usize,
        /// Required value.
        value: f64,
    },
    /// Any variable the equations compute (an effort, a flow, a signal: a [`Probe`]) held at
    /// a value; its row of the Jacobian is a central difference over the unknowns.
    Variable {
        /// What to read.
        probe: Probe,
        /// Its name in reports (`lift_piston.mech.e`).
        label: String,
        /// Required value.
        value: f64,
    },
}

/// The fraction of a condition's own scale within which it is met when Newton stalls at
/// its rounding floor (see the module notes): 1, a drift over the run of at most one error
/// weight.
pub const OWN_SCALE_FRACTION: f64 = 1.0;

/// What a condition's own scale is made of: the integrator's tolerances and the span of the
/// run the start must stay steady over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settle {
    /// Absolute tolerance of the states.
    pub atol: f64,
    /// Relative tolerance of the states.
    pub rtol: f64,
    /// The time the start must stay steady over (`t_end − t_start`), s.
    pub span: f64,
}

impl Settle {
    /// The largest residual of `c` met in its own scale at `x`, where the condition's
    /// variable reads `v` (the state, or the variable for [`Condition::Variable`]).
    #[must_use]
    pub fn tolerance(&self, c: &Condition, x: &[f64], v: f64) -> f64 {
        let weight = |state: usize| self.atol + self.rtol * x.get(state).map_or(0.0, |x| x.abs());
        OWN_SCALE_FRACTION
            * match c {
                Condition::Derivative { state, .. } => weight(*state) / self.span,
                Condition::State { state, .. } => weight(*state),
                Condition::Variable { value, .. } => {
                    self.atol + self.rtol * v.abs().max(value.abs())
                }
            }
    }
}

/// A steady-state request: the unknown states and as many conditions.
#[derive(Clone, Debug)]
pub struct SteadyRequest {
    /// Indices of the unknown states.
    pub unknowns: Vec<usize>,
    /// The conditions, as many as unknowns.
    pub conditions: Vec<Condition>,
    /// Largest scaled residual accepted (default 1e-10).
    pub tol: f64,
    /// Most Newton iterations (default 50).
    pub max_iterations: usize,
    /// Each condition's own scale, for judging a solve that stalls at its rounding floor
    /// (default none: every condition is judged by `tol` in the scaled measure alone).
    pub settle: Option<Settle>,
}

impl SteadyRequest {
    /// A request with the default tolerance and iteration limit.
    #[must_use]
    pub fn new(unknowns: Vec<usize>, conditions: Vec<Condition>) -> Self {
        Self {
            unknowns,
            conditions,
            tol: 1e-10,
            max_iterations: 50,
            settle: None,
        }
    }
}

/// A solved steady state.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    /// The whole state vector, with the unknowns solved.
    pub x: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Per condition: its name (`mass.p.dot = 0`), the residual in the condition's units, and
    /// scaled by its row scale.
    pub residuals: Vec<(String, f64, f64)>,
    /// The conditions met in their own scale only ([`Settle`]), not by `tol` in the scaled
    /// measure: name, residual, the largest residual their own scale accepts. Empty when
    /// the solve converged in the scaled measure.
    pub own_scale: Vec<(String, f64, f64)>,
}

impl Equilibrium {
    /// The largest scaled residual and its condition.
    #[must_use]
    pub fn worst(&self) -> Option<&(String, f64, f64)> {
        self.residuals
            .iter()
            .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()))
    }
}

/// Name of a condition: `mass.p.dot = 0`, `spring.q = 0.01`.
#[must_use]
pub fn condition_name(eqs: &StateEquations, c: &Condition) -> String {
    let name = |i: usize| eqs.states().get(i).map_or("?", |s| s.name.as_str());
    match c {
        Condition::Derivative { state, value } => format!("{}.dot = {value}", name(*state)),
        Condition::State { state, value } => format!("{} = {value}", name(*state)),
        Condition::Variable { label, value, .. } => format!("{label} = {value}"),
    }
}

struct Problem<'a> {
    eqs: &'a StateEquations,
    t: f64,
    req: &'a SteadyRequest,
    dx: Vec<f64>,
    jac: DMatrix<f64>,
    row_scale: Vec<f64>,
    col_scale: Vec<f64>,
}

impl Problem<'_> {
    /// Residuals at x (unscaled).
    fn residuals(&mut self, x: &[f64]) -> Vec<f64> {
        let variables = self
            .req
            .conditions
            .iter()
            .any(|c| matches!(c, Condition::Variable { .. }));
        if variables {
            self.eqs.evaluate(self.t, x);
        }
        self.eqs.rhs(self.t, x, &mut self.dx);
        self.req
            .conditions
            .iter()
            .map(|c| match c {
                Condition::Derivative { state, value } => self.dx[*state] - value,
                Condition::State { state, value } => x[*state] - value,
                Condition::Variable { probe, value, .. } => {
                    self.eqs.read(*probe, self.t, x) - value
                }
            })
            .collect()
    }

    /// ∂r/∂z at x (unscaled), conditions × unknowns.
    fn jacobian(&mut self, x: &[f64]) -> DMatrix<f64> {
        self.eqs.jacobian(self.t, x, &mut self.jac);
        let (m, n) = (self.req.conditions.len(), self.req.unknowns.len());
        let mut out = DMatrix::from_fn(m, n, |i, j| {
            let u = self.req.unknowns[j];
            match &self.req.conditions[i] {
                Condition::Derivative { state, .. } => self.jac[(*state, u)],
                Condition::State { state, .. } => {
                    if *state == u {
                        1.0
                    } else {
                        0.0
                    }
                }
                Condition::Variable { .. } => 0.0,
            }
        });
        // rows of variables: central differences, step 1e-7 of each unknown's scale
        let rows: Vec<(usize, Probe)> = self
            .req
            .conditions
            .iter()
            .enumerate()
            .filter_map(|(i, c)| match c {
                Condition::Variable { probe, .. } => Some((i, *probe)),
                _ => None,
            })
            .collect();
        if !rows.is_empty() {
            let mut xp = x.to_vec();
            for j in 0..n {
                let u = self.req.unknowns[j];
                let h = 1e-7 * self.col_scale[j];
                xp[u] = x[u] + h;
                self.eqs.evaluate(self.t, &xp);
                let plus: Vec<f64> = rows
                    .iter()
                    .map(|&(_, p)| self.eqs.read(p, self.t, &xp))
                    .collect();
                xp[u] = x[u] - h;
                self.eqs.evaluate(self.t, &xp);
                for (k, &(i, p)) in rows.iter().enumerate() {
                    out[(i, j)] = (plus[k] - self.eqs.read(p, self.t, &xp)) / (2.0 * h);
                }
                xp[u] = x[u];
            }
        }
        out
    }

    fn scaled(&self, r: &[f64]) -> Vec<f64> {
        r.iter().zip(&self.row_scale).map(|(r, s)| r / s).collect()
    }

    fn report(&self, r: &[f64], worst_only: bool) -> Vec<(String, f64, f64)> {
        let s = self.scaled(r);
        let mut out: Vec<(String, f64, f64)> = self
            .req
            .conditions
            .iter()
            .enumerate()
            .map(|(i, c)| (condition_name(self.eqs, c), r[i], s[i]))
            .collect();
        if worst_only {
            out.sort_by(|a, b| b.2.abs().total_cmp(&a.2.abs()));
            out.truncate(4);
        }
        out
    }

    /// A stalled solve judged per condition in its own scale (see the module notes): the
    /// equilibrium if every condition is met by `tol` in the scaled measure or within its
    /// own scale ([`Settle::tolerance`]).
    fn settled(&mut self, x: Vec<f64>, r: &[f64], iterations: usize) -> Option<Equilibrium> {
        let settle = self.req.settle?;
        if r.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let s = self.scaled(r);
        let mut own_scale = Vec::new();
        for (i, c) in self.req.conditions.iter().enumerate() {
            if s[i].abs() <= self.req.tol {
                continue;
            }
            let v = match c {
                Condition::Variable { value, .. } => r[i] + value,
                Condition::Derivative { state, .. } | Condition::State { state, .. } => x[*state],
            };
            let tol = settle.tolerance(c, &x, v);
            if tol.is_nan() || r[i].abs() > tol {
                return None;
            }
            own_scale.push((condition_name(self.eqs, c), r[i], tol));
        }
        Some(Equilibrium {
            residuals: self.report(r, false),
            x,
            iterations,
            own_scale,
        })
    }

    fn names(&self) -> Vec<String> {
        self.req
            .unknowns
            .iter()
            .map(|&i| self.eqs.states()[i].name.clone())
            .collect()
    }
}

fn merit(s: &[f64]) -> f64 {
    0.5 * s.iter().map(|v| v * v).sum::<f64>()
}

/// Solve for a steady state: the unknown states of `req` such that its conditions hold at
/// time `t`, starting from `x0` (which also gives every other state).
///
/// # Returns
/// Most states a steady solve takes: each Newton iteration assembles the dense n×n Jacobian
/// (8·n² bytes: 128 MB at 4 000 states).
pub const MAX_STEADY_STATES: usize = 4000;

/// Most unknowns a steady solve takes: each Newton iteration factors the m×m reduced Jacobian
/// by SVD (about 10·m³ operations: a second or so at 500 unknowns).
pub const MAX_STEADY_UNKNOWNS: usize = 500;

/// Why a steady solve of `n` states and `m` unknowns is refused before any work, if it is.
#[must_use]
pub fn steady_size_error(n: usize, m: usize) -> Option<String> {
    if n > MAX_STEADY_STATES {
        Some(format!(
            "{n} states, more than the {MAX_STEADY_STATES} a steady solve takes: it is dense (an n×n Jacobian of 8·n² bytes per Newton iteration)"
        ))
    } else if m > MAX_STEADY_UNKNOWNS {
        Some(format!(
            "{m} unknowns, more than the {MAX_STEADY_UNKNOWNS} a steady solve takes: it is dense (an SVD of the m×m reduced Jacobian, about 10·m³ operations, per Newton iteration)"
        ))
    } else {
        None
    }
}

/// The state vector with the unknowns solved and the residual of each condition, or an
/// [`EquilibriumError`] naming the unknowns and the largest residuals.
///
/// # Complexity
/// Per Newton iteration one Jacobian, one SVD of the m×m reduced Jacobian (O(m³)) and a few
/// right-hand sides for the line search.
pub fn solve_steady(
    eqs: &StateEquations,
    t: f64,
    x0: &[f64],
    req: &SteadyRequest,
) -> Result<Equilibrium, EquilibriumError> {
    let n = eqs.n_states();
    let state_name = |i: usize| eqs.states()[i].name.clone();
    if x0.len() != n {
        return Err(EquilibriumError::Invalid(format!(
            "the state vector has {} values, the equations {n} states",
            x0.len()
        )));
    }
    if let Some(m) = steady_size_error(n, req.unknowns.len()) {
        return Err(EquilibriumError::Invalid(m));
    }
    for (k, &u) in req.unknowns.iter().enumerate() {
        if u >= n {
            return Err(EquilibriumError::Invalid(format!("no state {u}")));
        }
        if req.unknowns[..k].contains(&u) {
            return Err(EquilibriumError::Invalid(format!(
                "`{}` is named twice as an unknown",
                state_name(u)
            )));
        }
    }
    for c in &req.conditions {
        if let Condition::Derivative { state, .. } | Condition::State { state, .. } = c {
            if *state >= n {
                return Err(EquilibriumError::Invalid(format!("no state {state}")));
            }
        }
    }
    if req.unknowns.len() != req.conditions.len() {
        return Err(EquilibriumError::CountMismatch {
            unknowns: req.unknowns.iter().map(|&i| state_name(i)).collect(),
            conditions: req
                .conditions
                .iter()
                .map(|c| condition_name(eqs, c))
                .collect(),
        });
    }
    let mut x = x0.to_vec();
    let m = req.unknowns.len();
    if m == 0 {
        return Ok(Equilibrium {
            x,
            iterations: 0,
            residuals: Vec::new(),
            own_scale: Vec::new(),
        });
    }
    let mut p = Problem {
        eqs,
        t,
        req,
        dx: vec![0.0; n],
        jac: DMatrix::zeros(n, n),
        row_scale: vec![1.0; m],
        col_scale: req
            .unknowns
            .iter()
            .map(|&i| {
                let c = x0[i].abs().max(eqs.states()[i].nominal.abs());
                if c > 0.0 && c.is_finite() {
                    c
                } else {
                    1.0
                }
            })
            .collect(),
    };
    // Row scales from the Jacobian at the start.
    let j0 = p.jacobian(&x);
    let r0 = p.residuals(&x);
    for i in 0..m {
        let s = (0..m)
            .map(|j| (j0[(i, j)] * p.col_scale[j]).abs())
            .fold(0.0, f64::max);
        if !(s > 0.0 && s.is_finite()) {
            return Err(EquilibriumError::Unaffected {
                condition: condition_name(eqs, &req.conditions[i]),
                residual: r0[i],
                unknowns: p.names(),
            });
        }
        p.row_scale[i] = s;
    }
    let mut r = r0;
    for it in 0..=req.max_iterations {
        let s = p.scaled(&r);
        let worst = s.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if worst <= req.tol {
            let residuals = p.report(&r, false);
            return Ok(Equilibrium {
                x,
                iterations: it,
                residuals,
                own_scale: Vec::new(),
            });
        }
        if it == req.max_iterations || !worst.is_finite() {
            break;
        }
        // Scaled Newton step: A·Δ = −s with A_ij = J_ij·c_j/s_i.
        let j = p.jacobian(&x);
        let a = DMatrix::from_fn(m, m, |i, k| j[(i, k)] * p.col_scale[k] / p.row_scale[i]);
        // A non-finite entry would keep nalgebra's SVD iterating forever (found by the loader
        // fuzzer on a mutated lift circuit): stop here, and bound the iterations otherwise
        // (the tolerance is `svd`'s own, 5 ε, so converged solves are unchanged to the bit).
        if a.iter().any(|v| !v.is_finite()) {
            break;
        }
        let Some(svd) = a.try_svd(true, true, 5.0 * f64::EPSILON, 1000 + 100 * m) else {
            break;
        };
        let (smax, smin, kmin) = svd.singular_values.iter().enumerate().fold(
            (0.0f64, f64::INFINITY, 0),
            |(mx, mn, k), (i, &v)| {
                if v < mn {
                    (mx.max(v), v, i)
                } else {
                    (mx.max(v), mn, k)
                }
            },
        );
        if smin.is_nan() || smin <= 1e-13 * smax {
            let null: Vec<f64> = svd
                .v_t
                .as_ref()
                .map(|vt| vt.row(kmin).iter().copied().collect())
                .unwrap_or_default();
            let big = null.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let mut named: Vec<(f64, String)> = null
                .iter()
                .enumerate()
                .filter(|(_, v)| v.abs() >= 0.1 * big)
                .map(|(k, v)| (v.abs(), state_name(req.unknowns[k])))
                .collect();
            named.sort_by(|a, b| b.0.total_cmp(&a.0));
            return Err(EquilibriumError::Singular {
                unknowns: named.into_iter().map(|(_, n)| n).collect(),
                ratio: if smax > 0.0 { smin / smax } else { 0.0 },
                residuals: p.report(&r, true),
            });
        }
        let rhs = DVector::from_iterator(m, s.iter().map(|v| -v));
        let Ok(delta) = svd.solve(&rhs, 0.0) else {
            break;
        };
        // Backtracking line search on ½‖s‖².
        let phi0 = merit(&s);
        let mut alpha = 1.0;
        let accepted = loop {
            let mut trial = x.clone();
            for (k, &u) in req.unknowns.iter().enumerate() {
                trial[u] += alpha * delta[k] * p.col_scale[k];
            }
            let rt = p.residuals(&trial);
            let phi = merit(&p.scaled(&rt));
            if phi.is_finite() && phi <= (1.0 - 1e-4 * alpha) * phi0 {
                break Some((trial, rt));
            }
            alpha *= 0.5;
            if alpha < 1e-10 {
                break None;
            }
        };
        match accepted {
            Some((trial, rt)) => {
                x = trial;
                r = rt;
            }
            None => {
                return p
                    .settled(x, &r, it + 1)
                    .ok_or_else(|| EquilibriumError::NoEquilibrium {
                        unknowns: p.names(),
                        iterations: it + 1,
                        residuals: p.report(&r, true),
                    })
            }
        }
    }
    let residuals = p.report(&r, true);
    p.settled(x, &r, req.max_iterations)
        .ok_or_else(|| EquilibriumError::NoEquilibrium {
            unknowns: p.names(),
            iterations: req.max_iterations,
            residuals,
        })
}

#[cfg(test)]
mod tests;
