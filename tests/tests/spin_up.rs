//! The spin-up benchmark of Kane, Ryan & Banerjee (J. Guidance 1987): a cantilever of
//! L = 10 m, EI = 1.4e4 N·m², ρA = 1.2 kg/m, no gravity, whose root angle is prescribed as
//!
//! ```text
//! θ(t) = (Ω_s/T_s)(t²/2 + (T_s/2π)²(cos(2πt/T_s) − 1))   t ≤ T_s,     Ω_s(t − T_s/2) after
//! ```
//!
//! with Ω_s = 6 rad/s, T_s = 15 s. Ω_s is well above the first bending frequency (3.80 rad/s):
//! without geometric stiffening the centrifugal force, which pulls the bent beam outwards,
//! is not balanced by the axial tension it causes, and the tip deflection diverges; with it,
//! the deflection stays bounded and settles to a small vibration about zero.
//!
//! The root angle is prescribed by a flywheel (rotary inertia J = 1e6 × the beam's, a point
//! mass at x = 0 turning with the root section) driven by the torque (J + ρAL³/3)θ̈(t) through a
//! constant MTF into joint 1 of the arm's 1-junction: the root follows θ(t) to within
//! (the beam's reaction torque)/J. The beam has clamped–free modes. The run with 3 modes at
//! rtol 1e-6 is compared with a reference computed here with 6 modes at rtol 1e-10.
//! `BG_UPDATE_DOCS=1` redraws `docs/manipulator/spin_up.png`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, CantileverMode, Link, ModeShape, PointMass};
use bondgraph::{
    assign_causality, simulate, BondGraph, DMatrix, EffortSource, MatrixTransformer, Output, Param,
    Settings, StateEquations,
};

const L: f64 = 10.0;
const EI: f64 = 1.4e4;
const RHO_A: f64 = 1.2;
const OMEGA_S: f64 = 6.0;
const T_S: f64 = 15.0;

/// θ̈(t) of the prescribed root angle.
fn root_acceleration(t: f64) -> f64 {
    if t <= T_S {
        OMEGA_S / T_S * (1.0 - (2.0 * PI * t / T_S).cos())
    } else {
        0.0
    }
}

/// θ(t).
fn root_angle(t: f64) -> f64 {
    if t <= T_S {
        let c = T_S / (2.0 * PI);
        OMEGA_S / T_S * (0.5 * t * t + c * c * ((2.0 * PI * t / T_S).cos() - 1.0))
    } else {
        OMEGA_S * (t - T_S / 2.0)
    }
}

struct Run {
    t: Vec<f64>,
    /// Tip deflection in the rotating frame of the root (m).
    tip: Vec<f64>,
    /// Largest |root angle − θ(t)| (rad).
    root_error: f64,
    /// Whether the run reached t_end.
    finished: bool,
}

fn spin_up(modes: u32, stiffening: bool, rtol: f64, t_end: f64) -> Run {
    let flywheel = 1e6 * RHO_A * L.powi(3) / 3.0;
    let link = Link::rigid(L, RHO_A)
        .unwrap()
        .with_bending_stiffness(EI)
        .unwrap()
        .with_cantilever_modes(modes)
        .unwrap()
        .with_point_mass(PointMass {
            x: 0.0,
            mass: 0.0,
            inertia: flywheel,
        })
        .unwrap()
        .with_geometric_stiffening(stiffening);
    let n = 1 + modes as usize;
    let scene = ArmScene::new(vec![link], 0.0);
    let mut g = BondGraph::new();
    let ports = scene.add_to(&mut g, "beam").unwrap();
    let torque = g
        .add(
            "torque",
            EffortSource::new(Param::modulated(vec![], move |t, _| {
                (flywheel + RHO_A * L.powi(3) / 3.0) * root_acceleration(t)
            })),
        )
        .unwrap();
    let mut select = DMatrix::zeros(n, 1);
    select[(0, 0)] = 1.0;
    let mtf = g
        .add("joint1", MatrixTransformer::constant(select).unwrap())
        .unwrap();
    let (p1, p2) = (
        g.port_index(mtf, "1").unwrap(),
        g.port_index(mtf, "2").unwrap(),
    );
    g.connect((torque, None), (mtf, Some(p2))).unwrap();
    let (_, junction, port) = ports.iter().find(|p| p.0 == "u").unwrap().clone();
    g.connect((mtf, Some(p1)), (junction, port)).unwrap();
    let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    let outputs: Vec<Output> = (0..n)
        .map(|k| Output {
            name: format!("q{k}"),
            probe: eqs.probe(&format!("beam_arm.q[{k}]")).unwrap(),
        })
        .collect();
    let settings = Settings {
        t_end,
        dt_out: 0.05,
        rtol,
        atol: rtol * 1e-2,
        ..Settings::default()
    };
    let x0 = eqs.initial_state();
    let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
    let t = run.trajectory.column("t").unwrap();
    let q: Vec<Vec<f64>> = (0..n)
        .map(|k| run.trajectory.column(&format!("q{k}")).unwrap())
        .collect();
    let psi_l: Vec<f64> = (1..=modes)
        .map(|k| CantileverMode::new(k, L).value(L))
        .collect();
    let tip = (0..t.len())
        .map(|r| (0..modes as usize).map(|k| psi_l[k] * q[k + 1][r]).sum())
        .collect();
    let root_error = t
        .iter()
        .zip(&q[0])
        .map(|(t, a)| (a - root_angle(*t)).abs())
        .fold(0.0, f64::max);
    Run {
        finished: run.error.is_none() && t.last().is_some_and(|l| (l - t_end).abs() < 1e-9),
        t,
        tip,
        root_error,
    }
}

