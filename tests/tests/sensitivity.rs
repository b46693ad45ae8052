//! Forward sensitivities (`Model::sensitivities`, docs/sensitivity.md) against two
//! independent references: the closed form of the mass–spring–damper, differentiated by
//! forward-mode duals; and central differences of whole runs at rtol 1e-10, on the
//! mass–spring–damper, the lift circuit and the knuckle-boom crane (with its steady start
//! and its event at 0.5 s).
//!
//! Agreement is measured per (output, parameter) pair against the pair's scale: the larger
//! of the reference's largest |dy/dp| over the run and max|y|/|p| (the scale of a normalised
//! sensitivity p/max|y|·dy/dp, the ranking `bg-sim sensitivity` prints): an error below
//! 10⁻⁴ of it moves no normalised sensitivity by more than 10⁻⁴.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{Model, Sensitivities};

fn load(name: &str, set: &[&str]) -> Model {
    bg_tests::load(name, set).unwrap()
}

/// Rows of a plain run with `set` (outputs without t), row-major.
fn run_rows(name: &str, set: &[String]) -> Vec<Vec<f64>> {
    let refs: Vec<&str> = set.iter().map(String::as_str).collect();
    let mut m = load(name, &refs);
    let out = m.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    out.trajectory.rows
}

/// The largest error of `s` against central differences of whole runs, relative to each
/// pair's scale, over every output, parameter and row; with the key of each parameter.
fn worst_against_runs(name: &str, base: &[&str], s: &Sensitivities, keys: &[&str]) -> f64 {
    let m = s.outputs.len();
    let np = s.params.len();
    let mut worst = 0.0f64;
    for (k, key) in keys.iter().enumerate() {
        let p = s.values[k];
        let d = 1e-4 * p.abs().max(1e-3);
        let with = |v: f64| {
            let mut set: Vec<String> = base.iter().map(|x| (*x).to_owned()).collect();
            set.push(format!("{key}={v:?}"));
            run_rows(name, &set)
        };
        let (plus, minus) = (with(p + d), with(p - d));
        assert_eq!(plus.len(), s.t.len());
        for j in 0..m {
            let fd: Vec<f64> = (0..s.t.len())
                .map(|r| (plus[r][j + 1] - minus[r][j + 1]) / (2.0 * d))
                .collect();
            let ymax = (0..s.t.len()).fold(0.0f64, |a, r| a.max(s.y[r * m + j].abs()));
            let scale = fd
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()))
                .max(ymax / p.abs().max(1e-3))
                .max(1e-300);
            for (r, f) in fd.iter().enumerate() {
                let e = (s.dy_dp[(r * m + j) * np + k] - f).abs() / scale;
                if e > worst {
                    worst = e;
                    eprintln!(
                        "{name}: d{}/d{} at t = {}: {} vs runs {} (scale {scale:e}): {e:e}",
                        s.outputs[j],
                        s.params[k],
                        s.t[r],
                        s.dy_dp[(r * m + j) * np + k],
                        f
                    );
                }
            }
        }
    }
    worst
}

/// A forward-mode dual number, for the closed form's derivatives.
#[derive(Clone, Copy, Debug)]
struct D(f64, f64);
impl std::ops::Add for D {
    type Output = D;
    fn add(self, o: D) -> D {
        D(self.0 + o.0, self.1 + o.1)
    }
}
impl std::ops::Sub for D {
    type Output = D;
    fn sub(self, o: D) -> D {
        D(self.0 - o.0, self.1 - o.1)
    }
}
impl std::ops::Mul for D {
    type Output = D;
    fn mul(self, o: D) -> D {
        D(self.0 * o.0, self.1 * o.0 + self.0 * o.1)
    }
}
impl std::ops::Div for D {
    type Output = D;
    fn div(self, o: D) -> D {
        D(self.0 / o.0, (self.1 * o.0 - self.0 * o.1) / (o.0 * o.0))
    }
}
impl D {
    fn c(v: f64) -> D {
        D(v, 0.0)
    }
    fn sqrt(self) -> D {
        let r = self.0.sqrt();
        D(r, self.1 / (2.0 * r))
    }
    fn exp(self) -> D {
        let e = self.0.exp();
        D(e, self.1 * e)
    }
    fn sin(self) -> D {
        D(self.0.sin(), self.1 * self.0.cos())
    }
    fn cos(self) -> D {
        D(self.0.cos(), -self.1 * self.0.sin())
    }
}

/// x(t) of the free mass–spring–damper (the model's own [[check]] formula).
fn msd_x(t: f64, m: D, k: D, c: D, x0: D) -> D {
    let wn = (k / m).sqrt();
    let zeta = c / (D::c(2.0) * (k * m).sqrt());
    let wd = wn * (D::c(1.0) - zeta * zeta).sqrt();
    let tt = D::c(t);
    x0 * (D::c(0.0) - zeta * wn * tt).exp() * ((wd * tt).cos() + zeta * wn / wd * (wd * tt).sin())
}

