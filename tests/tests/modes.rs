//! `bondgraph::modes` on models with closed forms, and on the crane against a
//! central-difference Jacobian.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, Link};
use bondgraph::{assign_causality, modes, modes_of, BondGraph, DMatrix, StateEquations};

/// One link pinned at both ends (its joint held by a stiff joint damper, D₁₁ = 1e12
/// N·m·s/rad, as in `crates/manipulator/tests/flexible_link_frequencies.rs`): the bending
/// frequencies are ω_k = (kπ/L)²·√(EI/ρA)/√(1 + (I/A)(kπ/L)²), the Euler–Bernoulli value
/// lowered by the rotary inertia ρI (eq. 40), undamped. Tolerance 1e-6 relative.
#[test]
fn pinned_pinned_link_bending_frequencies() {
    let (l, e, rho, a, i) = (8.0, 210e9, 7850.0, 0.0264, 5.89e-4);
    let link = Link::beam(l, e, rho, a, i)
        .unwrap()
        .with_sine_modes(3)
        .unwrap();
    let mut scene = ArmScene::new(vec![link], 0.0);
    scene.damping = vec![1e12, 0.0, 0.0, 0.0];
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "beam").unwrap();
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let ms = modes(&eqs, 0.0, &eqs.initial_state()).unwrap();
    let mut bending: Vec<f64> = ms
        .iter()
        .filter(|m| m.damped_hz > 0.0)
        .map(|m| 2.0 * PI * m.natural_hz)
        .collect();
    bending.sort_by(f64::total_cmp);
    assert_eq!(bending.len(), 3, "{ms:?}");
    for (k, w) in bending.iter().enumerate() {
        let kf = (k + 1) as f64;
        let plain = (kf * PI / l).powi(2) * (e * i / (rho * a)).sqrt();
        let exact = plain / (1.0 + (i / a) * (kf * PI / l).powi(2)).sqrt();
        let rel = (w / exact - 1.0).abs();
        eprintln!(
            "mode {}: ω = {w:.9} rad/s, closed form {exact:.9}: rel. {rel:.1e}",
            k + 1
        );
        assert!(rel < 1e-6, "mode {}: {w} vs {exact}", k + 1);
    }
    for m in ms.iter().filter(|m| m.damped_hz > 0.0) {
        // undamped but for the energy the stiff joint damper takes out (ζ ≈ 1e-6)
        assert!(m.damping_ratio.abs() < 1e-5, "undamped: {m:?}");
        // a bending mode is its modal coordinate and momentum
        assert!(m.participation[0].1 + m.participation[1].1 > 0.99, "{m:?}");
    }
}

/// The crane's modes from the exact Jacobian equal those of a central-difference Jacobian
/// (relative step 1e-6 of each state's scale): the 15 oscillating modes to 1e-4 relative
/// (measured: up to 6e-5, the differences' own error). The real eigenvalues of the two
/// nearly identical spool–controller loops form near-double pairs, too sensitive for a
/// difference Jacobian to reproduce, and are not compared.
#[test]
fn crane_modes_match_a_difference_jacobian() {
    let m = bg_tests::load("knuckle_boom", &[]).unwrap();
    let eqs = &m.equations;
    let n = eqs.n_states();
    let x0 = m.x0.clone();
    let exact = modes(eqs, 0.0, &x0).unwrap();
    let mut fd = DMatrix::zeros(n, n);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        let h = 1e-6 * x0[j].abs().max(eqs.states()[j].nominal).max(1e-6);
        let mut x = x0.clone();
        x[j] = x0[j] + h;
        eqs.rhs(0.0, &x, &mut fp);
        x[j] = x0[j] - h;
        eqs.rhs(0.0, &x, &mut fm);
        for i in 0..n {
            fd[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    let diff = modes_of(&fd).unwrap();
    let oscillating = |ms: &[bondgraph::Mode]| -> Vec<bondgraph::Mode> {
        ms.iter().filter(|m| m.damped_hz > 0.01).cloned().collect()
    };
    let (a, b) = (oscillating(&exact), oscillating(&diff));
    assert_eq!(a.len(), 15, "14 oscillating modes and the payload swing");
    assert_eq!(a.len(), b.len());
    for (k, (a, b)) in a.iter().zip(&b).enumerate() {
        let rel = (a.eigenvalue - b.eigenvalue).norm() / a.eigenvalue.norm();
        eprintln!("{k}: {} vs {}: rel. {rel:.1e}", a.eigenvalue, b.eigenvalue);
        assert!(rel < 1e-4, "{k}: {} vs {}", a.eigenvalue, b.eigenvalue);
    }
    // no mode grows at the held start
    assert!(exact
        .iter()
        .all(|m| m.eigenvalue.re < 1e-6 * exact[0].eigenvalue.norm()));
}
