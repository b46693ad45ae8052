//! Stress recovery on the knuckle boom crane (`models/knuckle_boom.toml`, docs/stress.md):
//!
//! * statics: at the full rest state (`initial.steady.use = "rest"`) N, V, M along both booms,
//!   published by the arm's stress block, equal a free-body calculation written here from
//!   the design numbers (docs/knuckle-boom.md) and the rest state's deflections, to 1e-6 of
//!   the largest |M|; the modal moment EI·w'' converges towards the summed one as modes are
//!   added (1, 3, 10 modes);
//! * dynamics: along each boom dN/dx = −q_x, dV/dx = q_y and dM/dx = V + w'N − μ at random
//!   output rows of the crane's luffing run, by central differences, to 1e-6 of scale.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::many_single_char_names,
    clippy::needless_range_loop
)]

use bg_manipulator::stress::SectionGrid;
use bg_manipulator::{Link, PlanarArm};
use bg_model::Model;
use bg_tests::root;
use bondgraph::{Outcome, Output};
use nalgebra::Vector2;

const GRID: usize = 41;

fn run(sets: &[&str], extra: &[String]) -> Outcome {
    let mut sets: Vec<String> = sets.iter().map(|s| (*s).to_owned()).collect();
    sets.push(format!("elements.crane.stress_grid={GRID}"));
    let mut model = Model::load(
        &root().join("models/knuckle_boom.toml"),
        &bg_sim::registry(),
        &sets,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    for name in extra {
        let probe = model
            .equations
            .probe(name)
            .unwrap_or_else(|| panic!("no probe {name}"));
        model.outputs.push(Output {
            name: name.clone(),
            probe,
        });
    }
    model.run().unwrap_or_else(|e| panic!("{e}"))
}

fn grid_names(link: usize, q: &str) -> Vec<String> {
    (0..GRID)
        .map(|j| format!("crane_stress.grid{link}.{q}[{j}]"))
        .collect()
}

fn row(out: &Outcome, r: usize, names: &[String]) -> Vec<f64> {
    names
        .iter()
        .map(|n| out.trajectory.column(n).unwrap_or_else(|| panic!("{n}"))[r])
        .collect()
}

fn rot(phi: f64, v: Vector2<f64>) -> Vector2<f64> {
    let (s, c) = phi.sin_cos();
    Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

fn cross(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The crane's design numbers (docs/knuckle-boom.md).
const G: f64 = 9.81;
const L: [f64; 2] = [10.0, 8.0];
const RHO_A: f64 = 7850.0 * 0.0264;
const M3: f64 = 5000.0;
const M_P: f64 = 235.0;
const M_B: f64 = 713.0;
const D0: f64 = 3.0;
const H1: f64 = 4.0;
const H2: f64 = 4.0;
const H3: f64 = 3.0;

/// A link of the rest state: chord angle, origin, modal coordinates (sine modes).
struct Boom {
    phi: f64,
    o: Vector2<f64>,
    len: f64,
    qb: Vec<f64>,
}

impl Boom {
    fn w(&self, s: f64) -> f64 {
        self.qb
            .iter()
            .enumerate()
            .map(|(k, q)| q * ((k + 1) as f64 * std::f64::consts::PI * s / self.len).sin())
            .sum()
    }
    fn at(&self, s: f64) -> Vector2<f64> {
        self.o + rot(self.phi, Vector2::new(s, self.w(s)))
    }
    /// Weight of (x, L] and its moment about p, in closed form for the sine deflection.
    fn weight_beyond(&self, x: f64, p: Vector2<f64>) -> (Vector2<f64>, f64) {
        let (sn, cs) = self.phi.sin_cos();
        let pi = std::f64::consts::PI;
        let int_w: f64 = self
            .qb
            .iter()
            .enumerate()
            .map(|(k, q)| {
                let kp = (k + 1) as f64 * pi;
                q * self.len / kp * ((kp * x / self.len).cos() - kp.cos())
            })
            .sum();
        let int_rx =
            self.o.x * (self.len - x) + cs * (self.len * self.len - x * x) / 2.0 - sn * int_w;
        let w = RHO_A * G;
        (
            Vector2::new(0.0, -w * (self.len - x)),
            -w * (int_rx - p.x * (self.len - x)),
        )
    }
}

/// (N, V, M) of the hand free body at x on `link` (0 or 1), and the cylinder forces.
fn hand(b: &[Boom; 2], link: usize, x: f64) -> ((f64, f64, f64), (f64, f64)) {
    let weight = |m: f64| Vector2::new(0.0, -m * G);
    let beta3 = std::f64::consts::PI / 3.0;
    let base = Vector2::new(D0 * beta3.cos(), -D0 * beta3.sin());
    let (h11, h12, h21) = (b[0].at(H1), b[0].at(L[0] - H2), b[1].at(H3));
    let o3 = b[1].at(L[1]);
    let e1 = (h11 - base).normalize();
    let e2 = (h21 - h12).normalize();
    // cylinder 2: moments about joint 2 of link 2, the payload and piston 2
    let o2 = b[1].o;
    let (w2, m_w2) = b[1].weight_beyond(0.0, o2);
    let _ = w2;
    let m2 = m_w2 + cross(o3 - o2, weight(M3)) + cross(h21 - o2, weight(M_P));
    let f_c2 = -m2 / cross(h21 - o2, e2);
    // cylinder 1: moments about joint 1 of everything
    let zero = Vector2::zeros();
    let m1 = b[0].weight_beyond(0.0, zero).1
        + b[1].weight_beyond(0.0, zero).1
        + cross(o3, weight(M3))
        + cross(h11, weight(M_P))
        + cross(h12, weight(M_B))
        + cross(h21, weight(M_P));
    let f_c1 = -m1 / cross(h11, e1);
    // the free body beyond x
    let p = b[link].at(x);
    let mut loads: Vec<(Vector2<f64>, Vector2<f64>)> = vec![(o3, weight(M3))];
    let (mut f, mut m) = b[link].weight_beyond(x, p);
    if link == 0 {
        let (fw, mw) = b[1].weight_beyond(0.0, p);
        f += fw;
        m += mw;
        loads.push((h21, weight(M_P)));
        loads.push((h21, f_c2 * e2));
        if H1 > x {
            loads.push((h11, weight(M_P)));
            loads.push((h11, f_c1 * e1));
        }
        if L[0] - H2 > x {
            loads.push((h12, weight(M_B)));
            loads.push((h12, -f_c2 * e2));
        }
    } else if H3 > x {
        loads.push((h21, weight(M_P)));
        loads.push((h21, f_c2 * e2));
    }
    for (r, fl) in loads {
        f += fl;
        m += cross(r - p, fl);
    }
    let phi = b[link].phi;
    let (ex, ey) = (rot(phi, Vector2::x()), rot(phi, Vector2::y()));
    ((f.dot(&ex), -f.dot(&ey), m), (f_c1, f_c2))
}

fn booms(out: &Outcome, r: usize, modes: usize) -> [Boom; 2] {
    let c = |n: &str| out.trajectory.column(n).unwrap()[r];
    let qb = |link: usize| {
        (1..=modes)
            .map(|k| out.trajectory.column(&format!("qb{link}_{k}")).unwrap()[r])
            .collect::<Vec<_>>()
    };
    let (q1, q2) = (c("q1"), c("q2"));
    let b1 = Boom {
        phi: q1,
        o: Vector2::zeros(),
        len: L[0],
        qb: qb(1),
    };
    let o2 = b1.at(L[0]);
    let b2 = Boom {
        phi: q1 + q2,
        o: o2,
        len: L[1],
        qb: qb(2),
    };
    [b1, b2]
}

#[test]
fn stress_crane_at_rest_equals_the_hand_free_body() {
    let mut extra = Vec::new();
    for link in 1..=2 {
        for q in ["N", "V", "M"] {
            extra.extend(grid_names(link, q));
        }
    }
    let out = run(
        &["initial.steady.use=rest", "simulation.t_end=0.01"],
        &extra,
    );
    let b = booms(&out, 0, 3);
    let mut worst = 0.0_f64;
    let mut m_max = 0.0_f64;
    let mut rows = Vec::new();
    for link in 0..2 {
        let n = row(&out, 0, &grid_names(link + 1, "N"));
        let v = row(&out, 0, &grid_names(link + 1, "V"));
        let m = row(&out, 0, &grid_names(link + 1, "M"));
        for j in 0..GRID {
            let x = L[link] * j as f64 / (GRID - 1) as f64;
            let ((nh, vh, mh), fc) = hand(&b, link, x);
            m_max = m_max.max(mh.abs());
            rows.push((link, x, n[j] - nh, v[j] - vh, m[j] - mh, fc));
        }
    }
    for (link, x, dn, dv, dm, fc) in &rows {
        if std::env::var("STRESS_DEBUG").is_ok() {
            eprintln!("{link} {x:.2} {dn:.4e} {dv:.4e} {dm:.4e} {fc:?}");
        }
        worst = worst.max(dn.abs()).max(dv.abs()).max(dm.abs());
        assert!(
            dn.abs().max(dv.abs()).max(dm.abs()) < 1e-6 * m_max,
            "link {} x = {x}: ΔN {dn:e}, ΔV {dv:e}, ΔM {dm:e} (max |M| {m_max:e})",
            link + 1
        );
    }
    let (f_c1, f_c2) = rows[0].5;
    let run_fc1 = out.trajectory.column("F_c1").unwrap()[0];
    let run_fc2 = out.trajectory.column("F_c2").unwrap()[0];
    eprintln!(
        "rest: max |M| {m_max:.6e} N·m, worst difference {worst:.3e} ({:.3e} of max |M|); hand F_c1 {f_c1:.3} N (run {run_fc1:.3}), F_c2 {f_c2:.3} N (run {run_fc2:.3})",
        worst / m_max
    );
    assert!((f_c1 - run_fc1).abs() < 1e-6 * f_c1.abs());
    assert!((f_c2 - run_fc2).abs() < 1e-6 * f_c2.abs());
}

#[test]
fn stress_crane_modal_moment_converges_to_the_summed_one() {
    let mut errors = Vec::new();
    let mut summed_max = Vec::new();
    for modes in [1, 3, 10] {
        let mut extra = Vec::new();
        for link in 1..=2 {
            extra.extend(grid_names(link, "M"));
            extra.extend(grid_names(link, "M_modal"));
        }
        let m1 = format!("parameters.modes1={modes}");
        let m2 = format!("parameters.modes2={modes}");
        let out = run(
            &["initial.steady.use=rest", "simulation.t_end=0.01", &m1, &m2],
            &extra,
        );
        let (mut err, mut scale) = (0.0_f64, 0.0_f64);
        for link in 1..=2 {
            let m = row(&out, 0, &grid_names(link, "M"));
            let mm = row(&out, 0, &grid_names(link, "M_modal"));
            for j in 0..GRID {
                err = err.max((m[j] - mm[j]).abs());
                scale = scale.max(m[j].abs());
            }
        }
        eprintln!(
            "{modes:>2} modes: max |M_modal − M| = {err:.4e} N·m = {:.4} of max |M| ({scale:.6e} N·m)",
            err / scale
        );
        errors.push(err / scale);
        summed_max.push(scale);
    }
    assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
    assert!(errors[2] < 0.1, "{errors:?}");
    // the summed moment hardly depends on the modes (only through the rest deflection)
    for s in &summed_max {
        assert!(
            (s - summed_max[2]).abs() < 1e-3 * summed_max[2],
            "{summed_max:?}"
        );
    }
}

/// The crane's arm, as the model file builds it.
fn arm() -> PlanarArm {
    let beam = |l: f64| {
        Link::beam(l, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(3)
            .unwrap()
    };
    let p = Link::pendulum(6.0, M3).unwrap();
    PlanarArm::with_quadrature(vec![beam(10.0), beam(8.0), p], G, 16).unwrap()
}

#[test]
fn stress_crane_run_satisfies_the_local_equilibrium_at_random_times() {
    let arm = arm();
    let n = arm.n();
    let mut extra: Vec<String> = (0..n).map(|k| format!("crane_arm.udot[{k}]")).collect();
    extra.extend((0..6).map(|k| format!("crane_lump.2.e[{k}]")));
    extra.extend((0..n).map(|k| format!("crane_arm.u[{k}]")));
    let out = run(&["simulation.t_end=2.0"], &extra);
    let c = |name: &str| out.trajectory.column(name).unwrap();
    let names_q = [
        "q1", "q2", "q3", "qb1_1", "qb1_2", "qb1_3", "qb2_1", "qb2_2", "qb2_3",
    ];
    let names_u: Vec<String> = (0..n).map(|k| format!("crane_arm.u[{k}]")).collect();
    let rows = out.trajectory.rows.len();
    let mut seed: u64 = 2024;
    let mut next = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let beta3 = std::f64::consts::PI / 3.0;
    let base = Vector2::new(D0 * beta3.cos(), -D0 * beta3.sin());
    let mut worst = (0.0_f64, 0.0_f64, 0.0_f64);
    for _ in 0..6 {
        let r = 1 + (next() * (rows - 2) as f64) as usize;
        let q: Vec<f64> = names_q.iter().map(|n| c(n)[r]).collect();
        let u: Vec<f64> = names_u.iter().map(|n| c(n)[r]).collect();
        let ud: Vec<f64> = (0..n)
            .map(|k| c(&format!("crane_arm.udot[{k}]"))[r])
            .collect();
        let kin = arm.kinematics(&q);
        let pose = kin.pose();
        let (s11, s12, s21) = (
            arm.station(0, H1).unwrap(),
            arm.station(0, L[0] - H2).unwrap(),
            arm.station(1, H3).unwrap(),
        );
        let e1 = (pose.position(&s11) - base).normalize();
        let e2 = (pose.position(&s21) - pose.position(&s12)).normalize();
        let (f1, f2) = (c("F_c1")[r], c("F_c2")[r]);
        let pf: Vec<f64> = (0..6)
            .map(|k| c(&format!("crane_lump.2.e[{k}]"))[r])
            .collect();
        let loads = vec![
            (&s11, f1 * e1),
            (&s21, f2 * e2),
            (&s12, -f2 * e2),
            (&s11, Vector2::new(pf[0], pf[1])),
            (&s12, Vector2::new(pf[2], pf[3])),
            (&s21, Vector2::new(pf[4], pf[5])),
        ];
        let torques = [0.0, 0.0, -5000.0 * u[2]];
        for link in 0..2 {
            let len = L[link];
            let mut x0 = len * (0.05 + 0.9 * next());
            for pin in [H1, L[0] - H2, H3] {
                if (x0 - pin).abs() < 0.05 {
                    x0 += 0.1;
                }
            }
            let h = 1e-3;
            let grid = SectionGrid::new(&arm, link, &[x0 - h, x0, x0 + h]).unwrap();
            let mut f = grid.forces();
            kin.section_forces_into(&grid, &u, &ud, &loads, &torques, &mut f);
            // the scale: the largest section force and moment along the link at this time
            let full = SectionGrid::new(
                &arm,
                link,
                &(0..=40).map(|j| len * j as f64 / 40.0).collect::<Vec<_>>(),
            )
            .unwrap();
            let mut g = full.forces();
            kin.section_forces_into(&full, &u, &ud, &loads, &torques, &mut g);
            let max = |v: &[f64]| v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            let (sf, sm) = (max(&g.n).max(max(&g.v)) / len, max(&g.m) / len);
            let d = |v: &[f64]| (v[2] - v[0]) / (2.0 * h);
            let (load, mu) = kin.distributed_load(link, x0, &u, &ud);
            let en = (d(&f.n) + load.x).abs() / sf;
            let ev = (d(&f.v) - load.y).abs() / sf;
            let em = (d(&f.m) - (f.v[1] + f.slope[1] * f.n[1] - mu)).abs() / sm;
            worst = (worst.0.max(en), worst.1.max(ev), worst.2.max(em));
            assert!(
                en < 1e-6 && ev < 1e-6 && em < 1e-6,
                "t = {}, link {}, x = {x0}: {en:e} {ev:e} {em:e}",
                c("t")[r],
                link + 1
            );
        }
    }
    eprintln!(
        "crane run, 6 random rows: dN/dx error {:.2e}, dV/dx {:.2e}, dM/dx {:.2e} (of max|force|/L, max|M|/L)",
        worst.0, worst.1, worst.2
    );
}
