//! Non-uniform links (`Link::with_profile`: EI(x), ρA(x), ρI(x) sampled along the chord):
//!
//! * a uniform link given as a profile equals the uniform link (its sine modes integrated in
//!   closed form) to 1e-12: shape integrals, shortening integrals, M, E, G and K of a
//!   two-link arm at random configurations;
//! * a tapered cantilever (EI and ρA falling linearly to 40 % at the tip), eight uniform
//!   cantilever modes as a Ritz basis, joint held: its first two bending frequencies, from
//!   the eigenvalues of the bond graph's exact Jacobian, against a fine finite-element model
//!   computed here (40 Hermite-cubic elements, 80 for its convergence, with the exact linear EI and ρA).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_manipulator::{ArmScene, Link, PlanarArm, Profile};
use bondgraph::{assign_causality, modes, BondGraph, DMatrix, StateEquations};

fn uniform_pair() -> (PlanarArm, PlanarArm) {
    let (ei, rho_a, rho_i) = (210e9 * 5.89e-4, 7850.0 * 0.0264, 7850.0 * 5.89e-4);
    let beam = |l: f64, profile: bool| {
        let b = Link::rigid(l, rho_a)
            .unwrap()
            .with_rotary_inertia(rho_i)
            .unwrap()
            .with_bending_stiffness(ei)
            .unwrap();
        let b = if profile {
            b.with_profile(Profile {
                bending_stiffness: Some(vec![ei, ei]),
                mass_per_length: Some(vec![rho_a; 5]),
                rotary_inertia_per_length: Some(vec![rho_i; 3]),
            })
            .unwrap()
        } else {
            b
        };
        b.with_sine_modes(3)
            .unwrap()
            .with_geometric_stiffening(true)
    };
    let arm = |p: bool| {
        PlanarArm::new(
            vec![
                beam(10.0, p),
                beam(8.0, p),
                Link::pendulum(6.0, 5000.0).unwrap(),
            ],
            9.81,
        )
        .unwrap()
    };
    (arm(false), arm(true))
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).abs().max() / b.abs().max()
}

