//! The knuckle boom crane, `models/knuckle_boom.toml`, against its conventions
//! (`docs/knuckle-boom.md`) and against an independent rigid-body computation:
//!
//! * the initial pressures the file's steady start solves (`[initial.steady]`, Newton on the
//!   model's own equations) are the rigid static balance (`τ_b F + G = 0`, first two rows)
//!   computed three more ways: by the hand-derived formulas the file used to carry, by the
//!   hand-written Lagrange model below and by the manipulator crate's own `τ_b` and `G`;
//!   (the full-rest start, `initial.steady.use = "rest"`, is tested in `steady.rs`);
//! * with 0 modes and rigidly attached lumped masses, t = 0 is a rest state; with flexible
//!   links released undeformed it is not;
//! * a 0-mode run matches [`RigidCrane`]: Lagrange's equations of two rigid booms, the
//!   pendulum and the point masses, with the cylinders, valves, spool lags and controllers of
//!   the docs/knuckle-boom.md, integrated by classical RK4 — pointwise (accelerations from the run's
//!   states and pressures) and over the whole 20 s run; its final pose is the scene's
//!   rigid sanity figures up to the controller's remaining length error;
//! * the energy bookkeeping of the flexible scene closes;
//! * a run at the file's settings agrees with one at rtol 1e-9 on every column.
// Index loops read like the equations (Σ_k A_jk …): `needless_range_loop` is allowed.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::many_single_char_names,
    clippy::needless_range_loop
)]

use bg_manipulator::{LinearActuator, Link, Pin, PlanarArm, PointMass};
use bg_model::Model;
use bg_tests::root;
use bondgraph::Outcome;
use indexmap::IndexMap;
use toml_edit::{value, DocumentMut};

// ---------------------------------------------------------------------------------------
// Loading the scene and its variants

fn scene_text() -> String {
    std::fs::read_to_string(root().join("models/knuckle_boom.toml")).unwrap()
}

