//! Geometric stiffening (`src/geometric_stiffening.rs`) on the flexible knuckle boom: the
//! shortening of the chords and of the pins in closed form, and every derivative the
//! elements use (E, Ṁu, G, B, H, ∂²V_g, the Jacobian and Hessian of a point and of an
//! actuator's length) against central differences of what it differentiates. The checks are
//! made on the *change* that stiffening brings (stiffened minus plain arm), so a missing or
//! wrong stiffening term cannot hide behind the large terms of the paper's beam.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::f64::consts::PI;

use bg_manipulator::{Link, Pin, PlanarArm};
use common::{crane_links, cylinders, Rng, G};
use nalgebra::{DMatrix, DVector, Vector2};

const H: f64 = 1e-6;

fn arms() -> (PlanarArm, PlanarArm) {
    let stiff = crane_links(3)
        .into_iter()
        .map(|l| l.with_geometric_stiffening(true))
        .collect();
    (
        PlanarArm::new(crane_links(3), G).unwrap(),
        PlanarArm::new(stiff, G).unwrap(),
    )
}

/// Central differences of a vector function: column k = ∂f/∂x_k.
fn jacobian_fd(x: &[f64], f: impl Fn(&[f64]) -> DVector<f64>) -> DMatrix<f64> {
    let n = x.len();
    let m = f(x).len();
    let mut j = DMatrix::zeros(m, n);
    for k in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        let h = H * x[k].abs().max(1.0);
        xp[k] += h;
        xm[k] -= h;
        j.set_column(k, &((f(&xp) - f(&xm)) / (2.0 * h)));
    }
    j
}

/// `got` (stiffened − plain, analytic) against `want` (the same difference, by central
/// differences), relative to the size of the change.
fn assert_change(name: &str, got: &DMatrix<f64>, want: &DMatrix<f64>) {
    let size = want.abs().max();
    assert!(size > 0.0, "{name}: stiffening changes nothing");
    let err = (got - want).abs().max() / size;
    assert!(err < 1e-5, "{name}: relative error {err:e}\n{got}\n{want}");
}

fn states(seed: u64, arm: &PlanarArm) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(seed);
    let _ = rng.vec(16, 1.0);
    (0..4)
        .map(|_| (rng.q(arm, 0.3), rng.vec(arm.n(), 1.0)))
        .collect()
}

#[test]
fn the_chord_shortens_by_a_quarter_of_q_squared_kappa_squared_l() {
    // one sine mode: s = −½ q² ∫ψ'² = −q²κ²L/4
    let l = 10.0;
    let link = Link::beam(l, 210e9, 7850.0, 0.0264, 5.89e-4)
        .unwrap()
        .with_sine_modes(1)
        .unwrap()
        .with_geometric_stiffening(true);
    let arm = PlanarArm::new(vec![link, Link::pendulum(6.0, 5000.0).unwrap()], G).unwrap();
    let q = [0.3, -1.0, 0.25];
    let pose = arm.pose(&q);
    let kappa = PI / l;
    let s = -q[2] * q[2] * kappa * kappa * l / 4.0;
    let want = (l + s) * Vector2::new(q[0].cos(), q[0].sin());
    assert!(
        (pose.pivot(1) - want).norm() < 1e-14 * l,
        "{}",
        pose.pivot(1)
    );
    // the paper's joint stays where it was
    assert!((pose.origin(1) - l * Vector2::new(q[0].cos(), q[0].sin())).norm() < 1e-14 * l);
    // a pin at the end of the chord sits on the next joint; one at mid-span moves by u(L/2)
    let end = arm.station(0, l).unwrap();
    assert!((pose.position(&end) - pose.pivot(1)).norm() < 1e-13);
    let mid = arm.station(0, l / 2.0).unwrap();
    let u_mid = -0.5 * q[2] * q[2] * kappa * kappa * (l / 4.0); // ∫₀^{L/2} cos² = L/4
    assert!(
        (pose.axial_shortening(&mid) - u_mid).abs() < 1e-14,
        "{u_mid}"
    );
    // the payload hangs from the shifted joint
    let payload = arm.station(1, 6.0).unwrap();
    let want = pose.pivot(1) + 6.0 * Vector2::new((q[0] + q[1]).cos(), (q[0] + q[1]).sin());
    assert!((pose.position(&payload) - want).norm() < 1e-13);
}

#[test]
fn mass_matrix_stays_symmetric_positive_definite() {
    // (modal coordinates up to 5 cm: the energy is truncated at second order, so M is
    // positive definite for deflections small against the links, not at any deflection)
    let (_, arm) = arms();
    let mut rng = Rng::new(3);
    for q in (0..4).map(|_| rng.q(&arm, 0.05)) {
        let m = arm.kinematics(&q).mass_matrix();
        assert!((&m - m.transpose()).abs().max() <= 1e-12 * m.abs().max());
        assert!(m.symmetric_eigen().eigenvalues.min() > 0.0);
    }
}