/// Peak |tip deflection| and when.
fn peak(run: &Run) -> (f64, f64) {
    run.t
        .iter()
        .zip(&run.tip)
        .map(|(t, d)| (d.abs(), *t))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

#[test]
fn spin_up_with_stiffening_stays_bounded_and_without_diverges() {
    let t_end = 30.0;
    let stiff = spin_up(3, true, 1e-6, t_end);
    let reference = spin_up(6, true, 1e-10, t_end);
    assert!(stiff.finished && reference.finished);
    let theta_end = root_angle(t_end);
    assert!(
        stiff.root_error < 1e-6 * theta_end,
        "root angle error {}",
        stiff.root_error
    );
    let (p, tp) = peak(&stiff);
    let (p_ref, tp_ref) = peak(&reference);
    eprintln!(
        "with stiffening: peak |tip deflection| {p:.5} m at t = {tp:.2} s; reference (6 modes, rtol 1e-10) {p_ref:.5} m at {tp_ref:.2} s (rel. {:.1e}); root angle within {:.1e} rad",
        p / p_ref - 1.0,
        stiff.root_error
    );
    assert!(
        (p / p_ref - 1.0).abs() < 1e-2,
        "peak {p} vs reference {p_ref}"
    );
    // bounded, and it settles: after the spin-up (t > T_s + 5 s) the vibration is a small
    // fraction of the peak
    let late = stiff
        .t
        .iter()
        .zip(&stiff.tip)
        .filter(|(t, _)| **t > T_S + 5.0)
        .map(|(_, d)| d.abs())
        .fold(0.0, f64::max);
    eprintln!("after t = 20 s: |tip deflection| ≤ {late:.2e} m");
    assert!(p < 1.0 && late < 0.2 * p, "late {late} vs peak {p}");
    // without the shortening the deflection runs away once Ω passes the bending frequency
    let plain = spin_up(3, false, 1e-6, t_end);
    let (pp, tpp) = peak(&plain);
    eprintln!(
        "without stiffening: |tip deflection| reaches {pp:.3e} m at t = {tpp:.2} s (finished: {})",
        plain.finished
    );
    assert!(pp > 10.0 * p, "the plain beam diverges: {pp}");

    if std::env::var_os("BG_UPDATE_DOCS").is_some() {
        draw(&stiff, &reference, &plain);
    }
}

/// `docs/manipulator/spin_up.png`: the tip deflection with stiffening (and its reference), and
/// without.
fn draw(stiff: &Run, reference: &Run, plain: &Run) {
    use bg_model::plots::{Panel, Plot, Series};
    let mut csv = String::from("t,stiff,reference,plain\n");
    for (r, t) in stiff.t.iter().enumerate() {
        let clip = |v: Option<&f64>| v.map_or(f64::NAN, |v| v.clamp(-3.0, 3.0));
        csv.push_str(&format!(
            "{t},{},{},{}\n",
            stiff.tip[r],
            reference.tip.get(r).copied().unwrap_or(f64::NAN),
            clip(plain.tip.get(r))
        ));
    }
    let results = bg_sim::plot::Results::parse(&csv).unwrap();
    let series = |column: &str, label: &str, dashed: bool, line: usize| Series {
        column: column.to_owned(),
        label: label.to_owned(),
        scale: 1.0,
        offset: 0.0,
        dashed,
        line,
    };
    let plot = Plot {
        file: "spin_up".to_owned(),
        title:
            "Spin-up of a 10 m cantilever to 6 rad/s in 15 s: tip deflection in the rotating frame"
                .to_owned(),
        x: "t".to_owned(),
        x_label: "time [s]".to_owned(),
        panels: vec![
            Panel {
                y_label: "with geometric stiffening".to_owned(),
                unit: Some("m".to_owned()),
                x_range: None,
                series: vec![
                    series("stiff", "3 modes, rtol 1e-6", false, 0),
                    series("reference", "6 modes, rtol 1e-10", true, 1),
                ],
                line: 0,
            },
            Panel {
                y_label: "without (clipped at ±3 m)".to_owned(),
                unit: Some("m".to_owned()),
                x_range: None,
                series: vec![series("plain", "3 modes, rtol 1e-6", false, 2)],
                line: 0,
            },
        ],
        line: 0,
    };
    let dir = bg_tests::root().join("docs").join("manipulator");
    std::fs::create_dir_all(&dir).unwrap();
    bg_sim::plot::draw(&results, &plot, &dir, bg_sim::plot::Format::Png).unwrap();
}
