//! The payload on an elastic wire and its landing (elements/wire_payload.rs): free fall
//! while the wire is slack, the peak tension of a mass caught by a spring, the Hunt–Crossley
//! restitution and the static deflection of a resting payload.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::elements::{Landing, WireSpec};
use bg_manipulator::{ArmScene, Link};
use bondgraph::{assign_causality, simulate, BondGraph, Motion, Output, Settings, StateEquations};

const G: f64 = 9.81;

/// A mast: one rigid link standing straight up, so heavy (10¹² kg) that the payload's pull
/// along it moves nothing; the tip at (0, 2 m).
fn mast(spec: WireSpec) -> ArmScene {
    let mut scene = ArmScene::new(vec![Link::rigid(2.0, 5e11).unwrap()], G);
    scene.q0 = vec![PI / 2.0];
    scene.payload = Some(spec);
    scene
}

fn wire(length: f64) -> WireSpec {
    WireSpec {
        mass: 100.0,
        ea: 1e6,
        damping: 0.0,
        length,
        winch: false,
        slack_band: 1e-6,
        start_stretched: false,
        landing: None,
    }
}

fn equations(scene: &ArmScene) -> StateEquations {
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "a").unwrap();
    StateEquations::new(assign_causality(g).unwrap()).unwrap()
}

fn state(eqs: &StateEquations, name: &str) -> usize {
    eqs.states().iter().position(|s| s.name == name).unwrap()
}

fn run(eqs: &mut StateEquations, x0: &[f64], t_end: f64, dt: f64, names: &[&str]) -> Vec<Vec<f64>> {
    let outputs = names
        .iter()
        .map(|n| Output {
            name: (*n).into(),
            probe: eqs.probe(n).unwrap(),
        })
        .collect::<Vec<_>>();
    let settings = Settings {
        t_end,
        dt_out: dt,
        rtol: 1e-9,
        atol: 1e-10,
        ..Settings::default()
    };
    let r = simulate(eqs, x0, &settings, &outputs, vec![]);
    assert!(r.error.is_none(), "{:?}", r.error);
    names
        .iter()
        .map(|n| r.trajectory.column(n).unwrap())
        .collect()
}

#[test]
fn wire_slack_payload_falls_freely_then_the_peak_tension_is_a_mass_caught_by_a_spring() {
    let (m, ea, length, drop) = (100.0, 1e6, 3.0, 0.5);
    let mut eqs = equations(&mast(wire(length)));
    let mut x0 = eqs.initial_state();
    let iy = state(&eqs, "a_payload.y");
    let ipy = state(&eqs, "a_payload.py");
    // hanging exactly at length L below the tip; lift it by `drop`: the wire is slack
    x0[iy] += drop;
    let mut dx = vec![0.0; x0.len()];
    for lift in [drop, 0.3, 1e-3] {
        let mut x = x0.clone();
        x[iy] += lift - drop;
        x[ipy] = -m * 0.7;
        eqs.rhs(0.4, &x, &mut dx);
        let a = dx[ipy] / m;
        assert!((a + G).abs() <= 1e-9 * G, "slack by {lift} m: ÿ = {a}");
    }
    let out = run(
        &mut eqs,
        &x0,
        0.6,
        1e-4,
        &["a_payload.y", "a_payload.T", "a_arm.q1"],
    );
    let (y, tension, q1) = (&out[0], &out[1], &out[2]);
    // free fall until the wire takes up, t = √(2d/g)
    let t_catch = (2.0 * drop / G).sqrt();
    for (k, yk) in y.iter().enumerate() {
        let t = k as f64 * 1e-4;
        if t < t_catch - 1e-3 {
            let free = x0[iy] - 0.5 * G * t * t;
            assert!((yk - free).abs() < 1e-7, "t {t}: y {yk} vs {free}");
            assert!(
                tension[k].to_bits() == 0,
                "t {t}: slack wire pulls {}",
                tension[k]
            );
        }
    }
    // ½ m v² + m g s = ½ k s²  ⇒  T_max = k s_max = m g + √((m g)² + k m v²)
    let k = ea / length;
    let v = (2.0 * G * drop).sqrt();
    let expect = m * G + ((m * G).powi(2) + k * m * v * v).sqrt();
    let peak = tension.iter().fold(0.0f64, |a, b| a.max(*b));
    eprintln!("peak tension {peak:.2} N, closed form {expect:.2} N");
    assert!(
        (peak / expect - 1.0).abs() < 1e-4,
        "peak {peak} vs {expect}"
    );
    // the mast did not move
    assert!(q1.iter().all(|q| (q - PI / 2.0).abs() < 1e-9));
}

