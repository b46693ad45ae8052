//! The moving base (crate::base): against an independent Lagrange derivation in inertial
//! coordinates, a base accelerating upwards as heavier gravity, the parametric resonance of
//! a pendulum on a heaving base (Mathieu) against Floquet multipliers computed here, and a
//! base that does not move against no base at all.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;
use std::sync::Arc;

use bg_manipulator::{ArmScene, Base, Link, PointMass};
use bondgraph::{assign_causality, simulate, BondGraph, Motion, Output, Settings, StateEquations};
use nalgebra::{Matrix2, Vector2};

const G: f64 = 9.81;

fn law(f: impl Fn(f64) -> [f64; 3] + Send + Sync + 'static) -> Motion {
    Motion::Law(Arc::new(f))
}

fn equations(scene: &ArmScene) -> StateEquations {
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "a").unwrap();
    StateEquations::new(assign_causality(g).unwrap()).unwrap()
}

fn read(eqs: &StateEquations, name: &str, t: f64, x: &[f64]) -> f64 {
    eqs.read(eqs.probe(name).unwrap(), t, x)
}

// A rigid double pendulum: link 1 a rod (μ1, j1) with a point mass, link 2 a rod with a tip
// mass (the constants of tests/rigid_double_pendulum.rs).
const L1: f64 = 1.3;
const MU1: f64 = 2.0;
const J1: f64 = 0.01;
const PM1: f64 = 0.7;
const A1: f64 = 0.4;
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

/// By hand, in inertial coordinates: absolute angle φ₁ = θ + q₁, φ₁₂ = φ₁ + q₂, absolute
/// speeds (w₁, u₂), a uniform field f (gravity minus the base's acceleration, inertial axes):
/// T = ½ I1 w₁² + ½ [M2 L1² w₁² + I2 (w₁ + u₂)² + 2 L1 s2 w₁ (w₁ + u₂) cos q₂],
/// V = −f · (S1 e(φ₁) + s2 e(φ₁₂)). Returns the absolute accelerations (φ̈₁, q̈₂) and
/// Σ m r̈ relative to the base's origin.
fn closed_form(phi1: f64, q2: f64, w: [f64; 2], f: Vector2<f64>) -> (Vector2<f64>, Vector2<f64>) {
    let i1 = MU1 * L1.powi(3) / 3.0 + J1 * L1 + PM1 * A1 * A1;
    let s1 = MU1 * L1 * L1 / 2.0 + PM1 * A1;
    let m2 = MU2 * L2 + PM2;
    let s2 = MU2 * L2 * L2 / 2.0 + PM2 * L2;
    let i2 = MU2 * L2.powi(3) / 3.0 + J2 * L2 + PM2 * L2 * L2;
    let big_s1 = s1 + m2 * L1;
    let c2 = q2.cos();
    let m12 = i2 + L1 * s2 * c2;
    let m = Matrix2::new(i1 + m2 * L1 * L1 + i2 + 2.0 * L1 * s2 * c2, m12, m12, i2);
    let h = L1 * s2 * q2.sin();
    let phi12 = phi1 + q2;
    let rhs = Vector2::new(
        f.x * (-big_s1 * phi1.sin() - s2 * phi12.sin())
            + f.y * (big_s1 * phi1.cos() + s2 * phi12.cos())
            + 2.0 * h * w[0] * w[1]
            + h * w[1] * w[1],
        f.x * (-s2 * phi12.sin()) + f.y * (s2 * phi12.cos()) - h * w[0] * w[0],
    );
    let acc = m.lu().solve(&rhs).unwrap();
    let e = |a: f64| Vector2::new(a.cos(), a.sin());
    let n = |a: f64| Vector2::new(-a.sin(), a.cos());
    let w12 = w[0] + w[1];
    let mr_ddot = big_s1 * (acc[0] * n(phi1) - w[0] * w[0] * e(phi1))
        + s2 * ((acc[0] + acc[1]) * n(phi12) - w12 * w12 * e(phi12));
    (acc, mr_ddot)
}

fn sea_base() -> Base {
    Base {
        x: law(|t| {
            [
                0.3 * (1.1 * t).sin() + 0.2 * t * t,
                0.33 * (1.1 * t).cos() + 0.4 * t,
                -0.363 * (1.1 * t).sin() + 0.4,
            ]
        }),
        y: law(|t| {
            let w: f64 = 0.8;
            [
                0.5 * (w * t).cos(),
                -0.5 * w * (w * t).sin(),
                -0.5 * w * w * (w * t).cos(),
            ]
        }),
        roll: law(|t| {
            let (w, a, ph) = (0.9_f64, 0.1, 0.4);
            [
                a * (w * t + ph).sin(),
                a * w * (w * t + ph).cos(),
                -a * w * w * (w * t + ph).sin(),
            ]
        }),
    }
}

