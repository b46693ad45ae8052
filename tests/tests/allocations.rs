//! The right-hand side and the Jacobian allocate nothing once warmed up: a counting global
//! allocator watches 100 `rhs` calls and 10 `jacobian` calls at varying states, for every
//! model in `models/` (performance guide: "no allocation in the rhs").
//!
//! The allocator counts every thread, so the file holds a single test (see below).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::alloc::System;

use bg_tests::{is_refused, model_files};
use bondgraph::{DMatrix, StateEquations};
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Allocations (count, bytes) of 100 rhs calls, then of 10 Jacobians, at varying states.
fn allocations(eqs: &StateEquations) -> ((usize, usize), (usize, usize)) {
    let n = eqs.n_states();
    let x0 = eqs.initial_state();
    let states: Vec<Vec<f64>> = (0..100)
        .map(|k| {
            x0.iter()
                .zip(eqs.states())
                .enumerate()
                .map(|(j, (x, s))| x + 1e-3 * s.nominal * ((j * 7 + k * 13) as f64).sin())
                .collect()
        })
        .collect();
    let mut dx = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, n);
    eqs.rhs(0.0, &x0, &mut dx);
    eqs.jacobian(0.0, &x0, &mut jac);
    let pattern = eqs.jacobian_pattern().unwrap();
    let mut values = vec![0.0; pattern.nnz()];
    eqs.jacobian_sparse(0.0, &x0, &pattern, &mut values);
    // The counter sees every thread of the process (the harness's threads allocate now and
    // then); an allocation of rhs or the Jacobian shows in every pass, so keep the fewest.
    let mut best = ((usize::MAX, 0), (usize::MAX, 0));
    for _ in 0..3 {
        let region = Region::new(GLOBAL);
        for (k, x) in states.iter().enumerate() {
            eqs.rhs(1e-3 * k as f64, x, &mut dx);
        }
        let rhs = region.change();
        let region = Region::new(GLOBAL);
        for (k, x) in states.iter().take(10).enumerate() {
            eqs.jacobian(1e-3 * k as f64, x, &mut jac);
            // The sparse path, straight into the pattern's value slots.
            eqs.jacobian_sparse(1e-3 * k as f64, x, &pattern, &mut values);
        }
        let jacobian = region.change();
        best.0 = best
            .0
            .min((rhs.allocations + rhs.reallocations, rhs.bytes_allocated));
        best.1 = best.1.min((
            jacobian.allocations + jacobian.reallocations,
            jacobian.bytes_allocated,
        ));
    }
    best
}

fn check(name: &str) {
    let model = if name == "every_kind" {
        bg_tests::every_kind().unwrap()
    } else {
        let path = bg_tests::root().join("models").join(format!("{name}.toml"));
        bg_model::Model::load(&path, &bg_sim::registry(), &[]).unwrap()
    };
    let (rhs, jac) = allocations(&model.equations);
    assert_eq!(rhs, (0, 0), "{name}: (allocations, bytes) in 100 rhs calls");
    assert_eq!(jac, (0, 0), "{name}: (allocations, bytes) in 10 Jacobians");
    assert_eq!(
        subset_allocations(&model),
        (0, 0),
        "{name}: (allocations, bytes) in 100 evaluations of the outputs' stages"
    );
}

/// Allocations (count, bytes) of 100 evaluations of the stages the outputs need
/// (`evaluate_only`, what a run does for every row and step), and their reads.
fn subset_allocations(model: &bg_model::Model) -> (usize, usize) {
    let eqs = &model.equations;
    let probes: Vec<bondgraph::Probe> = model.outputs.iter().map(|o| o.probe).collect();
    let subset = eqs.subset(&probes);
    let x0 = model.x0.clone();
    eqs.evaluate_only(&subset, 0.0, &x0);
    let mut best = (usize::MAX, 0);
    for _ in 0..3 {
        let mut sum = 0.0;
        let region = Region::new(GLOBAL);
        for k in 0..100 {
            let t = 1e-3 * f64::from(k);
            eqs.evaluate_only(&subset, t, &x0);
            sum += probes.iter().map(|&p| eqs.read(p, t, &x0)).sum::<f64>();
        }
        let c = region.change();
        std::hint::black_box(sum);
        best = best.min((c.allocations + c.reallocations, c.bytes_allocated));
    }
    best
}

/// The allocator counts every thread, and the test harness allocates on its own thread when
/// a test ends: so this file has one `#[test]`, which runs the checks one after the other
/// while nothing else in the process runs.
#[test]
fn nothing_allocates_in_the_solver_loop() {
    rhs_and_jacobian_do_not_allocate();
    energy_audit_steps_do_not_allocate();
    radau_steps_do_not_allocate();
    sparse_newton_iterations_do_not_allocate();
}

