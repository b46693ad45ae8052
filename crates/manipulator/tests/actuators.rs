//! Linear actuators and lumped masses: the scene's geometry and static figures,
//! τ_b = ∂l/∂q and J_c against finite differences, and power conservation of both MTFs.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, LumpedMassModel, PlanarArm};
use bondgraph::{assign_causality, BondGraph, EffortSource, StateEquations};
use common::{crane, crane_links, cylinders, initial_pose, lumped_masses, static_forces, Rng, G};

fn rigid_crane_with_lumped_masses() -> PlanarArm {
    let mut scene = ArmScene::new(crane_links(0), G);
    scene.lumped_masses = lumped_masses();
    scene.lumped_model = LumpedMassModel::Rigid;
    scene.arm().unwrap()
}

#[test]
fn cylinder_lengths_are_sqrt_13_in_the_initial_pose() {
    let arm = crane(3);
    let q = initial_pose(6);
    let pose = arm.pose(&q);
    for c in cylinders() {
        assert!((c.length(&pose) - 13f64.sqrt()).abs() < 1e-12);
    }
}

#[test]
fn tau_b_and_j_c_match_finite_differences() {
    let arm = crane(3);
    let acts = cylinders();
    let pins: Vec<_> = lumped_masses().iter().map(|m| m.pin).collect();
    let mut rng = Rng::new(23);
    for _ in 0..10 {
        let mut q = rng.q(&arm, 0.3);
        q[0] = rng.uniform(-0.3, 1.2); // keep the pins of cylinder 1 apart
        let pose = arm.pose(&q);
        let tau = arm.actuator_jacobian(&pose, &acts);
        let jc = arm.lumped_mass_jacobian(&pose, &pins);
        for k in 0..arm.n() {
            let h = 1e-6;
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[k] += h;
            qm[k] -= h;
            let (pp, pm) = (arm.pose(&qp), arm.pose(&qm));
            for (c, a) in acts.iter().enumerate() {
                let fd = (a.length(&pp) - a.length(&pm)) / (2.0 * h);
                assert!(
                    (fd - tau[(k, c)]).abs() < 1e-7,
                    "τ_b[{k},{c}] = {} vs {fd}",
                    tau[(k, c)]
                );
            }
            for (m, pin) in pins.iter().enumerate() {
                let fd = (pp.pin_position(pin) - pm.pin_position(pin)) / (2.0 * h);
                assert!(
                    (fd.x - jc[(2 * m, k)]).abs() < 1e-7
                        && (fd.y - jc[(2 * m + 1, k)]).abs() < 1e-7
                );
            }
        }
    }
}

#[test]
fn both_mtfs_conserve_power_at_random_states() {
    let mut scene = ArmScene::new(crane_links(3), G);
    scene.actuators = cylinders();
    scene.lumped_masses = lumped_masses();
    scene.lumped_model = LumpedMassModel::Springs {
        stiffness: 1e8,
        damping: 2e5,
    };
    let mut g = BondGraph::new();
    let ports = scene.add_to(&mut g, "crane").unwrap();
    for (k, f) in [2.1e5, -8.0e4].iter().enumerate() {
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
    let mut rng = Rng::new(31);
    for _ in 0..10 {
        let x: Vec<f64> = eqs
            .states()
            .iter()
            .map(|s| {
                if s.name.starts_with("crane_arm.q[") {
                    let k: usize = s.name[12..s.name.len() - 1].parse().unwrap();
                    if k < 3 {
                        initial_pose(0)[k] + rng.uniform(-0.3, 0.3)
                    } else {
                        rng.uniform(-0.05, 0.05)
                    }
                } else {
                    s.nominal * rng.uniform(-1.0, 1.0)
                }
            })
            .collect();
        eqs.evaluate(0.0, &x);
        for name in ["crane_act1", "crane_act2", "crane_lump"] {
            let id = eqs.graph().find(name).unwrap();
            let (p, scale) = (eqs.power_into(id), eqs.power_scale(id));
            assert!(scale > 1.0, "{name} carries power");
            assert!(p.abs() <= 1e-12 * scale, "{name}: net power {p} of {scale}");
        }
        // the length rate published is τ_bᵀ u, the flow on the cylinder bond
        let ldot = eqs.read(eqs.probe("crane_act1.ldot1").unwrap(), 0.0, &x);
        let f = eqs.read(eqs.probe("crane_act1.2.f").unwrap(), 0.0, &x);
        assert!((ldot - f).abs() <= 1e-12 * ldot.abs().max(1.0));
    }
}

#[test]
fn static_cylinder_forces_of_the_rigid_crane_in_the_initial_pose() {
    // Design page: "about +207 kN and −80.6 kN" (first two rows of τ_b F + G = 0, lumped
    // masses included).
    let arm = rigid_crane_with_lumped_masses();
    let [f1, f2] = static_forces(&arm, &initial_pose(0));
    eprintln!("initial pose: F1 = {:.1} N, F2 = {:.1} N", f1, f2);
    assert!((f1 / 207e3 - 1.0).abs() < 1e-3, "F1 = {f1}");
    assert!((f2 / -80.6e3 - 1.0).abs() < 1e-3, "F2 = {f2}");
}

#[test]
fn final_pose_for_six_metre_cylinders() {
    // Design page: q1 ≈ 57.28°, q2 ≈ −62.72°, payload near x = 13.37 m, F_c1 ≈ 512 kN,
    // F_c2 ≈ 260 kN.
    let arm = rigid_crane_with_lumped_masses();
    let acts = cylinders();
    let length = |q: &[f64], c: usize| acts[c].length(&arm.pose(q));
    let mut q = vec![0.5, -1.0, 0.0];
    for _ in 0..50 {
        // Newton on q1 for l1 = 6 (l1 does not depend on q2), then on q2 for l2 = 6.
        for (c, k) in [(0, 0), (1, 1)] {
            let h = 1e-7;
            let mut qp = q.clone();
            qp[k] += h;
            let d = (length(&qp, c) - length(&q, c)) / h;
            q[k] -= (length(&q, c) - 6.0) / d;
        }
    }
    q[2] = -PI / 2.0 - q[0] - q[1]; // the pendulum hangs straight down
    let (q1, q2) = (q[0].to_degrees(), q[1].to_degrees());
    let x = arm.pose(&q).origin(3).x;
    let [f1, f2] = static_forces(&arm, &q);
    eprintln!("final pose: q1 = {q1:.3}°, q2 = {q2:.3}°, payload x = {x:.3} m, F1 = {f1:.0} N, F2 = {f2:.0} N");
    assert!((q1 - 57.28).abs() < 0.01 && (q2 + 62.72).abs() < 0.01);
    assert!((x - 13.37).abs() < 0.01);
    assert!((f1 / 512e3 - 1.0).abs() < 1e-3 && (f2 / 260e3 - 1.0).abs() < 1e-3);
}