#[test]
fn base_moving_and_rolling_gives_the_inertial_lagrange_accelerations_and_pedestal_load() {
    let base = sea_base();
    let mass = MU1 * L1 + PM1 + MU2 * L2 + PM2;
    for (q, u) in [
        ([0.3, -1.1], [0.7, -2.0]),
        ([-2.0, 2.5], [-1.5, 0.4]),
        ([-1.4, 0.2], [0.0, 0.0]),
    ] {
        let mut scene = ArmScene::new(links(), G);
        scene.q0 = q.to_vec();
        scene.u0 = u.to_vec();
        scene.base = Some(base.clone());
        let eqs = equations(&scene);
        let x0 = eqs.initial_state();
        let omega0 = base.roll.eval(0.0)[1];
        for t in [0.0, 0.7] {
            let b = base.at(t);
            let theta = b.roll[0];
            // the state keeps the absolute momentum: the absolute speed is u₀ + θ̇(0) e₁
            let w = [u[0] + omega0, u[1]];
            let f = Vector2::new(-b.x[2], -G - b.y[2]);
            let (acc, mr_ddot) = closed_form(theta + q[0], q[1], w, f);
            eqs.evaluate(t, &x0);
            let udot = [
                read(&eqs, "a_arm.udot[0]", t, &x0),
                read(&eqs, "a_arm.udot[1]", t, &x0),
            ];
            let expect = [acc[0] - b.roll[2], acc[1]];
            for k in 0..2 {
                assert!(
                    (udot[k] - expect[k]).abs() <= 1e-11 * expect[k].abs().max(1.0),
                    "t {t} q {q:?}: u̇{k} = {} vs {}",
                    udot[k],
                    expect[k]
                );
            }
            let u1 = read(&eqs, "a_arm.u[0]", t, &x0);
            assert!((u1 - (w[0] - b.roll[1])).abs() < 1e-13, "relative speed");
            // the pedestal: the arm's load on the vessel, in the vessel's axes
            let on_arm =
                mass * Vector2::new(b.x[2], b.y[2]) + mr_ddot - mass * Vector2::new(0.0, -G);
            let (s, c) = theta.sin_cos();
            let on_vessel =
                -Vector2::new(c * on_arm.x + s * on_arm.y, -s * on_arm.x + c * on_arm.y);
            let fx = read(&eqs, "a_rho.F_ped_x", t, &x0);
            let fy = read(&eqs, "a_rho.F_ped_y", t, &x0);
            let scale = mass * G;
            assert!(
                (fx - on_vessel.x).abs() <= 1e-11 * scale,
                "F_ped_x {fx} vs {}",
                on_vessel.x
            );
            assert!(
                (fy - on_vessel.y).abs() <= 1e-11 * scale,
                "F_ped_y {fy} vs {}",
                on_vessel.y
            );
            // joint 1 is free: no moment reaches the vessel
            let m = read(&eqs, "a_rho.M_ped", t, &x0);
            assert!(m.abs() <= 1e-11 * scale * L1, "M_ped {m}");
        }
    }
}

/// A pendulum (massless rod, tip mass) hanging from a base that accelerates upwards at `a`.
fn lifted_pendulum(a: f64, q0: f64) -> ArmScene {
    let mut scene = ArmScene::new(vec![Link::pendulum(2.0, 30.0).unwrap()], G);
    scene.q0 = vec![q0];
    scene.base = Some(Base {
        x: Motion::Const(0.0),
        y: law(move |t| [0.5 * a * t * t, a * t, a]),
        roll: Motion::Const(0.0),
    });
    scene
}

