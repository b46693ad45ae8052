//! Stress recovery against closed forms: the local equilibrium of the summed section forces
//! at arbitrary states, and a cantilever under a suddenly applied tip load.
#![allow(clippy::unwrap_used, clippy::many_single_char_names)]

use nalgebra::Vector2;

use super::SectionGrid;
use crate::mode_shape::{CantileverMode, ModeShape};
use crate::{Link, PlanarArm, PointMass};

/// Two beams (3 sine modes each, a point mass on the first) and a pendulum, like the crane.
fn crane_like() -> PlanarArm {
    let b1 = Link::beam(10.0, 210e9, 7850.0, 0.0264, 5.89e-4)
        .unwrap()
        .with_sine_modes(3)
        .unwrap()
        .with_point_mass(PointMass {
            x: 6.0,
            mass: 713.0,
            inertia: 3.0,
        })
        .unwrap();
    let b2 = Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4)
        .unwrap()
        .with_sine_modes(3)
        .unwrap();
    let p = Link::pendulum(6.0, 5000.0).unwrap();
    PlanarArm::new(vec![b1, b2, p], 9.81).unwrap()
}

/// A deterministic pseudo-random sequence in [−1, 1).
fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// dN/dx = −q_x, dV/dx = q_y, dM/dx = V + w'N − μ at random states, points and loads, by
/// central differences of the summed forces against the local load of the point
/// accelerations (`ArmKinematics::point_acceleration`).
#[test]
fn stress_summation_satisfies_the_local_equilibrium_at_random_states() {
    let arm = crane_like();
    let mut seed = 7;
    for _ in 0..5 {
        let q: Vec<f64> = (0..arm.n())
            .map(|k| {
                if k < 3 {
                    lcg(&mut seed)
                } else {
                    0.05 * lcg(&mut seed)
                }
            })
            .collect();
        let u: Vec<f64> = (0..arm.n()).map(|_| lcg(&mut seed)).collect();
        let ud: Vec<f64> = (0..arm.n()).map(|_| 3.0 * lcg(&mut seed)).collect();
        let kin = arm.kinematics(&q);
        let pins = [arm.station(0, 4.0).unwrap(), arm.station(1, 3.0).unwrap()];
        let f = [
            Vector2::new(1e5 * lcg(&mut seed), 2e5 * lcg(&mut seed)),
            Vector2::new(1e5 * lcg(&mut seed), 1e5 * lcg(&mut seed)),
        ];
        let loads: Vec<_> = pins.iter().zip(f).collect();
        let torques = [0.0, 0.0, 5000.0 * lcg(&mut seed)];
        for link in 0..2 {
            let len = arm.links()[link].length();
            let x0 = len * (0.5 + 0.45 * lcg(&mut seed));
            // keep away from the pin and point mass
            let x0 = if (x0 - 4.0).abs() < 0.1 || (x0 - 6.0).abs() < 0.1 || (x0 - 3.0).abs() < 0.1 {
                x0 + 0.3
            } else {
                x0
            };
            let h = 1e-3;
            let grid = SectionGrid::new(&arm, link, &[x0 - h, x0, x0 + h]).unwrap();
            let mut out = grid.forces();
            kin.section_forces_into(&grid, &u, &ud, &loads, &torques, &mut out);
            let d = |v: &[f64]| (v[2] - v[0]) / (2.0 * h);
            let (load, mu) = kin.distributed_load(link, x0, &u, &ud);
            let scale_f = out
                .n
                .iter()
                .chain(&out.v)
                .fold(0.0_f64, |a, b| a.max(b.abs()));
            let scale_m = out.m.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            let tol_f = 1e-6 * scale_f.max(1e3) / len;
            let tol_m = 1e-6 * scale_m.max(1e3) / len;
            assert!(
                (d(&out.n) + load.x).abs() < tol_f,
                "dN/dx {} vs {}",
                d(&out.n),
                -load.x
            );
            assert!(
                (d(&out.v) - load.y).abs() < tol_f,
                "dV/dx {} vs {}",
                d(&out.v),
                load.y
            );
            let rhs = out.v[1] + out.slope[1] * out.n[1] - mu;
            assert!(
                (d(&out.m) - rhs).abs() < tol_m,
                "dM/dx {} vs {rhs}",
                d(&out.m)
            );
        }
    }
}

/// At the far joint of a free hinge the summed moment is the joint torque, and at the base
/// joint (no torque) it vanishes: the joint rows of the equations of motion, whatever the
/// state, follow from the summation only if the accelerations are the model's — here they
/// are arbitrary, so only the far end is checked (it is an input of the summation).
#[test]
fn stress_far_end_moment_is_the_joint_torque() {
    let arm = crane_like();
    let q = [0.3, -1.0, 0.6, 0.01, -0.002, 0.001, 0.02, 0.0, -0.003];
    let u = [0.1, -0.2, 0.3, 0.0, 0.1, 0.0, 0.0, 0.0, 0.2];
    let ud = [0.5, 0.1, -0.3, 1.0, 0.0, 2.0, 0.0, -1.0, 0.0];
    let kin = arm.kinematics(&q);
    let grid = SectionGrid::new(&arm, 1, &[0.0, 8.0]).unwrap();
    let mut out = grid.forces();
    kin.section_forces_into(&grid, &u, &ud, &[], &[0.0, 0.0, 1234.5], &mut out);
    // the joint torque τ acts +τ on the pendulum, −τ on link 2: M_cut(L) = −τ
    assert!((out.m[1] + 1234.5).abs() < 1e-9, "{}", out.m[1]);
}

