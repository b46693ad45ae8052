//! Reaction forces in the passive joints (section 5), in the scene's convention (docs/knuckle-boom.md):
//! ρ_{2j−1}, ρ_{2j} is the force that the inboard body exerts on link j through joint j, in
//! the axes of frame j.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, Link, LumpedMassModel};
use bondgraph::{assign_causality, BondGraph, EffortSource, StateEquations};
use common::{crane_links, cylinders, lumped_masses, newton, static_forces, G, M3};
use nalgebra::{DVector, Vector2};

/// Build the scene with constant cylinder forces; returns the equations and initial state.
fn build(scene: &ArmScene, forces: &[f64]) -> (StateEquations, Vec<f64>) {
    let mut g = BondGraph::new();
    let ports = scene.add_to(&mut g, "crane").unwrap();
    for (k, f) in forces.iter().enumerate() {
        let se = g
            .add(&format!("F{}", k + 1), EffortSource::new(*f))
            .unwrap();
        let (_, id, port) = ports
            .iter()
            .find(|p| p.0 == format!("cyl{}", k + 1))
            .unwrap()
            .clone();
        g.connect((se, None), (id, port)).unwrap();
    }
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let x0 = eqs.initial_state();
    (eqs, x0)
}

fn read(eqs: &StateEquations, x: &[f64], name: &str) -> f64 {
    eqs.read(
        eqs.probe(name).unwrap_or_else(|| panic!("no {name}")),
        0.0,
        x,
    )
}

#[test]
fn swinging_pendulums_match_the_closed_form() {
    let (m, l, theta, omega) = (5000.0, 6.0, -1.1, 0.8);
    // A point mass on a massless rod: ρ_x = −m L ω² + m g sin θ, ρ_y = 0.
    let mut scene = ArmScene::new(vec![Link::pendulum(l, m).unwrap()], G);
    scene.q0 = vec![theta];
    scene.u0 = vec![omega];
    let (eqs, x) = build(&scene, &[]);
    eqs.evaluate(0.0, &x);
    let want = -m * l * omega * omega + m * G * theta.sin();
    assert!((read(&eqs, &x, "crane_rho.rho1") - want).abs() < 1e-9 * want.abs());
    assert!(read(&eqs, &x, "crane_rho.rho2").abs() < 1e-9 * want.abs());
    // A uniform rod of mass m: θ̈ = −(3g/2L) cos θ, ρ_x = −m (L/2) ω² + m g sin θ,
    // ρ_y = m g cos θ / 4.
    let mut scene = ArmScene::new(vec![Link::rigid(l, m / l).unwrap()], G);
    scene.q0 = vec![theta];
    scene.u0 = vec![omega];
    let (eqs, x) = build(&scene, &[]);
    eqs.evaluate(0.0, &x);
    let (wx, wy) = (
        -m * l / 2.0 * omega * omega + m * G * theta.sin(),
        m * G * theta.cos() / 4.0,
    );
    let (rx, ry) = (
        read(&eqs, &x, "crane_rho.rho1"),
        read(&eqs, &x, "crane_rho.rho2"),
    );
    assert!(
        (rx - wx).abs() < 1e-9 * m * G && (ry - wy).abs() < 1e-9 * m * G,
        "({rx}, {ry}) vs ({wx}, {wy})"
    );
}

