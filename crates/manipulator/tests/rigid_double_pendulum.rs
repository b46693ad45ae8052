//! A rigid double pendulum (0 modes) built from the bond-graph elements: M(q) and the
//! accelerations published by the I-field match an independent Lagrange derivation.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_manipulator::{ArmScene, Link, PointMass};
use bondgraph::{assign_causality, BondGraph, StateEquations};
use nalgebra::{Matrix2, Vector2};

const G: f64 = 9.81;
// Link 1: uniform rod (μ1, j1 per length) with a point mass pm1 at a1.
const L1: f64 = 1.3;
const MU1: f64 = 2.0;
const J1: f64 = 0.01;
const PM1: f64 = 0.7;
const A1: f64 = 0.4;
// Link 2: uniform rod with a point mass pm2 at its end.
const L2: f64 = 0.9;
const MU2: f64 = 1.5;
const J2: f64 = 0.02;
const PM2: f64 = 1.1;

fn links() -> Vec<Link> {
    let pm = |x, mass| PointMass {
        x,
        mass,
        inertia: 0.0,
    };
    vec![
        Link::rigid(L1, MU1)
            .unwrap()
            .with_rotary_inertia(J1)
            .unwrap()
            .with_point_mass(pm(A1, PM1))
            .unwrap(),
        Link::rigid(L2, MU2)
            .unwrap()
            .with_rotary_inertia(J2)
            .unwrap()
            .with_point_mass(pm(L2, PM2))
            .unwrap(),
    ]
}

/// Lagrange, by hand: T = ½ I1 q̇1² + ½ [M2 L1² q̇1² + I2 φ̇2² + 2 L1 s2 q̇1 φ̇2 cos q2],
/// φ̇2 = q̇1 + q̇2; V = g [(s1 + M2 L1) sin q1 + s2 sin(q1 + q2)].
fn closed_form(q: [f64; 2], u: [f64; 2]) -> (Matrix2<f64>, Vector2<f64>) {
    let i1 = MU1 * L1.powi(3) / 3.0 + J1 * L1 + PM1 * A1 * A1;
    let s1 = MU1 * L1 * L1 / 2.0 + PM1 * A1;
    let m2 = MU2 * L2 + PM2;
    let s2 = MU2 * L2 * L2 / 2.0 + PM2 * L2;
    let i2 = MU2 * L2.powi(3) / 3.0 + J2 * L2 + PM2 * L2 * L2;
    let c2 = q[1].cos();
    let m12 = i2 + L1 * s2 * c2;
    let m = Matrix2::new(i1 + m2 * L1 * L1 + i2 + 2.0 * L1 * s2 * c2, m12, m12, i2);
    let h = L1 * s2 * q[1].sin();
    let (c1, c12) = (q[0].cos(), (q[0] + q[1]).cos());
    let rhs = Vector2::new(
        -G * ((s1 + m2 * L1) * c1 + s2 * c12) + 2.0 * h * u[0] * u[1] + h * u[1] * u[1],
        -G * s2 * c12 - h * u[0] * u[0],
    );
    (m, m.lu().solve(&rhs).unwrap())
}

#[test]
fn mass_matrix_and_accelerations_match_the_closed_form() {
    let cases = [
        ([0.3, -1.1], [0.7, -2.0]),
        ([-2.0, 2.5], [-1.5, 0.4]),
        ([1.0, 0.0], [0.0, 0.0]),
        ([2.9, -0.2], [3.0, 3.0]),
    ];
    for (q, u) in cases {
        let mut scene = ArmScene::new(links(), G);
        scene.q0 = q.to_vec();
        scene.u0 = u.to_vec();
        let arm = scene.arm().unwrap();
        let (m_exact, acc_exact) = closed_form(q, u);
        let m = arm.kinematics(&q).mass_matrix();
        for (a, b) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            assert!(
                (m[(a, b)] - m_exact[(a, b)]).abs() < 1e-12,
                "M[{a},{b}] = {} vs {}",
                m[(a, b)],
                m_exact[(a, b)]
            );
        }
        let mut g = BondGraph::new();
        scene.add_to(&mut g, "pend").unwrap();
        let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let x0 = eqs.initial_state();
        eqs.evaluate(0.0, &x0);
        for k in 0..2 {
            let udot = eqs.read(eqs.probe(&format!("pend_arm.udot[{k}]")).unwrap(), 0.0, &x0);
            assert!(
                (udot - acc_exact[k]).abs() < 1e-12,
                "q {q:?} u {u:?}: u̇{k} = {udot} vs {}",
                acc_exact[k]
            );
            let u_out = eqs.read(eqs.probe(&format!("pend_arm.u[{k}]")).unwrap(), 0.0, &x0);
            assert!((u_out - u[k]).abs() < 1e-13);
        }
        // and the momentum rate ṗ = e + E integrates to the same accelerations
        let mut dx = vec![0.0; x0.len()];
        eqs.rhs(0.0, &x0, &mut dx);
        assert!(
            (dx[2] - u[0]).abs() < 1e-13 && (dx[3] - u[1]).abs() < 1e-13,
            "q̇ = u"
        );
    }
}