#[test]
fn base_accelerating_upwards_is_gravity_g_plus_a() {
    let (a, m, l) = (3.7, 30.0, 2.0);
    // hanging load
    let scene = lifted_pendulum(a, -PI / 2.0);
    let eqs = equations(&scene);
    let x0 = eqs.initial_state();
    for t in [0.0, 1.3] {
        eqs.evaluate(t, &x0);
        let rho1 = read(&eqs, "a_rho.rho1", t, &x0);
        assert!(
            (rho1 + m * (G + a)).abs() <= 1e-9 * m * (G + a),
            "hanging load {rho1} vs {}",
            -m * (G + a)
        );
        let fy = read(&eqs, "a_rho.F_ped_y", t, &x0);
        assert!(
            (fy + m * (G + a)).abs() <= 1e-9 * m * (G + a),
            "pedestal {fy}"
        );
    }
    // the restoring moment −m (g + a) L sin ε at every angle ε from hanging: the frequency
    // is √((g + a)/L)
    for eps in [1e-3, 0.1, 0.7] {
        let scene = lifted_pendulum(a, -PI / 2.0 + eps);
        let eqs = equations(&scene);
        let x0 = eqs.initial_state();
        let mut dx = vec![0.0; x0.len()];
        eqs.rhs(0.9, &x0, &mut dx);
        let g_eff = -dx[0] / (m * l * eps.sin());
        assert!(
            (g_eff - (G + a)).abs() <= 1e-9 * (G + a),
            "ε {eps}: g_eff {g_eff} vs {}",
            G + a
        );
    }
    // and the swing equals the swing of a pendulum on solid ground under gravity g + a
    let run = |scene: &ArmScene| {
        let mut eqs = equations(scene);
        let outputs = vec![Output {
            name: "q".into(),
            probe: eqs.probe("a_arm.q1").unwrap(),
        }];
        let settings = Settings {
            t_end: 5.0,
            dt_out: 0.05,
            rtol: 1e-10,
            atol: 1e-12,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let r = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(r.error.is_none(), "{:?}", r.error);
        r.trajectory.column("q").unwrap()
    };
    let lifted = run(&lifted_pendulum(a, -PI / 2.0 + 0.6));
    let mut heavy = ArmScene::new(vec![Link::pendulum(2.0, 30.0).unwrap()], G + a);
    heavy.q0 = vec![-PI / 2.0 + 0.6];
    let heavy = run(&heavy);
    let worst = lifted
        .iter()
        .zip(&heavy)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-7, "lifted vs heavier gravity: {worst} rad");
}

/// The linearised damped pendulum on a base heaving as `A cos(Ω t)`:
/// θ̈ + 2ζω₀ θ̇ + (g + ÿ_b)/L θ = 0. Largest |Floquet multiplier| over one period, from the
/// monodromy matrix integrated with classical RK4.
fn floquet(a: f64, omega: f64, zeta: f64, l: f64) -> f64 {
    let w0 = (G / l).sqrt();
    let period = 2.0 * PI / omega;
    let steps = 4000;
    let h = period / f64::from(steps);
    let rate = |t: f64, y: [f64; 2]| -> [f64; 2] {
        let yb_ddot = -a * omega * omega * (omega * t).cos();
        [y[1], -2.0 * zeta * w0 * y[1] - (G + yb_ddot) / l * y[0]]
    };
    let mut cols = [[1.0, 0.0], [0.0, 1.0]];
    for y in &mut cols {
        let mut t = 0.0;
        for _ in 0..steps {
            let k1 = rate(t, *y);
            let k2 = rate(
                t + h / 2.0,
                [y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]],
            );
            let k3 = rate(
                t + h / 2.0,
                [y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]],
            );
            let k4 = rate(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
            for i in 0..2 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
        }
    }
    // eigenvalues of [[a, b], [c, d]] (columns are the images of e₁, e₂)
    let (m11, m21, m12, m22) = (cols[0][0], cols[0][1], cols[1][0], cols[1][1]);
    let (tr, det) = (m11 + m22, m11 * m22 - m12 * m21);
    let disc = tr * tr / 4.0 - det;
    if disc >= 0.0 {
        (tr / 2.0 + disc.sqrt())
            .abs()
            .max((tr / 2.0 - disc.sqrt()).abs())
    } else {
        det.sqrt()
    }
}

