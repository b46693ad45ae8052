//! The manipulator's elements allocate nothing per evaluation once warmed up: the knuckle
//! boom scene (I-, C-, R-fields, both actuator MTFs, the lumped-mass MTF with its masses,
//! springs, dampers and gravity, the reaction block) built as `ArmScene::add_to` builds it,
//! with constant cylinder forces, evaluated at 100 changing states by `rhs` (the right-hand
//! side) and by `evaluate` (every stage, the outputs included).
//!
//! A counting global allocator sees every allocation of the process, so this file holds a
//! single test: no other test thread runs beside it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::alloc::System;

use bg_manipulator::{ArmScene, LumpedMassModel};
use bondgraph::{assign_causality, BondGraph, EffortSource, StateEquations};
use common::{crane_links, cylinders, initial_pose, lumped_masses, Rng, G};
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn crane(modes: u32) -> StateEquations {
    let mut scene = ArmScene::new(crane_links(modes), G);
    scene.q0 = initial_pose(0);
    scene.damping = vec![0.0, 0.0, 5000.0];
    scene.actuators = cylinders();
    scene.lumped_masses = lumped_masses();
    scene.lumped_model = LumpedMassModel::Springs {
        stiffness: 1e8,
        damping: 2e5,
    };
    scene.paper_reactions = true;
    let mut g = BondGraph::new();
    let ports = scene.add_to(&mut g, "crane").unwrap();
    for (k, f) in [2.07e5, -8.06e4].into_iter().enumerate() {
        let se = g.add(&format!("F{}", k + 1), EffortSource::new(f)).unwrap();
        let name = format!("cyl{}", k + 1);
        let (_, id, port) = ports.iter().find(|p| p.0 == name).unwrap().clone();
        g.connect((se, None), (id, port)).unwrap();
    }
    StateEquations::new(assign_causality(g).unwrap()).unwrap()
}

#[test]
fn no_allocation_per_evaluation_after_the_first() {
    // the counter counts
    let region = Region::new(GLOBAL);
    let v = std::hint::black_box(vec![1.0f64; 8]);
    assert_eq!(region.change().allocations, 1);
    drop(v);
    for modes in [3, 10] {
        let eqs = crane(modes);
        let n = eqs.n_states();
        let x0 = eqs.initial_state();
        let mut rng = Rng::new(17);
        let states: Vec<Vec<f64>> = (0..100)
            .map(|_| {
                x0.iter()
                    .map(|x| x + rng.uniform(-1e-2, 1e-2) * x.abs().max(1e-3))
                    .collect()
            })
            .collect();
        let mut dx = vec![0.0; n];
        eqs.rhs(0.0, &x0, &mut dx);
        eqs.evaluate(0.0, &x0);
        // The counter sees every thread of the process: the test harness's own threads
        // allocate now and then. An allocation of the rhs would show in every pass, so the
        // fewest over three passes is what the evaluation itself allocates.
        let mut rhs = (usize::MAX, usize::MAX);
        let mut evaluate = (usize::MAX, usize::MAX);
        for _ in 0..3 {
            let region = Region::new(GLOBAL);
            for (k, x) in states.iter().enumerate() {
                eqs.rhs(0.01 * k as f64, x, &mut dx);
            }
            let c = region.change();
            rhs = rhs.min((c.allocations, c.reallocations));
            let region = Region::new(GLOBAL);
            for (k, x) in states.iter().enumerate() {
                eqs.evaluate(0.01 * k as f64, x);
            }
            let c = region.change();
            evaluate = evaluate.min((c.allocations, c.reallocations));
        }
        assert!(dx.iter().all(|d| d.is_finite()));
        assert_eq!(
            rhs,
            (0, 0),
            "{modes} modes: rhs (allocations, reallocations)"
        );
        assert_eq!(
            evaluate,
            (0, 0),
            "{modes} modes: evaluate (allocations, reallocations)"
        );
    }
}