/// The scene with `edit` applied to its TOML (the way a user would edit a copy of the file).
fn variant(edit: impl FnOnce(&mut DocumentMut)) -> Model {
    let mut doc: DocumentMut = scene_text().parse().unwrap();
    edit(&mut doc);
    Model::from_text(
        "knuckle_boom.toml (variant)",
        &doc.to_string(),
        &bg_sim::registry(),
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

fn outputs(doc: &mut DocumentMut) -> &mut toml_edit::Table {
    doc["outputs"].as_table_mut().unwrap()
}

/// `modes` per link, lumped masses `lumped` ("springs", "rigid", "none"): exactly the
/// scene switches a user makes with `--set` (see `scene_switches_are_single_sets`).
fn scene(doc: &mut DocumentMut, modes: u32, lumped: &str) {
    doc["parameters"]["modes1"] = value(i64::from(modes));
    doc["parameters"]["modes2"] = value(i64::from(modes));
    doc["elements"]["crane"]["lumped_model"] = value(lumped);
}

/// Each scene switch is one `--set`, with every design-page
/// column still written: the qb columns of modes that are not modelled read 0.
#[test]
fn scene_switches_are_single_sets() {
    for set in [
        &["parameters.modes1=0", "parameters.modes2=0"][..],
        &["parameters.modes1=1", "parameters.modes2=5"][..],
        &["elements.crane.lumped_model=rigid"][..],
        &["elements.crane.lumped_model=none"][..],
    ] {
        let mut m = bg_tests::load("knuckle_boom", set).unwrap_or_else(|e| panic!("{set:?}: {e}"));
        m.settings.t_end = 0.02;
        let out = run(&mut m);
        assert_eq!(out.trajectory.rows.len(), 3, "{set:?}");
        for c in ["qb1_1", "qb1_3", "qb2_2", "rho1_paper", "rho6"] {
            assert!(
                out.trajectory.columns.iter().any(|n| n == c),
                "{set:?}: no column {c}"
            );
        }
        if set[0] == "parameters.modes1=1" {
            assert!(
                col(&out, "qb1_3")
                    .iter()
                    .all(|v| v.abs() < f64::MIN_POSITIVE),
                "an unmodelled mode reads 0"
            );
            assert!(
                col(&out, "qb2_3").iter().any(|v| v.abs() > 1e-12),
                "a modelled mode moves"
            );
        }
    }
}

/// Add the accelerations `udot{k}` (k = 0..n) as columns.
fn with_accelerations(doc: &mut DocumentMut, n: usize) {
    let out = outputs(doc);
    for k in 0..n {
        out.insert(&format!("udot{k}"), value(format!("crane_arm.udot[{k}]")));
    }
}

fn run(model: &mut Model) -> Outcome {
    let out = model.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    eprintln!("{}", out.stats);
    out
}

fn col(out: &Outcome, name: &str) -> Vec<f64> {
    out.trajectory
        .column(name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// max |a − b| / max |b| over a column.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    if scale > 0.0 {
        diff / scale
    } else {
        diff
    }
}

// ---------------------------------------------------------------------------------------
// An independent model of the rigid crane

/// The rigid crane written out by hand from docs/knuckle-boom.md. Coordinates are the absolute
/// chord angles θ = (φ1, φ2, φ3) (φ1 = q1, φ2 = q1 + q2, φ3 = q1 + q2 + q3). Every mass is
/// a point or a uniform rod on body b, at distance s from its joint: its position is
/// `Σ_j a_j e(θ_j)` with a_j = L_j for j < b and a_b = s. So
/// `T = ½ Σ_jk A_jk cos(θ_j − θ_k) θ̇_j θ̇_k` (plus the rods' rotary inertia ρ·I·L),
/// `V = g Σ_j G_j sin θ_j`, and Lagrange's equations are
/// `Σ_k A_jk cos(θ_j − θ_k) θ̈_k = Q_j − Σ_k A_jk sin(θ_j − θ_k) θ̇_k²`,
/// `Q = −g G_j cos θ_j + F_1 ∂l_1/∂θ + F_2 ∂l_2/∂θ + damping`.
struct RigidCrane {
    p: IndexMap<String, f64>,
    /// A_jk, the inertia coefficients.
    a: [[f64; 3]; 3],
    /// G_j, the first moments.
    gm: [f64; 3],
}

/// Cylinder c's state: chamber pressures and spool stroke.
#[derive(Clone, Copy, Debug, Default)]
struct Hyd {
    p_p: f64,
    p_r: f64,
    x_v: f64,
}

/// The whole state: angles, rates, two cylinders.
#[derive(Clone, Copy, Debug, Default)]
struct State {
    th: [f64; 3],
    w: [f64; 3],
    cyl: [Hyd; 2],
}

fn e(th: f64) -> [f64; 2] {
    [th.cos(), th.sin()]
}
fn e_perp(th: f64) -> [f64; 2] {
    [-th.sin(), th.cos()]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Solve a 3×3 system by Gaussian elimination with partial pivoting.
fn solve3(mut m: [[f64; 3]; 3], mut b: [f64; 3]) -> [f64; 3] {
    for c in 0..3 {
        let piv = (c..3)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap();
        m.swap(c, piv);
        b.swap(c, piv);
        for r in c + 1..3 {
            let f = m[r][c] / m[c][c];
            for k in c..3 {
                m[r][k] -= f * m[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 3];
    for r in (0..3).rev() {
        let s: f64 = (r + 1..3).map(|k| m[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / m[r][r];
    }
    x
}

/// regRoot of docs/knuckle-boom.md: Δp/(Δp² + p_tr²)^¼.
fn reg_root(dp: f64, p_tr: f64) -> f64 {
    dp / (dp * dp + p_tr * p_tr).powf(0.25)
}

impl RigidCrane {
    fn new(p: IndexMap<String, f64>) -> Self {
        let l = [p["L1"], p["L2"], p["L3"]];
        let mu = p["rho"] * p["A"];
        let mut a = [[0.0; 3]; 3];
        let mut gm = [0.0; 3];
        let mut point = |b: usize, s: f64, m: f64| {
            let arm = |j: usize| {
                if j < b {
                    l[j]
                } else if j == b {
                    s
                } else {
                    0.0
                }
            };
            for j in 0..3 {
                gm[j] += m * arm(j);
                for k in 0..3 {
                    a[j][k] += m * arm(j) * arm(k);
                }
            }
        };
        // lumped masses, rigidly at their pins, and the payload
        point(0, p["h1"], p["m_p"]);
        point(0, p["L1"] - p["h2"], p["m_b"]);
        point(1, p["h3"], p["m_p"]);
        point(2, l[2], p["m3"]);
        // uniform rods on bodies 0 and 1: ∫ μ a_j a_k ds, plus rotary inertia ρ·I·L
        for b in 0..2 {
            let m = mu * l[b];
            for j in 0..=b {
                let aj = if j < b { l[j] } else { l[b] / 2.0 };
                gm[j] += m * aj;
                for k in 0..=b {
                    a[j][k] += match (j < b, k < b) {
                        (true, true) => m * l[j] * l[k],
                        (true, false) => m * l[j] * l[b] / 2.0,
                        (false, true) => m * l[b] / 2.0 * l[k],
                        (false, false) => m * l[b] * l[b] / 3.0 + p["rho"] * p["I"] * l[b],
                    };
                }
            }
        }
        Self { p, a, gm }
    }

    fn angles(q: [f64; 3]) -> [f64; 3] {
        [q[0], q[0] + q[1], q[0] + q[1] + q[2]]
    }

    /// Cylinder lengths and their gradients ∂l/∂θ.
    fn cylinders(&self, th: [f64; 3]) -> [(f64, [f64; 3]); 2] {
        let p = &self.p;
        let (e1, e2) = (e(th[0]), e(th[1]));
        let b = [p["d0"] * p["beta3"].cos(), -p["d0"] * p["beta3"].sin()];
        let d1 = [p["h1"] * e1[0] - b[0], p["h1"] * e1[1] - b[1]];
        let l1 = dot(d1, d1).sqrt();
        let n1 = [d1[0] / l1, d1[1] / l1];
        let d2 = [
            p["h2"] * e1[0] + p["h3"] * e2[0],
            p["h2"] * e1[1] + p["h3"] * e2[1],
        ];
        let l2 = dot(d2, d2).sqrt();
        let n2 = [d2[0] / l2, d2[1] / l2];
        [
            (l1, [p["h1"] * dot(n1, e_perp(th[0])), 0.0, 0.0]),
            (
                l2,
                [
                    p["h2"] * dot(n2, e_perp(th[0])),
                    p["h3"] * dot(n2, e_perp(th[1])),
                    0.0,
                ],
            ),
        ]
    }

    fn gravity(&self, th: [f64; 3]) -> [f64; 3] {
        let g = self.p["g"];
        [0, 1, 2].map(|j| -g * self.gm[j] * th[j].cos())
    }

    /// Angular accelerations for cylinder forces `f`.
    fn accelerations(&self, th: [f64; 3], w: [f64; 3], f: [f64; 2]) -> [f64; 3] {
        let mut m = [[0.0; 3]; 3];
        let mut rhs = self.gravity(th);
        for (c, (_, grad)) in self.cylinders(th).iter().enumerate() {
            for j in 0..3 {
                rhs[j] += f[c] * grad[j];
            }
        }
        let tq3 = -self.p["r_p"] * (w[2] - w[1]); // damping on q3 = θ3 − θ2
        rhs[2] += tq3;
        rhs[1] -= tq3;
        for j in 0..3 {
            for k in 0..3 {
                m[j][k] = self.a[j][k] * (th[j] - th[k]).cos();
                rhs[j] -= self.a[j][k] * (th[j] - th[k]).sin() * w[k] * w[k];
            }
        }
        solve3(m, rhs)
    }

    /// The cylinder forces that hold the crane at rest in the pose `q` with the pendulum
    /// hanging: rows q1 and q2 of the static balance (generalized forces in q are
    /// Q_q1 = Q_θ1 + Q_θ2 + Q_θ3, Q_q2 = Q_θ2 + Q_θ3).
    fn hold_forces(&self, q: [f64; 3]) -> [f64; 2] {
        let th = Self::angles(q);
        let g = self.gravity(th);
        let cyl = self.cylinders(th);
        let rows = |v: [f64; 3]| [v[0] + v[1] + v[2], v[1] + v[2]];
        let (gq, t1, t2) = (rows(g), rows(cyl[0].1), rows(cyl[1].1));
        // [t1 t2] F = −gq
        let det = t1[0] * t2[1] - t2[0] * t1[1];
        [
            (-gq[0] * t2[1] + t2[0] * gq[1]) / det,
            (-t1[0] * gq[1] + gq[0] * t1[1]) / det,
        ]
    }

    fn force(&self, h: &Hyd) -> f64 {
        self.p["A_p"] * h.p_p - self.p["A_r"] * h.p_r
    }

    /// Valve flows into the piston and rod sides (eqs. 29–30 with regRoot).
    fn valve(&self, h: &Hyd) -> (f64, f64) {
        let p = &self.p;
        let (alpha, ps, pt, ptr) = (p["alpha"], p["P_s"], p["P_T"], p["p_tr"]);
        let x = h.x_v.clamp(-1.0, 1.0);
        if x >= 0.0 {
            (
                alpha * x * reg_root(ps - h.p_p, ptr),
                -alpha * x * reg_root(h.p_r - pt, ptr),
            )
        } else {
            (
                alpha * x * reg_root(h.p_p - pt, ptr),
                -alpha * x * reg_root(ps - h.p_r, ptr),
            )
        }
    }

    fn initial(&self) -> State {
        let p = &self.p;
        let q0 = [p["q1_0"], p["q2_0"], p["q3_0"]];
        let f = self.hold_forces(q0);
        let hold = |f: f64| {
            let (ap, ar, pre) = (p["A_p"], p["A_r"], p["p_pre"]);
            if f >= 0.0 {
                ((f + ar * pre) / ap, pre)
            } else {
                (pre, (ap * pre - f) / ar)
            }
        };
        let mut s = State {
            th: Self::angles(q0),
            ..State::default()
        };
        for c in 0..2 {
            let (pp, pr) = hold(f[c]);
            s.cyl[c] = Hyd {
                p_p: pp,
                p_r: pr,
                x_v: 0.0,
            };
        }
        s
    }

    fn derivative(&self, s: &State) -> State {
        let p = &self.p;
        let f = [self.force(&s.cyl[0]), self.force(&s.cyl[1])];
        let dw = self.accelerations(s.th, s.w, f);
        let cyl = self.cylinders(s.th);
        let mut d = State {
            th: s.w,
            w: dw,
            ..State::default()
        };
        for c in 0..2 {
            let h = &s.cyl[c];
            let (l, grad) = cyl[c];
            let ldot: f64 = (0..3).map(|j| grad[j] * s.w[j]).sum();
            let st = l - p["l0"];
            let (vp, vr) = (p["A_p"] * (p["l_p0"] + st), p["A_r"] * (p["l_r0"] - st));
            let (qa, qb) = self.valve(h);
            let ql = (h.p_p - h.p_r) / p["R_l"];
            let kv = if c == 0 { p["K_v1"] } else { p["K_v2"] };
            let cmd = (kv * (p["l_d"] - l)).clamp(-1.0, 1.0);
            d.cyl[c] = Hyd {
                p_p: p["beta"] / vp * (qa - ql - p["A_p"] * ldot),
                p_r: p["beta"] / vr * (qb + ql + p["A_r"] * ldot),
                x_v: (cmd - h.x_v) / p["tau_v"],
            };
        }
        d
    }
}

fn axpy(s: &State, h: f64, d: &State) -> State {
    let mut o = *s;
    for j in 0..3 {
        o.th[j] += h * d.th[j];
        o.w[j] += h * d.w[j];
    }
    for c in 0..2 {
        o.cyl[c].p_p += h * d.cyl[c].p_p;
        o.cyl[c].p_r += h * d.cyl[c].p_r;
        o.cyl[c].x_v += h * d.cyl[c].x_v;
    }
    o
}

/// Classical RK4 with step `h`, sampled every `every` steps.
fn integrate(crane: &RigidCrane, t_end: f64, h: f64, every: usize) -> Vec<(f64, State)> {
    let mut s = crane.initial();
    let n = (t_end / h).round() as usize;
    let mut out = vec![(0.0, s)];
    for k in 1..=n {
        let k1 = crane.derivative(&s);
        let k2 = crane.derivative(&axpy(&s, h / 2.0, &k1));
        let k3 = crane.derivative(&axpy(&s, h / 2.0, &k2));
        let k4 = crane.derivative(&axpy(&s, h, &k3));
        let sum = axpy(&axpy(&axpy(&k1, 2.0, &k2), 2.0, &k3), 1.0, &k4);
        s = axpy(&s, h / 6.0, &sum);
        if k % every == 0 {
            out.push((k as f64 * h, s));
        }
    }
    out
}

fn rigid_model(rtol: f64) -> Model {
    let mut m = variant(|d| {
        scene(d, 0, "rigid");
        with_accelerations(d, 3);
    });
    m.settings.rtol = rtol;
    m.settings.atol = rtol;
    m
}

// ---------------------------------------------------------------------------------------
// The tests

/// The hold forces docs/knuckle-boom.md derived by hand (the formulas `models/knuckle_boom.toml`
/// carried before its steady start): g·Σ / (∂l/∂q), Σ the first moments of the masses
/// outboard of each joint.
fn hand_derived_hold_forces(p: &IndexMap<String, f64>) -> (f64, f64) {
    let (phi1, phi2) = (p["q1_0"], p["q1_0"] + p["q2_0"]);
    let phi3 = phi2 + p["q3_0"];
    let (m_1, m_2) = (p["rho"] * p["A"] * p["L1"], p["rho"] * p["A"] * p["L2"]);
    let x_j2 = p["L1"] * phi1.cos();
    let x_j3 = x_j2 + p["L2"] * phi2.cos();
    let x_m3 = x_j3 + p["L3"] * phi3.cos();
    let s2 = m_2 * p["L2"] / 2.0 * phi2.cos()
        + p["m3"] * (x_m3 - x_j2)
        + p["m_p"] * p["h3"] * phi2.cos();
    let s1 = m_1 * p["L1"] / 2.0 * phi1.cos()
        + m_2 * (x_j2 + p["L2"] / 2.0 * phi2.cos())
        + p["m3"] * x_m3
        + p["m_p"] * p["h1"] * phi1.cos()
        + p["m_b"] * (p["L1"] - p["h2"]) * phi1.cos()
        + p["m_p"] * (x_j2 + p["h3"] * phi2.cos());
    let (h1, h2, h3, d0) = (p["h1"], p["h2"], p["h3"], p["d0"]);
    let l1 = (h1 * h1 + d0 * d0 - 2.0 * h1 * d0 * (p["q1_0"] + p["beta3"]).cos()).sqrt();
    let l2 = (h2 * h2 + h3 * h3 + 2.0 * h2 * h3 * p["q2_0"].cos()).sqrt();
    (
        p["g"] * s1 / (h1 * d0 * (p["q1_0"] + p["beta3"]).sin() / l1),
        p["g"] * s2 / (-h2 * h3 * p["q2_0"].sin() / l2),
    )
}

fn state(model: &Model, name: &str) -> f64 {
    let i = model
        .equations
        .states()
        .iter()
        .position(|s| s.name == name)
        .unwrap_or_else(|| panic!("no state {name}"));
    model.x0[i]
}

/// The file's steady start solves the initial pressures on the model's own equations; they
/// equal the scene's hand-derived hold pressures to 1e-6 relative (measured: 5e-13),
/// and the forces they give are the rigid static balance computed by the hand-written model
/// and by the manipulator crate's own τ_b and G: about +207 kN and −80.6 kN.
#[test]
fn hold_forces_are_the_rigid_static_balance() {
    let model = variant(|_| {});
    let p = model.parameters.clone();
    let report = model
        .steady
        .as_ref()
        .expect("the file asks for a steady start");
    eprintln!("{report}");
    let (a_p, a_r, pre) = (p["A_p"], p["A_r"], p["p_pre"]);
    let (pp1, pr1) = (
        state(&model, "cyl1_chamber_p.p"),
        state(&model, "cyl1_chamber_r.p"),
    );
    let (pp2, pr2) = (
        state(&model, "cyl2_chamber_p.p"),
        state(&model, "cyl2_chamber_r.p"),
    );
    assert!(
        (pr1 - pre).abs() < 1e-9 && (pp2 - pre).abs() < 1e-9,
        "the less loaded chambers stay at p_pre"
    );
    let (h1, h2) = hand_derived_hold_forces(&p);
    // the scene's rule: the less loaded chamber at p_pre
    let (want_p1, want_r2) = ((h1 + a_r * pre) / a_p, (a_p * pre - h2) / a_r);
    let (e1, e2) = ((pp1 / want_p1 - 1.0).abs(), (pr2 / want_r2 - 1.0).abs());
    eprintln!("solved P_p1 = {pp1:.6} Pa (hand-derived {want_p1:.6}, rel. {e1:.1e}), P_r2 = {pr2:.6} Pa ({want_r2:.6}, rel. {e2:.1e})");
    assert!(e1 < 1e-6 && e2 < 1e-6, "{e1:e} {e2:e}");
    let (f1, f2) = (a_p * pp1 - a_r * pr1, a_p * pp2 - a_r * pr2);
    eprintln!("solved: F1 = {f1:.6} N, F2 = {f2:.6} N");

    let crane = RigidCrane::new(p.clone());
    let mine = crane.hold_forces([p["q1_0"], p["q2_0"], p["q3_0"]]);
    assert!((mine[0] - f1).abs() <= 1e-9 * f1.abs(), "{mine:?} vs {f1}");
    assert!((mine[1] - f2).abs() <= 1e-9 * f2.abs(), "{mine:?} vs {f2}");
    assert!((h1 - f1).abs() <= 1e-9 * f1.abs() && (h2 - f2).abs() <= 1e-9 * f2.abs());

    // the manipulator crate: first two rows of τ_b F + G = 0
    let beam = |l: f64| {
        Link::beam(l, p["E"], p["rho"], p["A"], p["I"])
            .unwrap()
            .with_sine_modes(3)
            .unwrap()
    };
    let pm = |x: f64, mass: f64| PointMass {
        x,
        mass,
        inertia: 0.0,
    };
    let link1 = beam(p["L1"])
        .with_point_mass(pm(p["h1"], p["m_p"]))
        .unwrap()
        .with_point_mass(pm(p["L1"] - p["h2"], p["m_b"]))
        .unwrap();
    let link2 = beam(p["L2"])
        .with_point_mass(pm(p["h3"], p["m_p"]))
        .unwrap();
    let arm = PlanarArm::new(
        vec![link1, link2, Link::pendulum(p["L3"], p["m3"]).unwrap()],
        p["g"],
    )
    .unwrap();
    let mut q = vec![0.0; arm.n()];
    q[..3].copy_from_slice(&[p["q1_0"], p["q2_0"], p["q3_0"]]);
    let g = arm.kinematics(&q).gravity_forces();
    let acts = [
        LinearActuator::new(
            Pin::ground(p["d0"] * p["beta3"].cos(), -p["d0"] * p["beta3"].sin()),
            Pin::on_link(0, p["h1"]),
        ),
        LinearActuator::new(Pin::on_link(0, p["L1"] - p["h2"]), Pin::on_link(1, p["h3"])),
    ];
    let tb = arm.actuator_jacobian(&arm.pose(&q), &acts);
    let det = tb[(0, 0)] * tb[(1, 1)] - tb[(0, 1)] * tb[(1, 0)];
    let c1 = (-g[0] * tb[(1, 1)] + tb[(0, 1)] * g[1]) / det;
    let c2 = (-tb[(0, 0)] * g[1] + g[0] * tb[(1, 0)]) / det;
    assert!((c1 - f1).abs() <= 1e-6 * f1.abs(), "{c1} vs {f1}");
    assert!((c2 - f2).abs() <= 1e-6 * f2.abs(), "{c2} vs {f2}");
    // the pendulum hangs: its row of the balance holds by itself
    assert!((g[2] + tb[(2, 0)] * c1 + tb[(2, 1)] * c2).abs() < 1e-6);

    assert!((f1 - 207.07e3).abs() < 10.0 && (f2 + 80.556e3).abs() < 10.0);
}

/// With 0 modes and the lumped masses rigidly attached, the initial pressures hold the
/// crane: every acceleration at t = 0 is below 1e-9 (SI), and the pendulum pivot carries
/// the payload (ρ5 = −m3·g, ρ6 = 0). With flexible links released undeformed it is not a
/// rest state.
#[test]
fn initial_pressures_make_the_rigid_crane_a_rest_state() {
    let mut m = rigid_model(1e-6);
    m.settings.t_end = 1e-3;
    m.settings.dt_out = 1e-3;
    let out = run(&mut m);
    let m3g = m.parameters["m3"] * m.parameters["g"];
    for k in 0..3 {
        let a = col(&out, &format!("udot{k}"))[0];
        eprintln!("rigid: udot{k}(0) = {a:e}");
        assert!(a.abs() < 1e-9, "udot{k}(0) = {a:e}");
    }
    for c in ["ldot1", "ldot2", "u1", "u2", "u3"] {
        assert!(col(&out, c)[0].abs() < 1e-12);
    }
    assert!((col(&out, "rho5")[0] + m3g).abs() < 1e-6 * m3g);
    assert!(col(&out, "rho6")[0].abs() < 1e-6);

    let mut m = variant(|d| {
        scene(d, 3, "rigid");
        with_accelerations(d, 9);
    });
    m.settings.t_end = 1e-3;
    m.settings.dt_out = 1e-3;
    let out = run(&mut m);
    let modal = (3..9)
        .map(|k| col(&out, &format!("udot{k}"))[0].abs())
        .fold(0.0, f64::max);
    eprintln!("flexible, undeformed: max modal acceleration at t = 0: {modal:.3} m/s²");
    assert!(modal > 1.0, "{modal}");
}

/// A 0-mode run (lumped masses rigid) against the hand-written rigid crane: the run's
/// accelerations at every row equal the Lagrange model's for the run's own state and
/// chamber pressures; integrated on its own by RK4, the Lagrange model follows the run for
/// 20 s; and the run ends at the scene's rigid sanity pose.
#[test]
fn rigid_crane_matches_an_independent_lagrange_model() {
    let mut m = rigid_model(1e-9);
    let out = run(&mut m);
    let crane = RigidCrane::new(m.parameters.clone());
    let p = &crane.p;

    // 1. pointwise: accelerations from the run's state and pressures
    let c = |n: &str| col(&out, n);
    let (q1, q2, q3) = (c("q1"), c("q2"), c("q3"));
    let (u1, u2, u3) = (c("u1"), c("u2"), c("u3"));
    let (pp1, pr1, pp2, pr2) = (c("p_p1"), c("p_r1"), c("p_p2"), c("p_r2"));
    let udot: Vec<Vec<f64>> = (0..3).map(|k| c(&format!("udot{k}"))).collect();
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    for i in 0..q1.len() {
        let th = RigidCrane::angles([q1[i], q2[i], q3[i]]);
        let w = RigidCrane::angles([u1[i], u2[i], u3[i]]);
        let f = [
            p["A_p"] * pp1[i] - p["A_r"] * pr1[i],
            p["A_p"] * pp2[i] - p["A_r"] * pr2[i],
        ];
        let a = crane.accelerations(th, w, f);
        let qdd = [a[0], a[1] - a[0], a[2] - a[1]];
        for k in 0..3 {
            worst = worst.max((qdd[k] - udot[k][i]).abs());
            scale = scale.max(udot[k][i].abs());
        }
    }
    eprintln!("accelerations: max |Δ| = {worst:.3e} rad/s² of max {scale:.3e}");
    assert!(worst <= 1e-9 * scale, "{worst:e} of {scale:e}");

    // 2. the whole run: RK4 at h = 5e-5 s, sampled at the run's 0.01 s rows
    let mine = integrate(&crane, m.settings.t_end, 5e-5, 200);
    assert_eq!(mine.len(), q1.len());
    let pick = |f: &dyn Fn(&RigidCrane, &State) -> f64| -> Vec<f64> {
        mine.iter().map(|(_, s)| f(&crane, s)).collect()
    };
    let columns: Vec<(&str, Vec<f64>)> = vec![
        ("q1", pick(&|_, s| s.th[0])),
        ("q2", pick(&|_, s| s.th[1] - s.th[0])),
        ("q3", pick(&|_, s| s.th[2] - s.th[1])),
        ("u1", pick(&|_, s| s.w[0])),
        ("u2", pick(&|_, s| s.w[1] - s.w[0])),
        ("u3", pick(&|_, s| s.w[2] - s.w[1])),
        ("l1", pick(&|c, s| c.cylinders(s.th)[0].0)),
        ("l2", pick(&|c, s| c.cylinders(s.th)[1].0)),
        ("p_p1", pick(&|_, s| s.cyl[0].p_p)),
        ("p_r1", pick(&|_, s| s.cyl[0].p_r)),
        ("p_p2", pick(&|_, s| s.cyl[1].p_p)),
        ("p_r2", pick(&|_, s| s.cyl[1].p_r)),
        ("Q_p1", pick(&|c, s| c.valve(&s.cyl[0]).0)),
        ("Q_r1", pick(&|c, s| c.valve(&s.cyl[0]).1)),
        ("Q_p2", pick(&|c, s| c.valve(&s.cyl[1]).0)),
        ("Q_r2", pick(&|c, s| c.valve(&s.cyl[1]).1)),
        ("x_v1", pick(&|_, s| s.cyl[0].x_v)),
        ("x_v2", pick(&|_, s| s.cyl[1].x_v)),
        ("F_c1", pick(&|c, s| c.force(&s.cyl[0]))),
        ("F_c2", pick(&|c, s| c.force(&s.cyl[1]))),
    ];
    let mut worst = (0.0, "");
    for (name, v) in &columns {
        let d = rel_diff(&col(&out, name), v);
        eprintln!("rigid vs Lagrange/RK4: {name:<5} {d:.2e}");
        if d > worst.0 {
            worst = (d, name);
        }
    }
    assert!(worst.0 < 2e-5, "{worst:?}");

    // 3. the final pose: rigid geometry of the final lengths, and the sanity figures
    let last = q1.len() - 1;
    let (l1, l2) = (col(&out, "l1")[last], col(&out, "l2")[last]);
    let q1_of = |l: f64| {
        ((p["h1"].powi(2) + p["d0"].powi(2) - l * l) / (2.0 * p["h1"] * p["d0"])).acos()
            - p["beta3"]
    };
    let q2_of =
        |l: f64| -((l * l - p["h2"].powi(2) - p["h3"].powi(2)) / (2.0 * p["h2"] * p["h3"])).acos();
    assert!((q1[last] - q1_of(l1)).abs() < 1e-9);
    assert!((q2[last] - q2_of(l2)).abs() < 1e-9);
    assert!((q1_of(6.0).to_degrees() - 57.28).abs() < 0.005);
    assert!((q2_of(6.0).to_degrees() + 62.72).abs() < 0.005);
    let (e1, e2) = (l1 - p["l_d"], l2 - p["l_d"]);
    eprintln!(
        "final: l1 − 6 = {e1:.3e} m, l2 − 6 = {e2:.3e} m; q1 = {:.4}°, q2 = {:.4}°",
        q1[last].to_degrees(),
        q2[last].to_degrees()
    );
    assert!(e1.abs() < 2.5e-3 && e2.abs() < 2.5e-3);
    // so the pose is the sanity figures' up to the length error: |dq/dl| ≤ 0.6 rad/m here
    // (dq1/dl1 = l1/(h1·d0·sin(q1 + β3)) = 0.56, dq2/dl2 = l2/(h2·h3·sin|q2|) = 0.28)
    assert!((q1[last] - q1_of(6.0)).abs() <= 0.6 * e1.abs() + 1e-9);
    assert!((q2[last] - q2_of(6.0)).abs() <= 0.6 * e2.abs() + 1e-9);

    // the other sanity figures, from the hand-written model: holding the payload in the
    // final pose takes F_c1 ≈ 512 kN, F_c2 ≈ 260 kN; it hangs near x = 13.37 m
    let (qf1, qf2) = (q1_of(6.0), q2_of(6.0));
    let qf = [qf1, qf2, -std::f64::consts::FRAC_PI_2 - qf1 - qf2];
    let f = crane.hold_forces(qf);
    let th = RigidCrane::angles(qf);
    let x3 = p["L1"] * th[0].cos() + p["L2"] * th[1].cos() + p["L3"] * th[2].cos();
    eprintln!(
        "final pose: F1 = {:.1} N, F2 = {:.1} N, payload x = {x3:.4} m",
        f[0], f[1]
    );
    assert!((f[0] - 512.2e3).abs() < 0.5e3 && (f[1] - 260.1e3).abs() < 0.5e3);
    assert!((x3 - 13.37).abs() < 0.005);
}

/// The energy bookkeeping of the flexible scene (lumped masses on springs) over 20 s:
/// the hydraulic energy the valves deliver into the cylinder lines equals the change of the
/// mechanical energy (arm T + V, lumped masses' kinetic, spring and gravity energy) plus
/// the dissipation (modal and pendulum damping, lumped dampers, internal leakage) plus the
/// work of compressing the oil. Powers are read every 1 ms and integrated by Simpson's rule
/// on either side of the damping switch.
#[test]
fn energy_bookkeeping_closes() {
    let mut m = variant(|d| {
        let out = outputs(d);
        let mut add = |k: String, v: String| {
            out.insert(&k, value(v));
        };
        for c in 1..=2 {
            for b in ["b_va", "b_vb", "b_la", "b_lb", "b_cp", "b_cr"] {
                add(format!("P{c}_{b}"), format!("cyl{c}_{b}.P"));
            }
        }
        add("P_damper".into(), "crane_b_damper.P".into());
        add("P_grav".into(), "crane_b_gravity.P".into());
        for k in 0..6 {
            add(format!("pm{k}"), format!("crane_masses.p[{k}]"));
            add(format!("xs{k}"), format!("crane_spring.q[{k}]"));
        }
        for k in 0..9 {
            add(format!("ua{k}"), format!("crane_arm.u[{k}]"));
        }
    });
    m.settings.dt_out = 1e-3;
    let out = run(&mut m);
    let p = m.parameters.clone();
    let rows = &out.trajectory;
    let cols: IndexMap<String, Vec<f64>> = rows
        .columns
        .iter()
        .map(|c| (c.clone(), col(&out, c)))
        .collect();
    let v = |n: &str, i: usize| cols[n][i];
    let masses = [p["m_p"], p["m_p"], p["m_b"], p["m_b"], p["m_p"], p["m_p"]];
    let mech = |i: usize| {
        v("T", i)
            + v("V", i)
            + (0..6)
                .map(|k| v(&format!("pm{k}"), i).powi(2) / (2.0 * masses[k]))
                .sum::<f64>()
            + 0.5 * p["k_c"] * (0..6).map(|k| v(&format!("xs{k}"), i).powi(2)).sum::<f64>()
    };
    // net power: hydraulic in, plus gravity's work on the lumped masses, less dissipation
    // and oil compression. The R-field's is D·u·u with r_e of the side of the switch.
    let net = |i: usize, r_e: f64| {
        let mut s = 0.0;
        for c in 1..=2 {
            let w = |b: &str| v(&format!("P{c}_{b}"), i);
            s += w("b_va") + w("b_vb"); // valves into the lines
            s -= w("b_la") - w("b_lb"); // internal leakage
            s -= w("b_cp") + w("b_cr"); // oil compression
        }
        let modal: f64 = (3..9).map(|k| v(&format!("ua{k}"), i).powi(2)).sum();
        s - p["r_p"] * v("ua2", i).powi(2) - r_e * modal - v("P_damper", i) + v("P_grav", i)
    };
    let t = &cols["t"];
    let switch = t
        .iter()
        .position(|&x| (x - p["t_switch"]).abs() < 1e-9)
        .unwrap();
    let e0 = mech(0);
    let (mut w, mut worst, mut w_hyd_max) = (0.0, 0.0_f64, 0.0_f64);
    let mut w_hyd = 0.0;
    for (a, b, r_e) in [(0, switch, p["r_e"]), (switch, t.len() - 1, 0.0)] {
        assert_eq!((b - a) % 2, 0);
        for j in (a..b).step_by(2) {
            let h = t[j + 1] - t[j];
            w += h / 3.0 * (net(j, r_e) + 4.0 * net(j + 1, r_e) + net(j + 2, r_e));
            let hyd = |i: usize| {
                (1..=2)
                    .map(|c| v(&format!("P{c}_b_va"), i) + v(&format!("P{c}_b_vb"), i))
                    .sum::<f64>()
            };
            w_hyd += h / 3.0 * (hyd(j) + 4.0 * hyd(j + 1) + hyd(j + 2));
            w_hyd_max = w_hyd_max.max(w_hyd.abs());
            worst = worst.max((w - (mech(j + 2) - e0)).abs());
        }
    }
    eprintln!(
        "energy: hydraulic {w_hyd:.6e} J delivered, mechanical {:.6e} J gained; \
         max |imbalance| {worst:.3e} J = {:.2e} of it",
        mech(t.len() - 1) - e0,
        worst / w_hyd_max
    );
    assert!(worst < 1e-6 * w_hyd_max, "{worst:e} J of {w_hyd_max:e} J");
}

/// The file's settings (radau5 at rtol 1e-4) against rtol 1e-9 over the full 20 s flexible
/// run: every column agrees to 1e-4 of its largest magnitude (worst measured: qb2_3, 7.8e-5).
#[test]
fn file_settings_agree_with_rtol_1e9_on_every_column() {
    let mut coarse = variant(|_| {});
    let mut fine = variant(|_| {});
    fine.settings.rtol = 1e-9;
    fine.settings.atol = 1e-9;
    let (a, b) = (run(&mut coarse), run(&mut fine));
    assert_eq!(a.trajectory.columns, b.trajectory.columns);
    assert_eq!(a.trajectory.rows.len(), 2001);
    let mut diffs: Vec<(f64, String)> = a
        .trajectory
        .columns
        .iter()
        .map(|c| (rel_diff(&col(&a, c), &col(&b, c)), c.clone()))
        .collect();
    diffs.sort_by(|x, y| y.0.total_cmp(&x.0));
    eprintln!(
        "file settings vs rtol 1e-9, worst columns: {:?}",
        &diffs[..5]
    );
    assert!(diffs[0].0 < 1e-4, "{:?}", diffs[0]);
}

/// The scene switches: modes per link 0–10, lumped masses on springs, rigid or left out
/// (the steady start follows: its `[*]` patterns name no lumped-mass state when there is
/// none, so the rigid crane still starts at rest).
#[test]
fn scene_switches_load_and_run() {
    for (modes, lumped) in [(0, "none"), (1, "springs"), (2, "rigid"), (10, "springs")] {
        let mut m = variant(|d| {
            scene(d, modes, lumped);
            with_accelerations(d, 3 + 2 * modes as usize);
        });
        m.settings.t_end = 0.02;
        let out = run(&mut m);
        assert_eq!(out.trajectory.rows.len(), 3);
        if modes >= 1 {
            let w = col(&out, "w1_mid")[2];
            assert!(w > 1e-4, "{modes} modes, {lumped}: w1_mid = {w}");
        }
        if modes == 0 {
            for k in 0..3 {
                let a = col(&out, &format!("udot{k}"))[0];
                assert!(a.abs() < 1e-9, "{lumped}: udot{k}(0) = {a:e}");
            }
        }
    }
}

/// The result columns of docs/knuckle-boom.md, named exactly as there, every 0.01 s.
#[test]
fn the_run_writes_the_design_page_columns() {
    let m = variant(|_| {});
    let names: Vec<&str> = m.outputs.iter().map(|o| o.name.as_str()).collect();
    for c in [
        "q1", "q2", "q3", "qb1_1", "qb1_2", "qb1_3", "qb2_1", "qb2_2", "qb2_3", "u1", "u2", "u3",
        "l1", "l2", "ldot1", "ldot2", "p_p1", "p_r1", "p_p2", "p_r2", "Q_p1", "Q_r1", "Q_p2",
        "Q_r2", "x_v1", "x_v2", "F_c1", "F_c2", "x_e1", "y_e1", "x_e2", "y_e2", "w1_mid", "w2_mid",
        "rho1", "rho2", "rho3", "rho4", "rho5", "rho6",
    ] {
        assert!(names.contains(&c), "missing column {c}");
    }
    assert!((m.settings.t_end - 20.0).abs() < 1e-12);
    // one event, at t_switch (event times are numbers, so the parameter is kept equal)
    let events = m.events().unwrap();
    assert_eq!(events.len(), 1);
    assert!((events[0].t - m.parameters["t_switch"]).abs() < 1e-15);
    assert!((m.settings.dt_out - 0.01).abs() < 1e-15);
    // the scene's areas and the retracted geometry
    let p = &m.parameters;
    assert!((p["A_p"] - 0.045_238_9).abs() < 1e-7);
    assert!((p["A_r"] - 0.042_411_5).abs() < 1e-7);
    assert!((p["l1_0"] - 13f64.sqrt()).abs() < 1e-12 && (p["l2_0"] - 13f64.sqrt()).abs() < 1e-12);
    assert!((p["s_max"] - 2.7).abs() < 1e-12);
}

/// Issue 24, item 2: a cylinder 0.54 m longer than the distance between its pins in the
/// initial pose cannot be assembled; the load refuses it (it ran before), naming the
/// cylinder, both lengths, the difference and the fix.
#[test]
fn a_cylinder_that_does_not_fit_its_pins_is_refused() {
    let text = scene_text();
    let from = r#"s0 = "l1_0 - l0""#;
    assert!(text.contains(from));
    let bad = text.replacen(from, r#"s0 = "l1_0 - l0 + 0.54""#, 1);
    let e = Model::from_text("kb.toml", &bad, &bg_sim::registry(), &[]).unwrap_err();
    assert_eq!(e.kind, bg_model::ErrorKind::BadParameter, "{e}");
    assert_eq!(e.element.as_deref(), Some("cyl1"), "{e}");
    let l_pins = 13f64.sqrt();
    for part in [
        "cannot be assembled".to_owned(),
        format!("{:.6} m long", l_pins + 0.54),
        format!("{l_pins:.6} m apart"),
        "differ by 0.540000 m".to_owned(),
    ] {
        assert!(e.message.contains(&part), "{part}: {e}");
    }
    assert!(
        e.hint
            .as_deref()
            .unwrap_or("")
            .contains(&format!("s0 = \"{l_pins:.6} - l0\"")),
        "{e}"
    );
    // 0.5 mm off is within the tolerance (1 mm + 1e-6 of the length) and loads
    let near = text.replacen(from, r#"s0 = "l1_0 - l0 + 0.0005""#, 1);
    Model::from_text("kb.toml", &near, &bg_sim::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
}
