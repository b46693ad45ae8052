//! One flexible link with its joint held: the small-amplitude frequencies of the hinged–hinged
//! modes match ω_k = (kπ/L)²√(EI/ρA)/√(1 + (I/A)(kπ/L)²), the Euler–Bernoulli frequency
//! lowered by the rotary inertia ρI of eq. 40 (by 0.2 %, 0.9 %, 1.5 % for k = 1, 2, 3 with
//! L = 8 m). The joint is held by a stiff joint damper (D₁₁ = 1e12 N·m·s/rad).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, Link};
use bondgraph::{assign_causality, simulate, BondGraph, Output, Settings, StateEquations};

const L: f64 = 8.0;
const E: f64 = 210e9;
const RHO: f64 = 7850.0;
const A: f64 = 0.0264;
const I: f64 = 5.89e-4;

/// Angular frequency from the zero crossings of a sampled oscillation.
fn frequency(t: &[f64], y: &[f64]) -> f64 {
    let mut crossings = Vec::new();
    for k in 1..y.len() {
        if y[k - 1] * y[k] < 0.0 {
            crossings.push(t[k - 1] + (t[k] - t[k - 1]) * y[k - 1] / (y[k - 1] - y[k]));
        }
    }
    let n = crossings.len();
    assert!(n >= 4, "too few crossings: {n}");
    PI * (n - 1) as f64 / (crossings[n - 1] - crossings[0])
}

#[test]
fn modal_frequencies_with_the_joint_held() {
    let link = Link::beam(L, E, RHO, A, I)
        .unwrap()
        .with_sine_modes(3)
        .unwrap();
    let mut scene = ArmScene::new(vec![link], 0.0);
    // a small deflection in each mode; the modes decouple, so each coordinate rings alone
    scene.q0 = vec![0.0, 1e-3, 5e-4, 2.5e-4];
    scene.damping = vec![1e12, 0.0, 0.0, 0.0];
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "beam").unwrap();
    let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let outputs: Vec<Output> = (0..4)
        .map(|k| Output {
            name: format!("q{k}"),
            probe: eqs.probe(&format!("beam_arm.q[{k}]")).unwrap(),
        })
        .collect();
    let settings = Settings {
        t_end: 0.2,
        dt_out: 2e-5,
        rtol: 1e-10,
        atol: 1e-12,
        ..Settings::default()
    };
    let x0 = eqs.initial_state();
    let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
    assert!(run.error.is_none(), "{:?}", run.error);
    let t = run.trajectory.column("t").unwrap();
    let joint = run.trajectory.column("q0").unwrap();
    let held = joint.iter().fold(0.0f64, |m, q| m.max(q.abs()));
    eprintln!("joint angle stays below {held:.1e} rad");
    assert!(held < 1e-7, "the joint is held: {held}");
    let plain = |k: f64| (k * PI / L).powi(2) * (E * I / (RHO * A)).sqrt();
    for k in 1..=3 {
        let kf = f64::from(k);
        let corrected = plain(kf) / (1.0 + (I / A) * (kf * PI / L).powi(2)).sqrt();
        let w = frequency(&t, &run.trajectory.column(&format!("q{k}")).unwrap());
        eprintln!(
            "mode {k}: ω = {w:.6} rad/s, with rotary inertia {corrected:.6} (rel. {:.1e}), without {:.6} (rel. {:.2e})",
            w / corrected - 1.0,
            plain(kf),
            w / plain(kf) - 1.0
        );
        assert!(
            (w / corrected - 1.0).abs() < 1e-6,
            "mode {k}: {w} vs {corrected}"
        );
        let lowered = 1.0 - corrected / plain(kf);
        assert!((w / plain(kf) - 1.0 + lowered).abs() < 1e-6 && lowered > 0.001 * kf * kf);
    }
    eprintln!("{}", run.stats);
}
