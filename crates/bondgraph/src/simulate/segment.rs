//! One segment of a run, between events: the equations as the methods need them (rhs with a
//! NaN watch, exact Jacobian–vector products for diffsol), then the method's stepper, driven
//! to the segment's end.

use std::cell::{Cell, RefCell};

use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeEquations, Op};

use super::radau::run_radau;
use super::stepper::{drive, Diffsol, Stepper};
use super::{bounds, Method, Recorder, SegmentError, Settings, Statistics};
use crate::error::SimulationError;

type M = NalgebraMat<f64>;
type LS = NalgebraLU<f64>;

/// Integrate from `t` to `t_stop`, recording grid rows strictly before `t_stop`.
pub(super) fn run_segment(
    rec: &mut Recorder<'_>,
    settings: &Settings,
    t: f64,
    t_stop: f64,
    x: &[f64],
    stats: &mut Statistics,
) -> Result<Vec<f64>, SegmentError> {
    let eqs = rec.eqs;
    let n = x.len();
    let nominal: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let atol: Vec<f64> = nominal.iter().map(|s| settings.atol * s).collect();
    let rhs_calls = Cell::new(0usize);
    let jac_calls = Cell::new(0usize);
    let bad: RefCell<Option<(f64, Vec<f64>)>> = RefCell::new(None);
    let cache = RefCell::new(JacCache {
        x: vec![f64::NAN; n],
        t: f64::NAN,
        // sized at the first use: Radau (the default) never asks, and an n×n matrix here
        // was most of a 2 000-segment pipe's memory
        jac: nalgebra::DMatrix::zeros(0, 0),
    });
    let rhs = |x: &[f64], _p: &[f64], t: f64, dx: &mut [f64]| {
        rhs_calls.set(rhs_calls.get() + 1);
        eqs.rhs(t, x, dx);
        if bad.borrow().is_none() && dx.iter().any(|v| !v.is_finite()) {
            *bad.borrow_mut() = Some((t, x.to_vec()));
        }
    };
    // The exact Jacobian, assembled once per (t, x) (bitwise): diffsol asks for it column
    // by column (v = unit vectors) and for products with Newton updates.
    let jvp = |x: &[f64], _p: &[f64], t: f64, v: &[f64], jv: &mut [f64]| {
        let mut c = cache.borrow_mut();
        let JacCache { x: cx, t: ct, jac } = &mut *c;
        if jac.nrows() != n {
            *jac = nalgebra::DMatrix::zeros(n, n);
        }
        if ct.to_bits() != t.to_bits() || cx.iter().zip(x).any(|(a, b)| a.to_bits() != b.to_bits())
        {
            eqs.jacobian(t, x, jac);
            jac_calls.set(jac_calls.get() + 1);
            cx.copy_from_slice(x);
            *ct = t;
        }
        jv.fill(0.0);
        for (k, &vk) in v.iter().enumerate() {
            if vk != 0.0 {
                for (j, a) in jv.iter_mut().zip(jac.column(k).iter()) {
                    *j += a * vk;
                }
            }
        }
    };
    // Equations that are not finite where the segment starts would send the solver after a
    // NaN step size: refuse at once, naming the culprit.
    {
        let mut dx = vec![0.0; n];
        eqs.rhs(t, x, &mut dx);
        if dx.iter().any(|v| !v.is_finite()) {
            let c = eqs
                .first_non_finite(t, x)
                .map(|c| format!("; {c}"))
                .unwrap_or_default();
            return Err((
                t,
                x.to_vec(),
                SimulationError::Solver {
                    t,
                    message: "the equations are not finite at the start".into(),
                    culprit: c,
                    hint: None,
                },
            ));
        }
    }
    let x0 = x.to_vec();
    let limits = bounds(eqs);
    if settings.method == Method::Radau5 {
        return run_radau(rec, settings, t, t_stop, x, &atol, limits, &bad, stats);
    }
    let n_roots = limits.len();
    let roots_of = limits.clone();
    let problem = OdeBuilder::<M>::new()
        .t0(t)
        .rtol(settings.rtol)
        .atol(atol)
        .rhs_implicit(rhs, jvp)
        .init(move |_p, _t, y| y.copy_from_slice(&x0), n)
        .root(
            move |x, _p, _t, g| {
                for (gk, b) in g.iter_mut().zip(&roots_of) {
                    *gk = b.margin(x);
                }
            },
            n_roots,
        )
        .build();
    let mut problem = match problem {
        Ok(p) => p,
        Err(e) => {
            return Err((
                t,
                x.to_vec(),
                SimulationError::SolverSetup {
                    message: format!("{e}"),
                },
            ))
        }
    };
    // diffsol counts Newton failures cumulatively over a solver's life: recovered failures
    // must not end a long segment, but a NaN step size never trips the step-size check, so
    // the limit stays finite.
    problem.ode_options.max_nonlinear_solver_failures = 10_000;
    problem.ode_options.max_error_test_failures = 100;
    let result = match settings.method {
        Method::Bdf => problem
            .bdf::<LS>()
            .map(|s| Box::new(Diffsol::new(s)) as Box<dyn Stepper + '_>),
        Method::Esdirk34 => problem
            .esdirk34::<LS>()
            .map(|s| Box::new(Diffsol::new(s)) as Box<dyn Stepper + '_>),
        Method::TrBdf2 => problem
            .tr_bdf2::<LS>()
            .map(|s| Box::new(Diffsol::new(s)) as Box<dyn Stepper + '_>),
        Method::Tsit45 => problem
            .tsit45()
            .map(|s| Box::new(Diffsol::new(s)) as Box<dyn Stepper + '_>),
        Method::Radau5 => Err(diffsol::error::DiffsolError::Other(
            "radau5 is not a diffsol method".into(),
        )),
    }
    .map_err(|e| e.to_string())
    .and_then(|mut s| {
        s.set_stop_time(t_stop)?;
        Ok(drive(
            s.as_mut(),
            rec,
            t_stop,
            settings,
            &limits,
            &bad,
            stats,
        ))
    });
    stats.rhs_evals += rhs_calls.get();
    stats.jac_assemblies += jac_calls.get();
    stats.jac_evals += problem.eqn.rhs().statistics().number_of_matrix_evals;
    match result {
        Ok(r) => r,
        Err(message) => Err((
            t,
            x.to_vec(),
            SimulationError::Solver {
                t,
                message,
                culprit: String::new(),
                hint: None,
            },
        )),
    }
}

struct JacCache {
    x: Vec<f64>,
    t: f64,
    jac: nalgebra::DMatrix<f64>,
}