/// A cantilever (the arm's equivalent: a single beam with cantilever modes, its joint held,
/// no gravity) under a tip load P applied at t = 0, undamped, one mode: the modal response is
/// a single-degree-of-freedom step response, `q(t) = q_s (1 − cos ωt)`, so the modal root
/// moment reaches exactly 2× its static value at t = π/ω; the summed root moment reaches
/// `−PL (1 + r)`, `r = ψ(L) (∫ρAψx + ρI ψ(L)) / (L M_bb)`, closed form from the mode shape.
/// The equations are integrated by RK4 with the arm's own mass and stiffness matrices.
#[test]
fn stress_cantilever_step_load_dynamic_amplification() {
    let (len, e, rho, a, i) = (8.0, 210e9, 7850.0, 0.0264, 5.89e-4);
    let link = Link::beam(len, e, rho, a, i)
        .unwrap()
        .with_cantilever_modes(1)
        .unwrap();
    let arm = PlanarArm::new(vec![link], 0.0).unwrap();
    let p = 1.0e4;
    let tip = arm.station(0, len).unwrap();
    let q0 = [0.0, 0.0];
    let m = arm.kinematics(&q0).mass_matrix();
    let k = arm.stiffness_matrix();
    let (mbb, kbb) = (m[(1, 1)], k[(1, 1)]);
    // independent shape integrals by a fine composite Simpson rule
    let mode = CantileverMode::new(1, len);
    let simpson = |f: &dyn Fn(f64) -> f64| {
        let n = 20_000;
        let h = len / n as f64;
        (0..=n)
            .map(|j| {
                let w = if j == 0 || j == n {
                    1.0
                } else if j % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * f(j as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0
    };
    let m_ref = simpson(&|x| rho * a * mode.value(x).powi(2) + rho * i * mode.slope(x).powi(2));
    let k_ref = simpson(&|x| e * i * mode.curvature(x).powi(2));
    assert!((mbb - m_ref).abs() < 1e-9 * m_ref, "{mbb} vs {m_ref}");
    assert!((kbb - k_ref).abs() < 1e-7 * k_ref, "{kbb} vs {k_ref}");
    let s = simpson(&|x| rho * a * mode.value(x) * x);
    let psi_l = mode.value(len);
    let omega = (kbb / mbb).sqrt();
    let q_static = -p * psi_l / kbb;
    let m_modal_static = e * i * mode.curvature(0.0) * q_static;
    let r = psi_l * (s + rho * i * psi_l) / (len * mbb);
    // RK4 on M_bb q̈ + K q = ψ(L)(−P), landing on t = π/ω
    let steps = 1000;
    let dt = std::f64::consts::PI / omega / steps as f64;
    let acc = |q: f64| (-p * psi_l - kbb * q) / mbb;
    let (mut q, mut v) = (0.0, 0.0);
    let grid = SectionGrid::new(&arm, 0, &[0.0]).unwrap();
    let mut out = grid.forces();
    let (mut peak_modal, mut peak_sum) = (0.0_f64, 0.0_f64);
    let load = Vector2::new(0.0, -p);
    for step in 0..=(3 * steps / 2) {
        let qs = [0.0, q];
        let kin = arm.kinematics(&qs);
        kin.section_forces_into(
            &grid,
            &[0.0, v],
            &[0.0, acc(q)],
            &[(&tip, load)],
            &[],
            &mut out,
        );
        peak_modal = peak_modal.max(out.m_modal[0].abs());
        peak_sum = peak_sum.max(out.m[0].abs());
        if step == 0 {
            // at t = 0 the beam is undeformed and at rest: the inertia takes the load, but the
            // free body beyond the root still carries −PL less the inertial moment
            assert!(out.m_modal[0].abs() < 1e-12);
        }
        let (k1q, k1v) = (v, acc(q));
        let (k2q, k2v) = (v + 0.5 * dt * k1v, acc(q + 0.5 * dt * k1q));
        let (k3q, k3v) = (v + 0.5 * dt * k2v, acc(q + 0.5 * dt * k2q));
        let (k4q, k4v) = (v + dt * k3v, acc(q + dt * k3q));
        q += dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
        v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    let amp_modal = peak_modal / m_modal_static.abs();
    let amp_sum = peak_sum / (p * len);
    eprintln!(
        "cantilever, 1 mode: modal root moment ×{amp_modal:.9} of static (closed form 2), summed ×{amp_sum:.9} of PL (closed form 1 + r = {:.9}); static modal/PL = {:.6}",
        1.0 + r,
        m_modal_static.abs() / (p * len)
    );
    assert!((amp_modal - 2.0).abs() < 1e-6, "{amp_modal}");
    assert!(
        (amp_sum - (1.0 + r)).abs() < 1e-6,
        "{amp_sum} vs {}",
        1.0 + r
    );
}
