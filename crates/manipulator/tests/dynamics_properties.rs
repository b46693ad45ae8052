//! Properties of M, E, Ṁu, G and K at random configurations of the flexible knuckle boom:
//! M symmetric positive definite, E = ∂T/∂q and G = −∂V_g/∂q against central differences,
//! Ṁu against differences of M along u, K against the closed form, and the convergence of
//! the per-station quadrature to the closed-form shape integrals at deformed configurations.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bg_manipulator::reference::StationKinematics;
use bg_manipulator::PlanarArm;
use common::{crane, crane_links, Rng, G};
use nalgebra::DVector;

/// Central difference of `f` along coordinate k, with step h.
fn central(q: &[f64], k: usize, h: f64, f: impl Fn(&[f64]) -> f64) -> f64 {
    let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
    qp[k] += h;
    qm[k] -= h;
    (f(&qp) - f(&qm)) / (2.0 * h)
}

#[test]
fn mass_matrix_is_symmetric_positive_definite_at_random_configurations() {
    let arm = crane(3);
    let mut rng = Rng::new(7);
    for _ in 0..20 {
        let q = rng.q(&arm, 0.3);
        let m = arm.kinematics(&q).mass_matrix();
        let asym = (&m - m.transpose()).abs().max();
        assert!(asym <= 1e-12 * m.abs().max(), "asymmetry {asym}");
        let eig = m.clone().symmetric_eigen().eigenvalues;
        assert!(eig.min() > 0.0, "eigenvalues {eig}");
    }
}

#[test]
fn e_matches_central_differences_of_kinetic_energy() {
    let arm = crane(3);
    let mut rng = Rng::new(11);
    for _ in 0..10 {
        let q = rng.q(&arm, 0.3);
        let u = rng.vec(arm.n(), 1.0);
        let e = arm.kinematics(&q).kinetic_forces(&u);
        let t = |q: &[f64]| arm.kinematics(q).kinetic_energy(&u);
        let scale = e.abs().max().max(1.0);
        for k in 0..arm.n() {
            let fd = central(&q, k, 1e-6, t);
            assert!(
                (fd - e[k]).abs() < 1e-6 * scale,
                "E[{k}] = {} vs {fd}",
                e[k]
            );
        }
        assert!(e[0].abs() < 1e-9 * scale, "T does not depend on q1");
    }
}

#[test]
fn mdot_u_matches_differences_of_m_along_u() {
    let arm = crane(3);
    let mut rng = Rng::new(5);
    for _ in 0..10 {
        let q = rng.q(&arm, 0.3);
        let u = rng.vec(arm.n(), 1.0);
        let (_, mdot_u) = arm.kinematics(&q).kinetic_terms(&u);
        let h = 1e-6;
        let shifted = |s: f64| -> Vec<f64> { q.iter().zip(&u).map(|(a, b)| a + s * b).collect() };
        let (qp, qm) = (shifted(h), shifted(-h));
        let dm =
            (arm.kinematics(&qp).mass_matrix() - arm.kinematics(&qm).mass_matrix()) / (2.0 * h);
        let fd = dm * DVector::from_column_slice(&u);
        let scale = fd.abs().max().max(1.0);
        assert!((fd - &mdot_u).abs().max() < 1e-6 * scale, "Ṁu {mdot_u}");
    }
}

#[test]
fn gravity_is_minus_the_gradient_of_the_potential() {
    let arm = crane(3);
    let mut rng = Rng::new(3);
    for _ in 0..10 {
        let q = rng.q(&arm, 0.3);
        let g = arm.kinematics(&q).gravity_forces();
        let scale = g.abs().max();
        for k in 0..arm.n() {
            let fd = central(&q, k, 1e-6, |q| arm.kinematics(q).gravity_potential());
            assert!(
                (fd + g[k]).abs() < 1e-6 * scale,
                "G[{k}] = {} vs {}",
                g[k],
                -fd
            );
        }
    }
    // at the initial pose the whole weight acts: Σ_i m_i g along −y
    let q = common::initial_pose(6);
    let kin = arm.kinematics(&q);
    let w: f64 = arm.mass() * G;
    let v = kin.gravity_potential();
    assert!(v < 0.0 && v > -w * 10.0);
}

#[test]
fn stiffness_of_sine_modes_is_ei_k_pi_over_l_to_the_fourth_l_over_2() {
    let arm = crane(3);
    let k = arm.stiffness_matrix();
    let ei = 210e9 * 5.89e-4;
    for (link, l, o) in [(0, 10.0, 3), (1, 8.0, 6)] {
        for a in 0..3 {
            for b in 0..3 {
                let kk = f64::from(a as u32 + 1) * std::f64::consts::PI / l;
                let want = if a == b {
                    ei * kk.powi(4) * l / 2.0
                } else {
                    0.0
                };
                let got = k[(o + a, o + b)];
                assert!(
                    (got - want).abs() < 1e-12 * ei,
                    "link {link} K[{a},{b}] = {got} vs {want}"
                );
            }
        }
    }
    assert!(k.rows(0, 3).abs().max() == 0.0);
}

#[test]
fn quadrature_of_m_converges_to_the_closed_form_at_deformed_configurations() {
    // With deformed positions the integrand is not polynomial: the per-station reference
    // with 4, 8, 12 and 16 points per link against the closed-form shape integrals.
    let mut rng = Rng::new(19);
    let exact = crane(3);
    let q = rng.q(&exact, 0.3);
    let m_ref = exact.kinematics(&q).mass_matrix();
    let scale = m_ref.abs().max();
    let mut errors = Vec::new();
    for n in [4, 8, 12, 16] {
        let arm = PlanarArm::with_quadrature(crane_links(3), G, n).unwrap();
        let m = StationKinematics::new(&arm, &q).mass_matrix();
        errors.push((m - &m_ref).abs().max() / scale);
    }
    eprintln!("relative error of M with 4, 8, 12, 16 points: {errors:?}");
    assert!(errors[0] > 1e-8, "4 points should not be exact: {errors:?}");
    assert!(errors[3] < 1e-14, "16 points: {errors:?}");
    assert!(errors.windows(2).all(|w| w[1] <= w[0].max(1e-15)));
}