const MSD: &str = "mass_spring_damper";
const MSD_SET: [&str; 3] = [
    "simulation.rtol=1e-10",
    "simulation.atol=1e-14",
    "simulation.t_end=5.0",
];

#[test]
fn sensitivity_mass_spring_damper_matches_its_closed_form() {
    let mut model = load(MSD, &MSD_SET);
    let params: Vec<String> = ["k", "parameters.c", "m", "x0", "elements.damper.r"]
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
    let s = model.sensitivities(&params).unwrap();
    assert_eq!(s.values, vec![10.0, 0.5, 1.0, 0.01, 0.5]);
    let jx = s.outputs.iter().position(|o| o == "x").unwrap();
    let (m, k, c, x0) = (1.0, 10.0, 0.5, 0.01);
    let mut worst = [0.0f64; 5];
    let mut scale = [0.0f64; 5];
    for (r, &t) in s.t.iter().enumerate() {
        let seeds = [
            msd_x(t, D::c(m), D(k, 1.0), D::c(c), D::c(x0)),
            msd_x(t, D::c(m), D::c(k), D(c, 1.0), D::c(x0)),
            msd_x(t, D(m, 1.0), D::c(k), D::c(c), D::c(x0)),
            msd_x(t, D::c(m), D::c(k), D::c(c), D(x0, 1.0)),
            msd_x(t, D::c(m), D::c(k), D(c, 1.0), D::c(x0)),
        ];
        for (p, d) in seeds.iter().enumerate() {
            scale[p] = scale[p].max(d.1.abs());
            worst[p] = worst[p].max((s.get(r, jx, p) - d.1).abs());
        }
        // and the state itself
        assert!((s.y[r * s.outputs.len() + jx] - seeds[0].0).abs() < 1e-9);
    }
    for p in 0..5 {
        let rel = worst[p] / scale[p];
        eprintln!("dx/d{}: worst {:e} of scale {:e}", params[p], rel, scale[p]);
        assert!(rel < 1e-4, "dx/d{}: {rel:e} of scale", params[p]);
    }
    // c and elements.damper.r are the same value here
    assert!(s
        .dy_dp
        .chunks(5)
        .all(|c| (c[1] - c[4]).abs() <= 1e-6 * scale[1]));
}

#[test]
fn sensitivity_mass_spring_damper_matches_differences_of_runs() {
    let mut model = load(MSD, &MSD_SET);
    let keys = [
        "parameters.k",
        "parameters.c",
        "parameters.m",
        "parameters.x0",
    ];
    let params: Vec<String> = keys.iter().map(|s| (*s).to_owned()).collect();
    let s = model.sensitivities(&params).unwrap();
    let worst = worst_against_runs(MSD, &MSD_SET, &s, &keys);
    assert!(worst < 1e-4, "worst {worst:e} of scale");
    // an unknown parameter is refused with a suggestion
    let e = model.sensitivities(&["zetta".to_owned()]).unwrap_err();
    assert!(e.to_string().contains("zeta"), "{e}");
}

#[test]
fn sensitivity_lift_circuit_matches_differences_of_runs() {
    let set = [
        "simulation.rtol=1e-10",
        "simulation.atol=1e-12",
        "simulation.t_end=2.5",
        "simulation.solver=\"radau5\"",
    ];
    let mut model = load("lift_circuit", &set);
    let keys = ["parameters.beta", "parameters.m", "parameters.c_load"];
    let params: Vec<String> = keys.iter().map(|s| (*s).to_owned()).collect();
    let s = model.sensitivities(&params).unwrap();
    let worst = worst_against_runs("lift_circuit", &set, &s, &keys);
    assert!(worst < 1e-4, "worst {worst:e} of scale");
}

#[test]
fn sensitivity_crane_matches_differences_of_runs() {
    let set = [
        "simulation.rtol=1e-10",
        "simulation.t_end=1.0",
        "simulation.dt_out=0.05",
    ];
    let mut model = load("knuckle_boom", &set);
    assert!(
        model.steady.is_some(),
        "the crane starts from [initial.steady]"
    );
    let q3 = model
        .equations
        .states()
        .iter()
        .find(|s| s.name == "crane_arm.q[2]")
        .unwrap()
        .name
        .clone();
    let initial = format!("initial.\"{q3}\"");
    let keys = [
        "parameters.beta",
        "parameters.R_l",
        "parameters.r_p",
        "parameters.m3",
        "parameters.tau_v",
        initial.as_str(),
    ];
    let params: Vec<String> = keys.iter().map(|s| (*s).to_owned()).collect();
    let s = model.sensitivities(&params).unwrap();
    let worst = worst_against_runs("knuckle_boom", &set, &s, &keys);
    assert!(worst < 1e-4, "worst {worst:e} of scale");
}