#[test]
fn e_mdot_u_and_g_are_derivatives_of_t_m_and_v_g() {
    let (plain, stiff) = arms();
    for (q, u) in states(7, &stiff) {
        let uv = DVector::from_column_slice(&u);
        let change = |f: &dyn Fn(&PlanarArm) -> DVector<f64>| f(&stiff) - f(&plain);
        let col = |v: DVector<f64>| DMatrix::from_column_slice(v.len(), 1, v.as_slice());
        // E = ∂T/∂q
        let e = change(&|a| a.kinematics(&q).kinetic_forces(&u));
        let fd = change(&|a| {
            jacobian_fd(&q, |q| {
                DVector::from_element(1, a.kinematics(q).kinetic_energy(&u))
            })
            .transpose()
            .column(0)
            .into_owned()
        });
        assert_change("E = ∂T/∂q", &col(e), &col(fd));
        // T = ½uᵀMu
        for a in [&plain, &stiff] {
            let k = a.kinematics(&q);
            let t = 0.5 * uv.dot(&(k.mass_matrix() * &uv));
            assert!((t - k.kinetic_energy(&u)).abs() < 1e-12 * t.abs().max(1.0));
        }
        // Ṁu
        let mdot = change(&|a| a.kinematics(&q).kinetic_terms(&u).1);
        let fd = change(&|a| {
            let shifted =
                |s: f64| -> Vec<f64> { q.iter().zip(&u).map(|(x, v)| x + s * v).collect() };
            let (qp, qm) = (shifted(H), shifted(-H));
            let (mp, mm) = (
                a.kinematics(&qp).mass_matrix(),
                a.kinematics(&qm).mass_matrix(),
            );
            (mp - mm) / (2.0 * H) * &uv
        });
        assert_change("Ṁu", &col(mdot), &col(fd));
        // G = −∂V_g/∂q
        let g = change(&|a| a.kinematics(&q).gravity_forces());
        let fd = change(&|a| {
            -jacobian_fd(&q, |q| {
                DVector::from_element(1, a.kinematics(q).gravity_potential())
            })
            .transpose()
            .column(0)
            .into_owned()
        });
        assert_change("G = −∂V_g/∂q", &col(g), &col(fd));
    }
}

#[test]
fn b_h_and_the_gravity_hessian_match_differences() {
    let (plain, stiff) = arms();
    let n = stiff.n();
    for (q, u) in states(23, &stiff) {
        let uv = DVector::from_column_slice(&u);
        let partials = |a: &PlanarArm| {
            let (mut b, mut h, mut hg) = (
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
                DMatrix::zeros(n, n),
            );
            a.kinematics(&q).kinetic_partials_into(&u, &mut b, &mut h);
            a.kinematics(&q).gravity_hessian_into(&mut hg);
            (b, h, hg)
        };
        let ((b0, h0, g0), (b1, h1, g1)) = (partials(&plain), partials(&stiff));
        let fd = |a: &PlanarArm| {
            (
                jacobian_fd(&q, |q| a.kinematics(q).mass_matrix() * &uv),
                jacobian_fd(&q, |q| a.kinematics(q).kinetic_forces(&u)),
                jacobian_fd(&q, |q| -a.kinematics(q).gravity_forces()),
                jacobian_fd(&u, |u| a.kinematics(&q).kinetic_forces(u)),
            )
        };
        let ((mb0, me0, mg0, eu0), (mb1, me1, mg1, eu1)) = (fd(&plain), fd(&stiff));
        assert_change("B = ∂(Mu)/∂q", &(&b1 - &b0), &(mb1 - mb0));
        assert_change("H = ∂E/∂q", &(&h1 - &h0), &(me1 - me0));
        assert_change("Bᵀ = ∂E/∂u", &(b1 - b0).transpose(), &(eu1 - eu0));
        assert_change("∂²V_g/∂q²", &(g1 - g0), &(mg1 - mg0));
        assert!((&h1 - h1.transpose()).abs().max() <= 1e-12 * h1.abs().max());
    }
}