/// On the sparse path the refactorisation on the stored patterns and the triangular solves
/// work in storage sized once (`bg_solver::sparse`); what allocates at all is faer's pivoted
/// factorisation when a stored pivot fails (Van der Pol changes its pivot order often: 27
/// allocations in 224 factorisations and 655 Newton iterations here).
fn sparse_newton_iterations_do_not_allocate() {
    use bondgraph::radau::{LinearAlgebra, Radau5, RadauOptions};
    let mut sys = VanDerPol;
    let options = RadauOptions {
        rtol: 1e-6,
        atol: vec![1e-6],
        linear_algebra: LinearAlgebra::Sparse,
        ..RadauOptions::default()
    };
    let mut radau = Radau5::new(&mut sys, 0.0, &[2.0, 0.0], options).unwrap();
    assert!(radau.is_sparse());
    let region = Region::new(GLOBAL);
    while !radau.step(&mut sys, 1.5).unwrap().reached_stop {}
    let stats = region.change();
    let s = radau.stats();
    assert!(s.newton_iterations > 200, "{s:?}");
    assert!(
        stats.allocations + stats.reallocations <= 3 * s.lu_decompositions,
        "{} allocations for {} LU and {} Newton iterations",
        stats.allocations + stats.reallocations,
        s.lu_decompositions,
        s.newton_iterations
    );
}

fn rhs_and_jacobian_do_not_allocate() {
    let mut checked = Vec::new();
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        check(&name);
        checked.push(name);
    }
    check("every_kind");
    // the crane with the axial shortening of its booms (geometric stiffening)
    let stiff = bg_tests::load(
        "knuckle_boom",
        &["elements.crane.geometric_stiffening=true"],
    )
    .unwrap();
    let (rhs, jac) = allocations(&stiff.equations);
    assert_eq!(rhs, (0, 0), "knuckle_boom with stiffening: rhs");
    assert_eq!(jac, (0, 0), "knuckle_boom with stiffening: Jacobian");
    for must in ["mass_spring_damper", "cylinder_lift", "knuckle_boom"] {
        assert!(checked.iter().any(|c| c == must), "{must} not checked");
    }
}

/// The energy audit's work after an accepted step (three evaluations of the plan, the power
/// of every element, the drives' external power) allocates nothing (docs/energy.md).
fn energy_audit_steps_do_not_allocate() {
    for name in [
        "knuckle_boom",
        "lift_circuit",
        "ls_circuit",
        "accumulator_circuit",
    ] {
        let model = bg_tests::load(name, &[]).unwrap();
        let eqs = &model.equations;
        let x0 = eqs.initial_state();
        let mut audit = bondgraph::EnergyAudit::new(eqs);
        audit.begin_segment(eqs, 0.0, &x0);
        let dense = |_: f64, y: &mut [f64]| {
            y.copy_from_slice(&x0);
            Ok(())
        };
        audit.step(eqs, 0.0, 1e-3, &x0, dense).unwrap();
        let mut best = usize::MAX;
        for _ in 0..3 {
            let region = Region::new(GLOBAL);
            for k in 1..50 {
                let t = 1e-3 * f64::from(k);
                audit.step(eqs, t, t + 1e-3, &x0, dense).unwrap();
            }
            let c = region.change();
            best = best.min(c.allocations + c.reallocations);
        }
        assert_eq!(best, 0, "{name}: allocations in 49 audited steps");
        assert_eq!(audit.report(eqs).steps, 50 * 3 - 2);
    }
}

/// Van der Pol (μ = 1000, stiff) with its analytic Jacobian, for the Radau test below.
struct VanDerPol;

impl bondgraph::radau::OdeSystem for VanDerPol {
    fn n(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = 1000.0 * ((1.0 - y[0] * y[0]) * y[1] - y[0]);
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
        jac[(0, 0)] = 0.0;
        jac[(0, 1)] = 1.0;
        jac[(1, 0)] = 1000.0 * (-2.0 * y[0] * y[1] - 1.0);
        jac[(1, 1)] = 1000.0 * (1.0 - y[0] * y[0]);
    }
    fn jacobian_pattern(&self) -> Option<bondgraph::radau::SparsePattern> {
        Some(bondgraph::radau::SparsePattern::dense(2))
    }
}

/// Radau5 allocates nothing after `new`: steps (factorisations, solves), restarts and
/// dense output, on a stiff problem that rejects steps and renews Jacobians.
fn radau_steps_do_not_allocate() {
    use bondgraph::radau::{Radau5, RadauOptions};
    let mut sys = VanDerPol;
    let options = RadauOptions {
        rtol: 1e-6,
        atol: vec![1e-6],
        ..RadauOptions::default()
    };
    let mut radau = Radau5::new(&mut sys, 0.0, &[2.0, 0.0], options).unwrap();
    let mut out = [0.0; 2];
    let region = Region::new(GLOBAL);
    for t_stop in [0.5, 1.0, 1.5] {
        while !radau.step(&mut sys, t_stop).unwrap().reached_stop {
            let mid = 0.5 * (radau.t_prev() + radau.t());
            radau.interpolate(mid, &mut out).unwrap();
        }
        radau.restart(None).unwrap();
    }
    let stats = region.change();
    assert!(radau.stats().steps > 100, "{:?}", radau.stats());
    assert!(radau.stats().lu_decompositions > 20, "{:?}", radau.stats());
    assert_eq!(
        (
            stats.allocations + stats.reallocations,
            stats.bytes_allocated
        ),
        (0, 0),
        "(allocations, bytes) in {:?}",
        radau.stats()
    );
}
