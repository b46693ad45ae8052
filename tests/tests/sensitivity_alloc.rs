//! A sensitivity run allocates nothing per step: its allocations do not grow with the
//! number of steps (`Model::sensitivities` on the mass–spring–damper over 2 s and over
//! 20 s with the same number of output rows, ten times the steps).
//!
//! The allocator counts every thread, so the file holds a single test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::alloc::System;

use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Allocations (count) and accepted steps of one sensitivity run to `t_end` with 200 rows.
fn allocations(t_end: f64) -> (usize, usize) {
    let set = [
        "simulation.rtol=1e-9".to_owned(),
        "simulation.solver=\"radau5\"".to_owned(),
        format!("simulation.t_end={t_end:?}"),
        format!("simulation.dt_out={:?}", t_end / 200.0),
    ];
    let refs: Vec<&str> = set.iter().map(String::as_str).collect();
    let params: Vec<String> = ["k", "c", "x0"].iter().map(|s| (*s).to_owned()).collect();
    let mut best = (usize::MAX, 0);
    for _ in 0..3 {
        let mut model = bg_tests::load("mass_spring_damper", &refs).unwrap();
        let region = Region::new(GLOBAL);
        let s = model.sensitivities(&params).unwrap();
        let count = region.change().allocations;
        assert_eq!(s.t.len(), 201);
        if count < best.0 {
            best = (count, s.steps);
        }
    }
    best
}

#[test]
fn sensitivity_run_allocates_nothing_per_step() {
    let (short, steps_short) = allocations(2.0);
    let (long, steps_long) = allocations(20.0);
    eprintln!("{steps_short} steps: {short} allocations; {steps_long} steps: {long} allocations");
    assert!(
        steps_long > 5 * steps_short,
        "{steps_short} vs {steps_long} steps"
    );
    // the twins are built before the run: the same set-up either way, nothing per step
    assert_eq!(short, long);
}