#[test]
fn points_and_actuators_move_with_the_shortening_and_their_derivatives_match() {
    let (plain, stiff) = arms();
    let n = stiff.n();
    for (q, _) in states(31, &stiff) {
        // the Jacobian of a point on link 2 (shifted by link 1's chord and its own u)
        let f = Vector2::new(0.7, -1.3);
        for (link, x) in [(0, 4.0), (1, 3.3), (2, 6.0)] {
            let gen = |a: &PlanarArm, q: &[f64]| {
                let s = a.station(link, x).unwrap();
                let mut g = DVector::zeros(n);
                a.pose(q).add_point_force(&s, &f, g.as_mut_slice());
                g
            };
            let col = |v: DVector<f64>| DMatrix::from_column_slice(n, 1, v.as_slice());
            let pos = |a: &PlanarArm, q: &[f64]| {
                DVector::from_element(1, f.dot(&a.pose(q).position(&a.station(link, x).unwrap())))
            };
            let fd = jacobian_fd(&q, |q| pos(&stiff, q)).transpose()
                - jacobian_fd(&q, |q| pos(&plain, q)).transpose();
            assert_change("∂(f·r)/∂q", &col(gen(&stiff, &q) - gen(&plain, &q)), &fd);
            let hess = |a: &PlanarArm| {
                let mut h = DMatrix::zeros(n, n);
                a.pose(&q)
                    .point_hessian(&a.station(link, x).unwrap(), |i, j, v| {
                        h[(i, j)] += f.dot(&v)
                    });
                h
            };
            let fd = jacobian_fd(&q, |q| gen(&stiff, q)) - jacobian_fd(&q, |q| gen(&plain, q));
            assert_change("∂²(f·r)/∂q²", &(hess(&stiff) - hess(&plain)), &fd);
        }
        // J_c (the callers of point_jacobian may assign a column: one per coordinate)
        for pin in [Pin::on_link(0, 4.0), Pin::on_link(1, 3.0)] {
            let jc = stiff.pin_jacobian(&stiff.pose(&q), &pin);
            let fd = jacobian_fd(&q, |q| {
                let r = stiff.pose(q).pin_position(&pin);
                DVector::from_column_slice(&[r.x, r.y])
            });
            let err = (&jc - &fd).abs().max() / fd.abs().max();
            assert!(err < 1e-7, "J_c: {err:e}");
        }
        for act in &cylinders() {
            let grad = |a: &PlanarArm, q: &[f64]| {
                let (pa, pb) = (
                    a.resolve_pin(&act.a).unwrap(),
                    a.resolve_pin(&act.b).unwrap(),
                );
                let mut g = DVector::zeros(n);
                let l = a.pose(q).actuator_length(&pa, &pb, g.as_mut_slice());
                (l, g)
            };
            let fd = jacobian_fd(&q, |q| DVector::from_element(1, grad(&stiff, q).0))
                - jacobian_fd(&q, |q| DVector::from_element(1, grad(&plain, q).0));
            let got = grad(&stiff, &q).1 - grad(&plain, &q).1;
            assert_change(
                "∂l/∂q",
                &DMatrix::from_column_slice(n, 1, got.as_slice()),
                &fd.transpose(),
            );
            let hess = |a: &PlanarArm| {
                let (pa, pb) = (
                    a.resolve_pin(&act.a).unwrap(),
                    a.resolve_pin(&act.b).unwrap(),
                );
                let (mut h, mut jd) = (DMatrix::zeros(n, n), vec![Vector2::zeros(); n]);
                a.pose(&q)
                    .actuator_length_hessian(&pa, &pb, &mut jd, &mut h);
                h
            };
            let fd =
                jacobian_fd(&q, |q| grad(&stiff, q).1) - jacobian_fd(&q, |q| grad(&plain, q).1);
            assert_change("∇²l", &(hess(&stiff) - hess(&plain)), &fd);
        }
    }
}

/// `½∫ρA|ṙ|²` of the whole arm by Gauss–Legendre quadrature, with every point's velocity
/// from fourth-order central differences in time of its position (`r(q + k h u)`,
/// k = ±1, ±2): the exact translational kinetic energy of the arm's kinematics, shortening
/// included when the arm keeps it.
fn translational_energy_by_quadrature(arm: &PlanarArm, q: &[f64], u: &[f64]) -> f64 {
    let h = 1e-3;
    let at = |k: f64| -> Vec<f64> { q.iter().zip(u).map(|(x, v)| x + k * h * v).collect() };
    let qs = [at(-2.0), at(-1.0), at(1.0), at(2.0)];
    let poses: Vec<_> = qs.iter().map(|q| arm.pose(q)).collect();
    let rule = bg_manipulator::GaussLegendre::new(48).unwrap();
    let mut t = 0.0;
    for (i, link) in arm.links().iter().enumerate() {
        let mut point = |x: f64, m: f64| {
            let s = arm.station(i, x).unwrap();
            let r: Vec<Vector2<f64>> = poses.iter().map(|p| p.position(&s)).collect();
            let v = (r[0] - 8.0 * r[1] + 8.0 * r[2] - r[3]) / (12.0 * h);
            t += 0.5 * m * v.norm_squared();
        };
        if link.mass_per_length() > 0.0 {
            for (x, w) in rule.on(link.length()) {
                point(x, w * link.mass_per_length());
            }
        }
        for pm in link.point_masses() {
            point(pm.x, pm.mass);
        }
    }
    t
}