/// A payload on a long slack wire over a fixed deck at height 0 (the payload starts 1 m
/// above it, falling).
fn landing_scene(k_c: f64, n: f64, lambda: f64, mu: f64) -> ArmScene {
    let mut spec = wire(100.0);
    spec.landing = Some(Landing {
        height: Motion::Const(0.0),
        stiffness: k_c,
        exponent: n,
        damping: lambda,
        friction: mu,
        slip_speed: 1e-3,
    });
    mast(spec)
}

/// Rebound over impact speed of m δ̈ = m g − max(0, k δⁿ + λ δⁿ δ̇) from δ = 0, δ̇ = v.
fn restitution_ode(m: f64, k: f64, n: f64, lambda: f64, v: f64) -> f64 {
    let acc = |d: f64, dd: f64| {
        let dn = d.max(0.0).powf(n);
        G - (k * dn + lambda * dn * dd).max(0.0) / m
    };
    let (mut d, mut dd, h) = (0.0_f64, v, 1e-8);
    loop {
        let (k1, l1) = (dd, acc(d, dd));
        let (k2, l2) = (dd + 0.5 * h * l1, acc(d + 0.5 * h * k1, dd + 0.5 * h * l1));
        let (k3, l3) = (dd + 0.5 * h * l2, acc(d + 0.5 * h * k2, dd + 0.5 * h * l2));
        let (k4, l4) = (dd + h * l3, acc(d + h * k3, dd + h * l3));
        d += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        dd += h / 6.0 * (l1 + 2.0 * l2 + 2.0 * l3 + l4);
        if d <= 0.0 {
            return -dd / v;
        }
    }
}

#[test]
fn landing_hunt_crossley_restitution_and_static_deflection() {
    let (m, k_c, n) = (100.0, 1e8, 1.5);
    let v_i = (2.0 * G * 1.0_f64).sqrt();
    for e in [0.95, 0.9, 0.7] {
        let lambda = 3.0 * k_c * (1.0 - e) / (2.0 * v_i);
        let mut eqs = equations(&landing_scene(k_c, n, lambda, 0.0));
        let mut x0 = eqs.initial_state();
        let iy = state(&eqs, "a_payload.y");
        x0[iy] = 1.0;
        let dt = 1e-6;
        let out = run(
            &mut eqs,
            &x0,
            0.47,
            dt,
            &["a_payload.vy", "a_payload.contact", "a_payload.y"],
        );
        let (vy, contact) = (&out[0], &out[1]);
        let first = contact.iter().position(|c| *c > 0.0).unwrap();
        let last = first + contact[first..].iter().position(|c| *c == 0.0).unwrap();
        let (v_in, v_out) = (-vy[first - 1], vy[last]);
        let e_meas = v_out / v_in;
        eprintln!("e = {e}: impact {v_in:.4} m/s, rebound {v_out:.4} m/s, e measured {e_meas:.4}");
        assert!(
            (v_in - v_i).abs() < 1e-3 * v_i,
            "impact speed {v_in} vs {v_i}"
        );
        // the relation λ = 3k(1 − e)/(2v) is Hunt and Crossley's first-order estimate in
        // 1 − e: within 0.01 for e ≥ 0.9 (it overestimates the loss further down)
        if e >= 0.9 {
            assert!((e_meas - e).abs() < 0.01, "e {e}: measured {e_meas}");
        }
        // against the 1-D contact ODE m δ̈ = −k δⁿ − λ δⁿ δ̇ integrated here (RK4)
        let e_ode = restitution_ode(m, k_c, n, lambda, v_i);
        assert!(
            (e_meas - e_ode).abs() < 1e-4,
            "e measured {e_meas} vs ODE {e_ode}"
        );
    }
    // at rest on the deck: δ = (m g / k)^(1/n)
    // (heavily damped, λ = 10¹⁰ N·s/m^2.5, so that it settles within the run; set down
    // with half the static penetration)
    let expect = (m * G / k_c).powf(1.0 / n);
    let mut eqs = equations(&landing_scene(k_c, n, 1e10, 0.3));
    let mut x0 = eqs.initial_state();
    let iy = state(&eqs, "a_payload.y");
    x0[iy] = -0.5 * expect;
    let out = run(
        &mut eqs,
        &x0,
        2.0,
        1e-3,
        &["a_payload.y", "a_payload.contact"],
    );
    let (y, f) = (out[0].last().unwrap(), out[1].last().unwrap());
    eprintln!(
        "resting: penetration {:.6e} m, closed form {expect:.6e} m",
        -y
    );
    assert!((-y / expect - 1.0).abs() < 1e-6, "δ {} vs {expect}", -y);
    assert!((f / (m * G) - 1.0).abs() < 1e-6, "contact force {f}");
}
