//! `bg-sim fit` on the lift circuit: recovery of hidden values from noisy synthetic data,
//! an unidentifiable product pair, the JSON shape, bad input, and Levenberg–Marquardt
//! against the derivative-free Nelder–Mead on the same problem.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::time::Instant;

use bg_model::{DataFile, Model};
use bg_sim::fit::{self, parse_param, JacobianKind, LmOptions, Method, Problem, RunOptions};
use bg_sim::registry;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn lift() -> (String, String) {
    let path = root().join("models/lift_circuit.toml");
    (
        path.display().to_string(),
        std::fs::read_to_string(&path).unwrap(),
    )
}

/// Box–Muller on SplitMix64: seeded Gaussian noise, the same on every machine.
struct Noise(u64);
impl Noise {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        #[allow(clippy::cast_precision_loss)]
        let u = ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        u
    }
    fn gauss(&mut self) -> f64 {
        let (a, b) = (self.unit(), self.unit());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

/// The lift circuit run at `hidden` (`--set` overrides) over `t_end`, `columns` kept, with
/// Gaussian noise of `level` × each column's RMS.
fn synthetic(hidden: &[&str], columns: &[&str], level: f64, t_end: f64, seed: u64) -> DataFile {
    let (file, text) = lift();
    let sets: Vec<String> = hidden.iter().map(|s| (*s).to_owned()).collect();
    let mut m = Model::from_text(&file, &text, &registry(), &sets).unwrap();
    m.settings.t_end = t_end;
    let out = m.run().unwrap();
    assert!(out.error.is_none());
    let tr = &out.trajectory;
    let idx: Vec<usize> = columns
        .iter()
        .map(|c| tr.columns.iter().position(|n| n == c).unwrap())
        .collect();
    #[allow(clippy::cast_precision_loss)]
    let rms: Vec<f64> = idx
        .iter()
        .map(|&j| (tr.rows.iter().map(|r| r[j] * r[j]).sum::<f64>() / tr.rows.len() as f64).sqrt())
        .collect();
    let mut noise = Noise(seed);
    let mut csv = format!("t,{}\n", columns.join(","));
    for r in &tr.rows {
        csv.push_str(&format!("{:?}", r[0]));
        for (k, &j) in idx.iter().enumerate() {
            csv.push_str(&format!(",{:?}", r[j] + level * rms[k] * noise.gauss()));
        }
        csv.push('\n');
    }
    DataFile::parse(&csv, "measured.csv").unwrap()
}

fn problem(data: &[DataFile], params: &[&str], t_end: Option<f64>) -> Problem {
    let (file, text) = lift();
    Problem::from_parts(
        file,
        text,
        data,
        params.iter().map(|p| parse_param(p).unwrap()).collect(),
        None,
        &[],
        RunOptions {
            t_end,
            ..RunOptions::default()
        },
        registry,
    )
    .unwrap()
}

const HIDDEN: [&str; 3] = [
    "parameters.m=2160.0",
    "parameters.c_load=3.75e4",
    "parameters.beta=1.8e9",
];
const TRUE: [f64; 3] = [2160.0, 3.75e4, 1.8e9];

#[test]
fn recovers_hidden_values_within_their_intervals() {
    let data = synthetic(&HIDDEN, &["s", "p_p", "p_b", "p_pump"], 0.01, 12.5, 32);
    // every start 30 % below the truth
    let p = problem(
        &[data],
        &[
            "m=1000..4000@1512",
            "c_load=1e4..1e5@26250",
            "beta=5e8..5e9@1.26e9",
        ],
        None,
    );
    let f = fit::fit(
        &p,
        Method::Lm,
        JacobianKind::Exact,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    eprintln!("{}", f.text());
    assert!(f.converged, "{}", f.reason);
    assert!(f.history.len() <= 10, "{} iterations", f.history.len());
    // exact sensitivities: one run per Jacobian (the start, each accepted point, the
    // statistics at the end) and one per trial point, rejected ones included (those of the
    // last, unaccepted search too: at most 40 before λ passes 1e16)
    let rejected: usize = f.history.iter().map(|i| i.rejected).sum();
    let least = 2 + 2 * f.history.len() + rejected;
    assert!(
        f.runs >= least && f.runs <= least + 40,
        "{} runs, {least} accounted for",
        f.runs
    );
    for (k, t) in TRUE.iter().enumerate() {
        let (lo, hi) = f.stats.ci95[k];
        assert!(
            lo <= *t && *t <= hi,
            "{}: {t} not in [{lo}, {hi}]",
            f.names[k]
        );
        // and the interval is informative: narrower than 5 % of the value
        assert!(hi - lo < 0.05 * t, "{}: [{lo}, {hi}]", f.names[k]);
    }
    assert!(f.warnings.is_empty(), "{:?}", f.warnings);
    // the residual variance is the noise's: σ_j = 1 % of the RMS, weights 1/scale_j²
    assert!(f.stats.variance > 0.0 && f.stats.variance < 1e-3);
}

#[test]
fn a_product_pair_is_flagged_unidentifiable() {
    // the pump's flow is d_pump·w_pump; without the drive torque in the data, only the
    // product is seen
    let data = synthetic(&[], &["s", "p_p", "p_b"], 0.01, 6.0, 5);
    let p = problem(
        &[data],
        &["d_pump=1e-6..1e-5@3.0e-6", "w_pump=50..200@110"],
        Some(6.0),
    );
    let f = fit::fit(
        &p,
        Method::Lm,
        JacobianKind::Exact,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    eprintln!("{}", f.text());
    assert!(
        f.warnings.iter().any(|w| w.starts_with("unidentifiable")
            && w.contains("d_pump")
            && w.contains("w_pump")),
        "{:?}",
        f.warnings
    );
    assert!(
        f.stats.correlation[(0, 1)].abs() > 0.999,
        "{}",
        f.stats.correlation
    );
    // the product is fixed although the factors are not: q_p = 20 l/min
    let q = f.p[0] * f.p[1];
    let q_true = 20e-3 / 60.0;
    assert!((q / q_true - 1.0).abs() < 1e-3, "{q} vs {q_true}");
}

#[test]
fn json_has_the_fixed_shape() {
    let data = synthetic(&HIDDEN, &["s", "p_p"], 0.01, 6.0, 7);
    let p = problem(
        &[data],
        &["m=1000..4000@1800", "c_load=1e4..1e5@3.5e4"],
        Some(6.0),
    );
    let f = fit::fit(
        &p,
        Method::Lm,
        JacobianKind::Exact,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let j = f.json();
    let mut keys: Vec<&str> = j.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "converged",
            "correlation",
            "cost",
            "covariance",
            "estimates",
            "iterations",
            "runs",
            "warnings"
        ]
    );
    for n in ["m", "c_load"] {
        let e = &j["estimates"][n];
        let mut k: Vec<&str> = e.as_object().unwrap().keys().map(String::as_str).collect();
        k.sort_unstable();
        assert_eq!(k, ["at_bound", "ci95", "stderr", "value"]);
        assert!(e["value"].is_f64() && e["stderr"].is_f64() && e["at_bound"].is_boolean());
        assert_eq!(e["ci95"].as_array().unwrap().len(), 2);
    }
    assert_eq!(
        j["correlation"]["names"],
        serde_json::json!(["m", "c_load"])
    );
    assert_eq!(j["correlation"]["matrix"].as_array().unwrap().len(), 2);
    assert!((j["correlation"]["matrix"][0][0].as_f64().unwrap() - 1.0).abs() < 1e-12);
    assert!(j["iterations"].is_u64() && j["runs"].is_u64() && j["converged"].is_boolean());
    assert!(j["cost"].is_f64() && j["warnings"].is_array());
    let se = j["estimates"]["m"]["stderr"].as_f64().unwrap();
    let var = j["covariance"]["matrix"][0][0].as_f64().unwrap();
    assert!((var.sqrt() / se - 1.0).abs() < 1e-12);
}

fn bad(data: &str, params: &[&str]) -> bg_model::ModelError {
    let (file, text) = lift();
    let d = DataFile::parse(data, "bad.csv");
    let d = match d {
        Ok(d) => d,
        Err(e) => return e,
    };
    let params: Vec<_> = params.iter().map(|p| parse_param(p).unwrap()).collect();
    match Problem::from_parts(
        file,
        text,
        &[d],
        params,
        None,
        &[],
        RunOptions::default(),
        registry,
    ) {
        Ok(_) => panic!("accepted"),
        Err(e) => e,
    }
}

#[test]
fn bad_input_is_refused_with_place_and_hint() {
    let ok = "t,s\n0,0.1\n13,0.1\n";
    // a column matching no output or input: did you mean
    let e = bad("t,p_pp\n0,1\n13,1\n", &["m=1..3000"]);
    assert_eq!(
        (e.file.as_str(), e.line, e.col),
        ("bad.csv", Some(1), Some(3))
    );
    assert!(
        e.hint.as_deref().unwrap().contains("did you mean `p_p`"),
        "{e}"
    );
    // a parameter the model lacks
    let e = bad(ok, &["mass=1..3000"]);
    assert!(e.message.contains("no parameter `mass`"), "{e}");
    assert!(
        e.hint.as_deref().unwrap().contains("did you mean `m`"),
        "{e}"
    );
    let e = bad(ok, &["elements.lift.bogus=1..2@1.5"]);
    assert!(e.message.contains("elements.lift.bogus"), "{e}");
    // NaN in the data, at its cell
    let e = bad("t,s\n0,0.1\n13,nan\n", &["m=1..3000"]);
    assert_eq!((e.line, e.col), (Some(3), Some(4)), "{e}");
    assert!(e.message.contains("not finite"), "{e}");
    // data not covering the run (12.5 s)
    let e = bad("t,s\n0,0.1\n10,0.1\n", &["m=1..3000"]);
    assert!(e.message.contains("before the run's end"), "{e}");
    assert!(e.hint.as_deref().unwrap().contains("--t-end"), "{e}");
    // the model's value outside the bounds, no start given
    let e = bad(ok, &["m=1..10"]);
    assert!(e.message.contains("outside the bounds"), "{e}");
    // bounds reversed, start outside: refused before any file is read
    assert!(parse_param("m=3000..1").unwrap_err().contains("reversed"));
    assert!(parse_param("m=1..3000@5000")
        .unwrap_err()
        .contains("outside the bounds"));
}

#[test]
fn cli_bad_input_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("d.csv");
    std::fs::write(&data, "t,p_pp\n0,1\n13,1\n").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .args([
            "fit",
            root().join("models/lift_circuit.toml").to_str().unwrap(),
            "--data",
        ])
        .arg(&data)
        .args(["--param", "m=1..3000"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("d.csv:1:3") && err.contains("did you mean `p_p`"),
        "{err}"
    );
}

#[test]
fn levenberg_marquardt_against_nelder_mead() {
    // the same two-parameter problem both ways (lift and hold, 6 s)
    let data = synthetic(&HIDDEN, &["s", "p_p", "p_b"], 0.01, 6.0, 11);
    let params = ["m=1000..4000@1512", "c_load=1e4..1e5@26250"];
    let lm = problem(std::slice::from_ref(&data), &params, Some(6.0));
    let t = Instant::now();
    let a = fit::fit(
        &lm,
        Method::Lm,
        JacobianKind::Exact,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let lm_wall = t.elapsed().as_secs_f64();
    let nm_data = data.clone();
    let nm = problem(&[data], &params, Some(6.0));
    let t = Instant::now();
    let b = fit::fit(
        &nm,
        Method::NelderMead,
        JacobianKind::Exact,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let nm_wall = t.elapsed().as_secs_f64();
    eprintln!(
        "LM: cost {:.6e}, {} iterations, {} runs, {lm_wall:.2} s; Nelder–Mead: cost {:.6e}, {} iterations, {} runs, {nm_wall:.2} s",
        a.cost,
        a.history.len(),
        a.runs,
        b.cost,
        b.history.len(),
        b.runs
    );
    // LM on central differences of whole runs: the same minimum, more runs
    let fd = problem(std::slice::from_ref(&nm_data), &params, Some(6.0));
    let t = Instant::now();
    let c = fit::fit(
        &fd,
        Method::Lm,
        JacobianKind::Fd,
        &LmOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    eprintln!(
        "LM on finite differences: cost {:.6e}, {} iterations, {} runs, {:.2} s",
        c.cost,
        c.history.len(),
        c.runs,
        t.elapsed().as_secs_f64()
    );
    for k in 0..2 {
        assert!(
            (a.p[k] - c.p[k]).abs() < 0.01 * a.stats.stderr[k],
            "{:?} vs {:?}",
            a.p,
            c.p
        );
        assert!((a.stats.stderr[k] / c.stats.stderr[k] - 1.0).abs() < 1e-3);
    }
    assert!(a.runs < c.runs, "exact {} runs, fd {}", a.runs, c.runs);
    // both reach the same minimum; LM with far fewer runs
    assert!(
        (b.cost / a.cost - 1.0).abs() < 1e-4,
        "{} vs {}",
        a.cost,
        b.cost
    );
    for k in 0..2 {
        assert!(
            (a.p[k] / b.p[k] - 1.0).abs() < 1e-3,
            "{:?} vs {:?}",
            a.p,
            b.p
        );
    }
    assert!(
        a.runs * 3 < b.runs,
        "LM {} runs, Nelder–Mead {}",
        a.runs,
        b.runs
    );
}