#[test]
fn a_uniform_profile_equals_the_uniform_link() {
    let (uniform, profiled) = uniform_pair();
    let mut worst: f64 = 0.0;
    for i in 0..2 {
        let (a, b) = (uniform.shape_integrals(i), profiled.shape_integrals(i));
        worst = worst
            .max(rel(a.translation(), b.translation()))
            .max(rel(a.rotation(), b.rotation()))
            .max(rel(a.bending(), b.bending()));
        let (sa, sb) = (a.shortening().unwrap(), b.shortening().unwrap());
        worst = worst
            .max(rel(sa.chord(), sb.chord()))
            .max(rel(sa.mass(), sb.mass()))
            .max(rel(sa.moment(), sb.moment()));
    }
    let q = [0.3, -2.0, 0.5, 0.1, -0.05, 0.02, 0.08, 0.03, -0.01];
    let u = [0.2, -0.4, 0.9, 1.0, -2.0, 0.5, 0.3, 0.7, -0.2];
    let (ka, kb) = (uniform.kinematics(&q), profiled.kinematics(&q));
    let col = |v: nalgebra::DVector<f64>| DMatrix::from_column_slice(v.len(), 1, v.as_slice());
    worst = worst
        .max(rel(&ka.mass_matrix(), &kb.mass_matrix()))
        .max(rel(
            &col(ka.kinetic_forces(&u)),
            &col(kb.kinetic_forces(&u)),
        ))
        .max(rel(&col(ka.gravity_forces()), &col(kb.gravity_forces())))
        .max(rel(
            &uniform.stiffness_matrix(),
            &profiled.stiffness_matrix(),
        ));
    eprintln!("uniform profile vs uniform link: worst relative difference {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    assert!((uniform.mass() - profiled.mass()).abs() < 1e-12 * uniform.mass());
}

const L: f64 = 10.0;
const EI0: f64 = 2.0e7;
const RHO_A0: f64 = 150.0;
const TIP: f64 = 0.4;

fn ei(x: f64) -> f64 {
    EI0 * (1.0 - (1.0 - TIP) * x / L)
}
fn rho_a(x: f64) -> f64 {
    RHO_A0 * (1.0 - (1.0 - TIP) * x / L)
}

/// The first two frequencies of the tapered cantilever by finite elements: `n` Hermite
/// cubics, element matrices by 4-point Gauss–Legendre (exact for the linear EI and ρA).
fn finite_elements(n: usize) -> [f64; 2] {
    let dofs = 2 * n; // node 0 clamped
    let (mut k, mut m): (DMatrix<f64>, DMatrix<f64>) =
        (DMatrix::zeros(dofs, dofs), DMatrix::zeros(dofs, dofs));
    let h = L / n as f64;
    let rule = bg_manipulator::GaussLegendre::new(4).unwrap();
    for e in 0..n {
        let x0 = e as f64 * h;
        let (mut ke, mut me) = ([[0.0; 4]; 4], [[0.0; 4]; 4]);
        for (y, w) in rule.on(h) {
            let s = y / h;
            let n_ = [
                1.0 - 3.0 * s * s + 2.0 * s * s * s,
                h * (s - 2.0 * s * s + s * s * s),
                3.0 * s * s - 2.0 * s * s * s,
                h * (-s * s + s * s * s),
            ];
            let b = [
                (-6.0 + 12.0 * s) / (h * h),
                (-4.0 + 6.0 * s) / h,
                (6.0 - 12.0 * s) / (h * h),
                (-2.0 + 6.0 * s) / h,
            ];
            for a in 0..4 {
                for c in 0..4 {
                    ke[a][c] += w * ei(x0 + y) * b[a] * b[c];
                    me[a][c] += w * rho_a(x0 + y) * n_[a] * n_[c];
                }
            }
        }
        for a in 0..4 {
            for c in 0..4 {
                let (ga, gc) = (2 * e + a, 2 * e + c);
                if ga >= 2 && gc >= 2 {
                    k[(ga - 2, gc - 2)] += ke[a][c];
                    m[(ga - 2, gc - 2)] += me[a][c];
                }
            }
        }
    }
    let chol = m.cholesky().unwrap();
    let linv: DMatrix<f64> = chol.l().try_inverse().unwrap();
    let a: DMatrix<f64> = &linv * &k * linv.transpose();
    let mut w: Vec<f64> = a
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .map(|l| l.sqrt())
        .collect();
    w.sort_by(f64::total_cmp);
    [w[0], w[1]]
}

#[test]
fn a_tapered_cantilever_matches_finite_elements() {
    let link = Link::rigid(L, RHO_A0)
        .unwrap()
        .with_bending_stiffness(EI0)
        .unwrap()
        .with_profile(Profile {
            bending_stiffness: Some(vec![EI0, TIP * EI0]),
            mass_per_length: Some(vec![RHO_A0, TIP * RHO_A0]),
            rotary_inertia_per_length: None,
        })
        .unwrap()
        .with_cantilever_modes(8)
        .unwrap();
    let mut scene = ArmScene::new(vec![link], 0.0);
    scene.damping = vec![1e12]; // the root held: clamped
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "taper").unwrap();
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let x0 = eqs.initial_state();
    let mut w: Vec<f64> = modes(&eqs, 0.0, &x0)
        .unwrap()
        .iter()
        .filter(|m| m.eigenvalue.im > 1e-3)
        .map(|m| m.eigenvalue.im)
        .collect();
    w.sort_by(f64::total_cmp);
    let fe = finite_elements(40);
    let fine = finite_elements(80);
    let uniform = 1.875_104_068_711_961_f64.powi(2) * (EI0 / (RHO_A0 * L.powi(4))).sqrt();
    for k in 0..2 {
        let err = w[k] / fe[k] - 1.0;
        eprintln!(
            "tapered cantilever ω{}: {:.6} rad/s, FE (40 elements) {:.6} (rel. {err:+.1e}; 80 elements {:.6})",
            k + 1,
            w[k],
            fe[k],
            fine[k],
        );
        assert!(
            (fe[k] / fine[k] - 1.0).abs() < 1e-6,
            "the FE reference converged"
        );
        assert!(err.abs() < 1e-3, "ω{}: {} vs {}", k + 1, w[k], fe[k]);
    }
    // the taper moves the first frequency well away from the uniform beam's (12.84 rad/s)
    assert!((w[0] / uniform - 1.0).abs() > 0.05);
}
