//! The sparse path allocates nothing per factorisation or solve once warmed up: a counting
//! global allocator watches Radau steps (refactorisations on the stored pivot order,
//! pivoted factorisations where a pivot fails, the Newton solves) on a banded chain and on
//! Van der Pol (whose 2×2 iteration matrices change pivot order often).
//!
//! The allocator counts every thread, so the file holds a single test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::alloc::System;

use bg_solver::radau::*;
use bg_solver::SparsePattern;
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// dpᵢ/dt = qᵢ₋₁ − qᵢ − pᵢ³, dqᵢ/dt = k(pᵢ − pᵢ₊₁) − c·qᵢ, driven at the first node.
struct Chain {
    m: usize,
}

impl Chain {
    const K: f64 = 400.0;
    const C: f64 = 5.0;
    fn entries(&self, y: &[f64], mut put: impl FnMut(usize, usize, f64)) {
        let m = self.m;
        for i in 0..m {
            let (p, q) = (i, m + i);
            if i > 0 {
                put(p, m + i - 1, 1.0);
            }
            put(p, q, -1.0);
            put(p, p, -3.0 * y[p] * y[p]);
            put(q, p, Self::K);
            if i + 1 < m {
                put(q, i + 1, -Self::K);
            }
            put(q, q, -Self::C);
        }
    }
}

impl OdeSystem for Chain {
    fn n(&self) -> usize {
        2 * self.m
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let m = self.m;
        for i in 0..m {
            let q_in = if i == 0 {
                (10.0 * t).sin()
            } else {
                y[m + i - 1]
            };
            dy[i] = q_in - y[m + i] - y[i].powi(3);
            let p_next = if i + 1 < m { y[i + 1] } else { 0.0 };
            dy[m + i] = Self::K * (y[i] - p_next) - Self::C * y[m + i];
        }
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
        jac.fill(0.0);
        self.entries(y, |i, j, v| jac[(i, j)] = v);
    }
    fn jacobian_pattern(&self) -> Option<SparsePattern> {
        let n = 2 * self.m;
        let mut cols = vec![Vec::new(); n];
        self.entries(&vec![1.0; n], |i, j, _| cols[j].push(i));
        SparsePattern::from_columns(n, &cols).ok()
    }
    fn jacobian_sparse(
        &mut self,
        _t: f64,
        y: &[f64],
        _fy: &[f64],
        pattern: &SparsePattern,
        values: &mut [f64],
        _dense: &mut DMatrix<f64>,
    ) {
        values.fill(0.0);
        self.entries(y, |i, j, v| {
            if let Some(s) = pattern.slot(i, j) {
                values[s] = v;
            }
        });
    }
}

/// Van der Pol, μ = 1000, on the (dense) 2×2 pattern.
struct VanDerPol;

impl OdeSystem for VanDerPol {
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
    fn jacobian_pattern(&self) -> Option<SparsePattern> {
        Some(SparsePattern::dense(2))
    }
}

/// Allocations (count + reallocations, bytes) of the steps from `warm` to `stop`, after
/// steps to `warm`; and the LU factorisations and Newton iterations counted.
fn steps_after_warm_up(
    sys: &mut impl OdeSystem,
    y0: &[f64],
    warm: f64,
    stop: f64,
) -> ((usize, usize), usize, usize) {
    let options = RadauOptions {
        rtol: 1e-6,
        atol: vec![1e-6],
        linear_algebra: LinearAlgebra::Sparse,
        ..RadauOptions::default()
    };
    let mut radau = Radau5::new(sys, 0.0, y0, options).unwrap();
    assert!(radau.is_sparse());
    while !radau.step(sys, warm).unwrap().reached_stop {}
    let (lu0, newton0) = (
        radau.stats().lu_decompositions,
        radau.stats().newton_iterations,
    );
    let region = Region::new(GLOBAL);
    while !radau.step(sys, stop).unwrap().reached_stop {}
    let c = region.change();
    let s = radau.stats();
    (
        (c.allocations + c.reallocations, c.bytes_allocated),
        s.lu_decompositions - lu0,
        s.newton_iterations - newton0,
    )
}

#[test]
fn sparse_factorisations_and_solves_do_not_allocate() {
    let m = 100;
    let (alloc, lus, newton) = steps_after_warm_up(&mut Chain { m }, &vec![0.0; 2 * m], 0.3, 2.0);
    assert!(lus > 5 && newton > 100, "{lus} LU, {newton} Newton");
    assert_eq!(
        alloc,
        (0, 0),
        "chain: (allocations, bytes) in {lus} LU, {newton} Newton"
    );
    let (alloc, lus, newton) = steps_after_warm_up(&mut VanDerPol, &[2.0, 0.0], 0.5, 1.5);
    assert!(lus > 20 && newton > 100, "{lus} LU, {newton} Newton");
    assert_eq!(
        alloc,
        (0, 0),
        "Van der Pol: (allocations, bytes) in {lus} LU, {newton} Newton"
    );
}