#[test]
fn base_heaving_at_twice_the_natural_frequency_shows_the_mathieu_resonance() {
    let (l, m, zeta) = (1.0, 1.0, 0.02);
    let w0 = (G / l).sqrt();
    let omega = 2.0 * w0;
    // the first tongue's boundary at Ω = 2ω₀: the heave amplitude where |λ|max = 1
    let (mut lo, mut hi) = (0.0, 0.2);
    assert!(floquet(lo, omega, zeta, l) < 1.0 && floquet(hi, omega, zeta, l) > 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if floquet(mid, omega, zeta, l) > 1.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let a_c = 0.5 * (lo + hi);
    // (the textbook estimate ε = AΩ²/g = 4ζ, A = ζ L: within a few per cent)
    assert!((a_c / (zeta * l) - 1.0).abs() < 0.05, "A_c = {a_c}");
    let period = 2.0 * PI / omega;
    let growth = |a: f64| -> f64 {
        let mut scene = ArmScene::new(vec![Link::pendulum(l, m).unwrap()], G);
        scene.q0 = vec![-PI / 2.0 + 0.01];
        scene.damping = vec![2.0 * zeta * w0 * m * l * l];
        scene.base = Some(Base {
            x: Motion::Const(0.0),
            y: law(move |t| {
                let c = (omega * t).cos();
                [
                    a * c,
                    -a * omega * (omega * t).sin(),
                    -a * omega * omega * c,
                ]
            }),
            roll: Motion::Const(0.0),
        });
        let mut eqs = equations(&scene);
        let outputs = vec![Output {
            name: "q".into(),
            probe: eqs.probe("a_arm.q1").unwrap(),
        }];
        let n_periods = 60.0;
        let settings = Settings {
            t_end: n_periods * period,
            dt_out: period / 100.0,
            rtol: 1e-9,
            atol: 1e-11,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let r = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(r.error.is_none(), "{:?}", r.error);
        let q = r.trajectory.column("q").unwrap();
        let amp = |window: &[f64]| {
            window
                .iter()
                .map(|x| (x + PI / 2.0).abs())
                .fold(0.0, f64::max)
        };
        let per = 100;
        // late windows, where the less damped Floquet solution dominates (the other one
        // has decayed by (λ₂/λ₁)²⁵ < 0.1 at A = 0.8 A_c)
        let first = amp(&q[25 * per..30 * per]);
        let last = amp(&q[q.len() - 5 * per..]);
        // per period, over the 30 periods between the windows' starts
        (last / first).powf(1.0 / 30.0)
    };
    for (factor, unstable) in [(1.2, true), (0.8, false)] {
        let a = factor * a_c;
        let lambda = floquet(a, omega, zeta, l);
        let g = growth(a);
        eprintln!("A = {factor} A_c = {a:.5} m: Floquet |λ| {lambda:.5}, measured growth per period {g:.5}");
        assert_eq!(lambda > 1.0, unstable);
        assert_eq!(g > 1.0, unstable, "A = {factor} A_c: growth {g} per period");
        assert!(
            (g.ln() / lambda.ln() - 1.0).abs() < 0.03,
            "growth per period {g} vs Floquet {lambda}"
        );
    }
}

#[test]
fn base_that_does_not_move_leaves_the_crane_as_it_was() {
    // the knuckle boom's links with three modes each, the cylinder bodies rigid (a base
    // refuses masses on springs), free of actuators: it falls and swings for two seconds
    let beam = |len: f64| {
        Link::beam(len, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(3)
            .unwrap()
    };
    let make = |base: Option<Base>| {
        let mut scene = ArmScene::new(
            vec![beam(10.0), beam(8.0), Link::pendulum(6.0, 5000.0).unwrap()],
            G,
        );
        scene.q0 = vec![0.3, -2.0 * PI / 3.0, -0.4];
        scene.damping = vec![0.0, 0.0, 0.0, 30.0, 30.0, 30.0, 30.0, 30.0, 30.0];
        scene.base = base;
        scene
    };
    let run = |scene: &ArmScene| {
        let mut eqs = equations(scene);
        let names = [
            "a_arm.q1",
            "a_arm.q2",
            "a_arm.q3",
            "a_arm.qb1_1",
            "a_arm.qb2_1",
            "a_rho.rho1",
            "a_rho.rho5",
        ];
        let outputs = names
            .iter()
            .map(|n| Output {
                name: (*n).into(),
                probe: eqs.probe(n).unwrap(),
            })
            .collect::<Vec<_>>();
        let settings = Settings {
            t_end: 2.0,
            dt_out: 0.01,
            rtol: 1e-7,
            atol: 1e-9,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let r = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(r.error.is_none(), "{:?}", r.error);
        (names, r.trajectory)
    };
    let (names, today) = run(&make(None));
    let (_, still) = run(&make(Some(Base::still())));
    for n in names {
        let (a, b) = (today.column(n).unwrap(), still.column(n).unwrap());
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-12 * scale, "{n}: {worst} of {scale}");
    }
}