#[test]
fn the_kinetic_energy_is_the_exact_one_to_second_order_in_the_deflection() {
    // ΔT (stiffened − plain) against the same change of the exact ½∫ρA|ṙ|² of the points
    // at their shortened positions: the model keeps every term of second order in the
    // modal coordinates and speeds (both scaled by ε), so the difference is of third order —
    // it falls ∝ ε³ while ΔT ∝ ε².
    let (plain, stiff) = arms();
    for (q, u) in states(41, &stiff) {
        let mut errs = Vec::new();
        for eps in [0.0125, 0.00625, 0.003125] {
            let scaled: Vec<f64> = q
                .iter()
                .enumerate()
                .map(|(k, x)| if k < stiff.n_links() { *x } else { eps * x })
                .collect();
            let speeds: Vec<f64> = u
                .iter()
                .enumerate()
                .map(|(k, x)| if k < stiff.n_links() { *x } else { eps * x })
                .collect();
            let model = stiff.kinematics(&scaled).kinetic_energy(&speeds)
                - plain.kinematics(&scaled).kinetic_energy(&speeds);
            let exact = translational_energy_by_quadrature(&stiff, &scaled, &speeds)
                - translational_energy_by_quadrature(&plain, &scaled, &speeds);
            let rel = (model - exact).abs() / exact.abs();
            println!("ε = {eps}: ΔT {model:.6e}, exact {exact:.6e}, relative {rel:.3e}");
            errs.push(rel);
        }
        // the relative error falls with ε (∝ ε: a third-order rest); a missing or wrong
        // second-order term would leave it constant
        assert!(
            errs[1] < errs[0] / 1.6 && errs[2] < errs[1] / 1.6,
            "{errs:?}"
        );
        assert!(errs[2] < 1e-4, "{errs:?}");
    }
}

#[test]
fn the_reactions_are_newtons_law_of_the_shortened_points() {
    // ρ at joint j is the force that accelerates everything outboard of it against gravity:
    // R_0^j Σ ∫ρA (r̈ + g ŷ) over the links ≥ j, with r̈ by central differences in time of the
    // points' shortened positions along q(t) = q + u t + ½u̇t². No loads, no rigid masses.
    let (plain, stiff) = arms();
    let mut rng = Rng::new(53);
    let rule = bg_manipulator::GaussLegendre::new(48).unwrap();
    for _ in 0..3 {
        let q = rng.q(&stiff, 0.05);
        let (u, u_dot) = (rng.vec(stiff.n(), 1.0), rng.vec(stiff.n(), 1.0));
        let newton = |arm: &PlanarArm| {
            let h = 1e-3;
            let at = |t: f64| -> Vec<f64> {
                (0..q.len())
                    .map(|k| q[k] + u[k] * t + 0.5 * u_dot[k] * t * t)
                    .collect()
            };
            let qs = [at(-2.0 * h), at(-h), at(0.0), at(h), at(2.0 * h)];
            let poses: Vec<_> = qs.iter().map(|q| arm.pose(q)).collect();
            let mut per_link = vec![Vector2::zeros(); arm.n_links()];
            for (i, link) in arm.links().iter().enumerate() {
                let mut point = |x: f64, m: f64| {
                    let s = arm.station(i, x).unwrap();
                    let r: Vec<Vector2<f64>> = poses.iter().map(|p| p.position(&s)).collect();
                    let a =
                        (-r[0] + 16.0 * r[1] - 30.0 * r[2] + 16.0 * r[3] - r[4]) / (12.0 * h * h);
                    per_link[i] += m * (a + Vector2::new(0.0, G));
                };
                if link.mass_per_length() > 0.0 {
                    for (x, w) in rule.on(link.length()) {
                        point(x, w * link.mass_per_length());
                    }
                }
                for pm in link.point_masses() {
                    point(pm.x, pm.mass);
                }
            }
            let mut rho = DVector::zeros(2 * arm.n_links());
            for j in 0..arm.n_links() {
                let f: Vector2<f64> = per_link[j..].iter().sum();
                let fj = poses[2].to_frame(j, &f);
                rho[2 * j] = fj.x;
                rho[2 * j + 1] = fj.y;
            }
            rho
        };
        let model = |arm: &PlanarArm| arm.kinematics(&q).reactions(&u, &u_dot, &[], &[]);
        let (got, want) = (
            model(&stiff) - model(&plain),
            newton(&stiff) - newton(&plain),
        );
        let col = |v: DVector<f64>| DMatrix::from_column_slice(v.len(), 1, v.as_slice());
        assert_change("Δρ", &col(got), &col(want));
    }
}