/// The flexible crane in static equilibrium with the pendulum hanging: cylinder forces and
/// modal deflections solved from rows 1, 2, 4..9 of G − Kq + τ_b F = 0.
fn flexible_equilibrium(q1: f64, q2: f64) -> (Vec<f64>, [f64; 2]) {
    let mut scene = ArmScene::new(crane_links(3), G);
    scene.lumped_masses = lumped_masses();
    scene.lumped_model = LumpedMassModel::Rigid;
    let arm = scene.arm().unwrap();
    let k = arm.stiffness_matrix();
    let q_of = |z: &[f64]| {
        let mut q = vec![q1, q2, -PI / 2.0 - q1 - q2];
        q.extend_from_slice(&z[2..]);
        q
    };
    let residual = |z: &[f64]| -> Vec<f64> {
        let q = q_of(z);
        let tau = arm.actuator_jacobian(&arm.pose(&q), &cylinders());
        let r = arm.kinematics(&q).gravity_forces() - &k * DVector::from_column_slice(&q)
            + tau * nalgebra::Vector2::new(z[0], z[1]);
        [0, 1, 3, 4, 5, 6, 7, 8].iter().map(|&i| r[i]).collect()
    };
    let f = static_forces(
        &arm,
        &[q1, q2, -PI / 2.0 - q1 - q2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    let mut z0 = vec![f[0], f[1]];
    z0.extend([0.0; 6]);
    let z = newton(
        z0,
        residual,
        &[1e5, 1e5, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2],
    );
    (q_of(&z), [z[0], z[1]])
}

#[test]
fn pendulum_hanging_at_rest_carries_its_weight() {
    let (q, f) = flexible_equilibrium(0.2, -2.0);
    eprintln!("equilibrium: F = {f:?}, w1 modal {:?}", &q[3..6]);
    for model in [
        LumpedMassModel::Rigid,
        LumpedMassModel::Springs {
            stiffness: 1e8,
            damping: 2e5,
        },
    ] {
        let mut scene = ArmScene::new(crane_links(3), G);
        scene.q0 = q.clone();
        scene.actuators = cylinders();
        scene.lumped_masses = lumped_masses();
        scene.lumped_model = model;
        scene.paper_reactions = true;
        let (eqs, mut x) = build(&scene, &f);
        if let LumpedMassModel::Springs { stiffness, .. } = model {
            // springs pre-loaded by the weights: k q_y = −m g
            for (m, lm) in lumped_masses().iter().enumerate() {
                let i = eqs
                    .states()
                    .iter()
                    .position(|s| s.name == format!("crane_spring.q[{}]", 2 * m + 1))
                    .unwrap();
                x[i] = -lm.mass * G / stiffness;
            }
        }
        eqs.evaluate(0.0, &x);
        let udot: Vec<f64> = (0..9)
            .map(|k| read(&eqs, &x, &format!("crane_arm.udot[{k}]")))
            .collect();
        assert!(udot.iter().all(|a| a.abs() < 1e-9), "at rest: u̇ = {udot:?}");
        let (r5, r6) = (
            read(&eqs, &x, "crane_rho.rho5"),
            read(&eqs, &x, "crane_rho.rho6"),
        );
        eprintln!("{model:?}: ρ5 = {r5}, ρ6 = {r6}");
        assert!((r5 / (-M3 * G) - 1.0).abs() < 1e-9, "ρ5 = {r5}");
        assert!(r6.abs() < 1e-9 * M3 * G, "ρ6 = {r6}");
        if matches!(model, LumpedMassModel::Springs { .. }) {
            for k in 1..=6 {
                let (a, b) = (
                    read(&eqs, &x, &format!("crane_rho.rho{k}")),
                    read(&eqs, &x, &format!("crane_rho.rho{k}_paper")),
                );
                assert!(
                    (a - b).abs() < 1e-9 * M3 * G,
                    "at rest the paper's variant agrees: ρ{k} {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn joint_reactions_of_a_static_rigid_pose_balance_gravity_and_the_cylinders() {
    let mut scene = ArmScene::new(crane_links(0), G);
    scene.actuators = cylinders();
    scene.lumped_masses = lumped_masses();
    scene.lumped_model = LumpedMassModel::Rigid;
    let (q1, q2) = (0.6, -1.3);
    scene.q0 = vec![q1, q2, -PI / 2.0 - q1 - q2];
    let arm = scene.arm().unwrap();
    let f = static_forces(&arm, &scene.q0);
    let (eqs, x) = build(&scene, &f);
    eqs.evaluate(0.0, &x);
    let rho = |j: usize| {
        // frame-j components to frame 0
        let phi: f64 = scene.q0[..=j].iter().sum();
        let r = Vector2::new(
            read(&eqs, &x, &format!("crane_rho.rho{}", 2 * j + 1)),
            read(&eqs, &x, &format!("crane_rho.rho{}", 2 * j + 2)),
        );
        Vector2::new(
            phi.cos() * r.x - phi.sin() * r.y,
            phi.sin() * r.x + phi.cos() * r.y,
        )
    };
    let pose = arm.pose(&scene.q0);
    let acts = cylinders();
    let weight = |m: f64| Vector2::new(0.0, -m * G);
    let links = crane_links(0);
    let (m1, m2) = (links[0].mass(), links[1].mass());
    let lumped: Vec<f64> = lumped_masses().iter().map(|m| m.mass).collect();
    // Joint 1 carries everything; cylinder 2 is internal to it.
    let all = weight(m1 + m2 + M3 + lumped.iter().sum::<f64>());
    let sum1 = rho(0) + all + f[0] * acts[0].direction(&pose);
    // Joint 2 carries link 2, the pendulum and piston 2; cylinder 2 pushes on H2,1.
    let sum2 = rho(1) + weight(m2 + M3 + lumped[2]) + f[1] * acts[1].direction(&pose);
    // The pivot carries the payload.
    let sum3 = rho(2) + weight(M3);
    let scale = all.norm();
    for (j, s) in [sum1, sum2, sum3].iter().enumerate() {
        assert!(s.norm() < 1e-9 * scale, "joint {}: residual {s}", j + 1);
    }
}
