//! Uncertainty carried forward: parameter distributions in a sweep spec (normal,
//! lognormal, uniform, and the multivariate normal of a fit: its estimates and covariance),
//! sampled by Monte Carlo or Latin hypercube (seeded), and the band of a column over time
//! (mean and 5/95 % quantiles across the runs, [`band`]).
//!
//! ```toml
//! [sweep]
//! design = "lhs"                 # or "monte_carlo"; samples = N, seed = S
//! samples = 200
//! seed = 1
//! [parameters]
//! beta = { dist = "normal", mean = 1.5e9, sd = 1e8 }
//! m = { dist = "lognormal", median = 2000.0, sigma = 0.05 }   # sigma of ln m
//! c_load = { dist = "uniform", from = 2e4, to = 4e4 }
//! [from_fit]
//! file = "fit.json"              # `bg-sim fit --format json`: estimates and covariance
//! [band]
//! columns = ["p_p", "s"]         # band.csv and band.png in the output folder
//! ```
//!
//! A Latin hypercube stratifies each parameter's probability (u in n equal strata, one
//! sample each) and maps it through the inverse distribution function; for a fit's
//! parameters each u becomes a standard normal z, and the sample is `p̂ + L z` with `L` the
//! Cholesky factor of the covariance (so the strata are of the independent z, and the
//! correlations of the fit are kept).

use std::path::Path;

use super::{err, SweepError};

/// A parameter's distribution.
#[derive(Clone, Debug, PartialEq)]
pub enum Dist {
    /// Normal.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        sd: f64,
    },
    /// Lognormal: ln x is normal with mean ln(median) and standard deviation `sigma`.
    LogNormal {
        /// Median.
        median: f64,
        /// Standard deviation of ln x.
        sigma: f64,
    },
    /// Uniform.
    Uniform {
        /// Lower end.
        from: f64,
        /// Upper end.
        to: f64,
    },
    /// Component `k` of the fit's multivariate normal ([`FromFit`]).
    FromFit(usize),
}

impl Dist {
    /// The value at probability `u` ∈ (0, 1) (a fit's component: the standard normal z;
    /// [`FromFit::sample`] makes the value).
    #[must_use]
    pub fn at(&self, u: f64) -> f64 {
        match *self {
            Self::Normal { mean, sd } => mean + sd * normal_quantile(u),
            Self::LogNormal { median, sigma } => median * (sigma * normal_quantile(u)).exp(),
            Self::Uniform { from, to } => from + u * (to - from),
            Self::FromFit(_) => normal_quantile(u),
        }
    }
}

/// The multivariate normal of a fit: its estimates and the Cholesky factor of its
/// covariance.
#[derive(Clone, Debug, PartialEq)]
pub struct FromFit {
    /// The `--set` paths, in the fit's order.
    pub paths: Vec<String>,
    /// The estimates.
    pub mean: Vec<f64>,
    /// Lower-triangular `L`, row-major, `C = L Lᵀ`.
    pub chol: Vec<Vec<f64>>,
}

impl FromFit {
    /// Read a fit's JSON (`estimates`, `covariance`).
    ///
    /// # Errors
    /// A file that is not a fit's report, or a covariance that is not positive definite (an
    /// unidentifiable parameter: fix it before sampling).
    pub fn read(path: &Path, spec_file: &str) -> Result<Self, SweepError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| err(spec_file, format!("[from_fit] cannot read {shown}: {e}")))?;
        let v: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| err(&shown, format!("not JSON: {e}")))?;
        let bad = |m: &str| {
            err(
                &shown,
                format!("{m}\n  hint: write it with `bg-sim fit … --format json > {shown}`"),
            )
        };
        let names: Vec<String> = v["covariance"]["names"]
            .as_array()
            .ok_or_else(|| bad("has no covariance.names"))?
            .iter()
            .map(|n| {
                n.as_str()
                    .map(str::to_owned)
                    .ok_or_else(|| bad("covariance.names holds a non-string"))
            })
            .collect::<Result<_, _>>()?;
        let n = names.len();
        let mut mean = Vec::with_capacity(n);
        for name in &names {
            mean.push(
                v["estimates"][name]["value"]
                    .as_f64()
                    .ok_or_else(|| bad(&format!("no estimates.{name}.value")))?,
            );
        }
        let mut c = vec![vec![0.0; n]; n];
        for (k, row) in c.iter_mut().enumerate() {
            for (l, cell) in row.iter_mut().enumerate() {
                *cell = v["covariance"]["matrix"][k][l]
                    .as_f64()
                    .ok_or_else(|| bad(&format!("covariance.matrix[{k}][{l}] is not a number (an unidentifiable parameter?)")))?;
            }
        }
        let chol = cholesky(&c).ok_or_else(|| {
            err(&shown, "the covariance is not positive definite\n  hint: a parameter the data could not identify: fit without it, then sample")
        })?;
        let paths = names
            .iter()
            .map(|n| {
                if n.contains('.') {
                    n.clone()
                } else {
                    format!("parameters.{n}")
                }
            })
            .collect();
        Ok(Self { paths, mean, chol })
    }

    /// The sample `p̂ + L z`.
    #[must_use]
    pub fn sample(&self, z: &[f64]) -> Vec<f64> {
        (0..self.mean.len())
            .map(|k| self.mean[k] + (0..=k).map(|l| self.chol[k][l] * z[l]).sum::<f64>())
            .collect()
    }
}

/// Cholesky `C = L Lᵀ`, or `None` if `C` is not positive definite.
fn cholesky(c: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = c.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                let d = c[i][i] - s;
                if d <= 0.0 || !d.is_finite() {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (c[i][j] - s) / l[j][j];
            }
        }
    }
    Some(l)
}

/// Parse `{ dist = …, … }`.
///
/// # Errors
/// An unknown distribution or a missing or bad key.
pub fn parse_dist(name: &str, t: &toml::Table, file: &str) -> Result<Dist, SweepError> {
    let num = |k: &str| -> Result<f64, SweepError> {
        match t.get(k) {
            Some(toml::Value::Float(f)) if f.is_finite() => Ok(*f),
            #[allow(clippy::cast_precision_loss)]
            Some(toml::Value::Integer(i)) => Ok(*i as f64),
            _ => Err(err(
                file,
                format!("`{name}`: `{k}` must be a finite number"),
            )),
        }
    };
    let keys = |allowed: &[&str]| -> Result<(), SweepError> {
        match t
            .keys()
            .find(|k| k.as_str() != "dist" && !allowed.contains(&k.as_str()))
        {
            Some(k) => Err(err(
                file,
                format!(
                    "`{name}`: this distribution has {}, not `{k}`",
                    allowed.join(" and ")
                ),
            )),
            None => Ok(()),
        }
    };
    match t.get("dist").and_then(toml::Value::as_str) {
        Some("normal") => {
            keys(&["mean", "sd"])?;
            let (mean, sd) = (num("mean")?, num("sd")?);
            if sd <= 0.0 {
                return Err(err(file, format!("`{name}`: sd must be > 0")));
            }
            Ok(Dist::Normal { mean, sd })
        }
        Some("lognormal") => {
            keys(&["median", "sigma"])?;
            let (median, sigma) = (num("median")?, num("sigma")?);
            if median <= 0.0 || sigma <= 0.0 {
                return Err(err(file, format!("`{name}`: median and sigma must be > 0")));
            }
            Ok(Dist::LogNormal { median, sigma })
        }
        Some("uniform") => {
            keys(&["from", "to"])?;
            let (from, to) = (num("from")?, num("to")?);
            if from >= to {
                return Err(err(file, format!("`{name}`: from {from} ≥ to {to}")));
            }
            Ok(Dist::Uniform { from, to })
        }
        _ => Err(err(
            file,
            format!("`{name}`: dist is \"normal\" (mean, sd), \"lognormal\" (median, sigma) or \"uniform\" (from, to)"),
        )),
    }
}

/// The standard normal quantile Φ⁻¹(u) (Acklam's rational approximation, relative error
/// below 1.2e-9), for u in (0, 1).
#[must_use]
pub fn normal_quantile(u: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let u = u.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if u < 0.02425 {
        tail((-2.0 * u.ln()).sqrt())
    } else if u > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - u).ln()).sqrt())
    } else {
        let q = u - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The band of columns over time across runs: per output row the mean and the 5 % and 95 %
/// quantiles (linear interpolation between order statistics). `runs[r][row][col]`; runs
/// shorter than the longest are left out of the rows they lack.
#[must_use]
pub fn band(runs: &[Vec<Vec<f64>>], cols: usize) -> Vec<Vec<(f64, f64, f64)>> {
    let rows = runs.iter().map(Vec::len).max().unwrap_or(0);
    (0..rows)
        .map(|i| {
            (0..cols)
                .map(|j| {
                    let mut v: Vec<f64> = runs
                        .iter()
                        .filter_map(|r| r.get(i).map(|row| row[j]))
                        .filter(|x| x.is_finite())
                        .collect();
                    v.sort_by(f64::total_cmp);
                    #[allow(clippy::cast_precision_loss)]
                    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
                    (mean, quantile(&v, 0.05), quantile(&v, 0.95))
                })
                .collect()
        })
        .collect()
}

/// Quantile `q` of sorted `v` (type 7: linear between order statistics).
#[must_use]
pub fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    #[allow(clippy::cast_precision_loss)]
    let h = (v.len() - 1) as f64 * q;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(v.len() - 1);
    #[allow(clippy::cast_precision_loss)]
    let w = h - lo as f64;
    v[lo] + w * (v[hi] - v[lo])
}

/// Read the runs a sweep kept (`runs/*.csv`), take the band of `columns`, and write
/// `band.csv` (`t`, then `COL_mean`, `COL_q05`, `COL_q95`, `COL_width` per column) and
/// `band.png` (per column a panel with the mean solid and the quantiles dashed, and one with
/// the band's width) into `out_dir`. Returns the
/// files written and the number of runs used.
///
/// # Errors
/// No run, a column no run has, a file that cannot be read or written, the figure.
pub fn write_band(
    out_dir: &Path,
    columns: &[String],
) -> Result<(Vec<std::path::PathBuf>, usize), SweepError> {
    let dir = out_dir.join("runs");
    let shown = dir.display().to_string();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map_err(|e| err(&shown, e.to_string()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    let mut t: Vec<f64> = Vec::new();
    let mut runs = Vec::new();
    for f in &files {
        let text =
            std::fs::read_to_string(f).map_err(|e| err(&f.display().to_string(), e.to_string()))?;
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
        let idx: Vec<usize> = columns
            .iter()
            .map(|c| {
                head.iter().position(|h| h == c).ok_or_else(|| {
                    err(
                        &f.display().to_string(),
                        format!(
                            "[band] column `{c}` is not an output column (they are: {})",
                            head[1..].join(", ")
                        ),
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        let mut rows = Vec::new();
        let mut times = Vec::new();
        for l in lines {
            let cells: Vec<f64> = l
                .split(',')
                .map(|c| c.trim().parse().unwrap_or(f64::NAN))
                .collect();
            times.push(cells.first().copied().unwrap_or(f64::NAN));
            rows.push(
                idx.iter()
                    .map(|&j| cells.get(j).copied().unwrap_or(f64::NAN))
                    .collect::<Vec<f64>>(),
            );
        }
        if times.len() > t.len() {
            t = times;
        }
        runs.push(rows);
    }
    if runs.is_empty() {
        return Err(err(&shown, "no finished run to take a band of"));
    }
    let b = band(&runs, columns.len());
    let mut csv = String::from("t");
    for c in columns {
        csv.push_str(&format!(",{c}_mean,{c}_q05,{c}_q95,{c}_width"));
    }
    csv.push('\n');
    for (i, row) in b.iter().enumerate() {
        csv.push_str(&format!("{:?}", t[i]));
        for (m, lo, hi) in row {
            csv.push_str(&format!(",{m:?},{lo:?},{hi:?},{:?}", hi - lo));
        }
        csv.push('\n');
    }
    let path = out_dir.join("band.csv");
    std::fs::write(&path, &csv).map_err(|e| err(&path.display().to_string(), e.to_string()))?;
    let mut written = vec![path];
    use bg_model::plots::{Panel, Plot, Series};
    let results = crate::plot::Results::parse(&csv)
        .map_err(|(l, m)| err("band.csv", format!("line {l}: {m}")))?;
    let s = |column: String, label: &str, dashed: bool| Series {
        column,
        label: label.to_owned(),
        scale: 1.0,
        offset: 0.0,
        dashed,
        line: 0,
    };
    let panels = columns
        .iter()
        .flat_map(|c| {
            [
                Panel {
                    y_label: c.clone(),
                    unit: None,
                    x_range: None,
                    series: vec![
                        s(format!("{c}_mean"), "mean", false),
                        s(format!("{c}_q05"), "5 % quantile", true),
                        s(format!("{c}_q95"), "95 % quantile", true),
                    ],
                    line: 0,
                },
                Panel {
                    y_label: format!("{c}: 95 % − 5 %"),
                    unit: None,
                    x_range: None,
                    series: vec![s(format!("{c}_width"), "width of the band", false)],
                    line: 0,
                },
            ]
        })
        .collect();
    let plot = Plot {
        file: "band".into(),
        title: format!("Band over {} runs: mean and 5/95 % quantiles", runs.len()),
        x: "t".into(),
        x_label: "time [s]".into(),
        panels,
        line: 0,
    };
    written.extend(
        crate::plot::draw(&results, &plot, out_dir, crate::plot::Format::Png)
            .map_err(|e| err("band.png", e.to_string()))?,
    );
    Ok((written, runs.len()))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn normal_quantiles_are_right() {
        for (u, z) in [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.05, -1.644_853_626_951_472_2),
            (0.001, -3.090_232_306_167_813_5),
        ] {
            assert!(
                (normal_quantile(u) - z).abs() < 1e-8,
                "{u}: {}",
                normal_quantile(u)
            );
        }
    }

    #[test]
    fn a_fit_sample_has_its_covariance() {
        // C = [[4, 1.2], [1.2, 1]]: L = [[2, 0], [0.6, 0.8]]
        let f = FromFit {
            paths: vec!["parameters.a".into(), "parameters.b".into()],
            mean: vec![10.0, 20.0],
            chol: cholesky(&[vec![4.0, 1.2], vec![1.2, 1.0]]).unwrap(),
        };
        assert!((f.chol[1][0] - 0.6).abs() < 1e-15 && (f.chol[1][1] - 0.8).abs() < 1e-15);
        assert_eq!(f.sample(&[1.0, 1.0]), vec![12.0, 21.4]);
        assert!(cholesky(&[vec![1.0, 1.0], vec![1.0, 1.0]]).is_none());
    }

    fn column(points: &[crate::sweep::Point], j: usize) -> Vec<f64> {
        points
            .iter()
            .map(|p| match p.values[j].1 {
                crate::sweep::Value::Num(v) => v,
                crate::sweep::Value::Text(_) => f64::NAN,
            })
            .collect()
    }

    fn moments(v: &[f64]) -> (f64, f64) {
        #[allow(clippy::cast_precision_loss)]
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        (
            m,
            (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)).sqrt(),
        )
    }

    #[test]
    fn distributions_are_sampled_with_their_moments() {
        for design in ["lhs", "monte_carlo"] {
            let text = format!(
                "[sweep]\ndesign = \"{design}\"\nsamples = 2000\nseed = 4\n[parameters]\na = {{ dist = \"normal\", mean = 10.0, sd = 2.0 }}\nb = {{ dist = \"lognormal\", median = 5.0, sigma = 0.1 }}\nc = {{ dist = \"uniform\", from = 1.0, to = 3.0 }}\n"
            );
            let spec = crate::sweep::parse_spec("s.toml", &text).unwrap();
            let p = crate::sweep::points(&spec);
            let (m, sd) = moments(&column(&p, 0));
            // Monte Carlo: the mean within 3 standard errors (2/√2000 = 0.045)
            assert!(
                (m - 10.0).abs() < 0.14 && (sd / 2.0 - 1.0).abs() < 0.05,
                "{design}: {m} {sd}"
            );
            let mut b = column(&p, 1);
            b.sort_by(f64::total_cmp);
            assert!((quantile(&b, 0.5) / 5.0 - 1.0).abs() < 0.01, "{design}");
            let c = column(&p, 2);
            assert!(c.iter().all(|v| (1.0..=3.0).contains(v)));
        }
        // the Latin hypercube puts one sample in each of the n probability strata
        let spec = crate::sweep::parse_spec(
            "s.toml",
            "[sweep]\ndesign = \"lhs\"\nsamples = 10\n[parameters]\nc = { dist = \"uniform\", from = 0.0, to = 10.0 }\n",
        )
        .unwrap();
        let mut strata: Vec<i64> = column(&crate::sweep::points(&spec), 0)
            .iter()
            .map(|v| {
                #[allow(clippy::cast_possible_truncation)]
                let s = v.floor() as i64;
                s
            })
            .collect();
        strata.sort_unstable();
        assert_eq!(strata, (0..10).collect::<Vec<_>>());
        let e = crate::sweep::parse_spec(
            "s.toml",
            "[parameters]\na = { dist = \"normal\", mean = 1.0, sd = 0.1 }\n",
        )
        .unwrap_err();
        assert!(e.message.contains("is a distribution"), "{e}");
        let e = crate::sweep::parse_spec("s.toml", "[sweep]\ndesign = \"lhs\"\nsamples = 3\n[parameters]\na = { dist = \"gauss\", mean = 1.0 }\n").unwrap_err();
        assert!(e.message.contains("dist is"), "{e}");
    }

    #[test]
    fn a_fit_is_sampled_with_its_covariance() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("fit.json"),
            r#"{"estimates": {"a": {"value": 10.0}, "b": {"value": 20.0}}, "covariance": {"names": ["a", "b"], "matrix": [[4.0, 1.2], [1.2, 1.0]]}}"#,
        )
        .unwrap();
        let spec_path = dir.path().join("s.toml");
        let spec = crate::sweep::parse_spec(
            &spec_path.display().to_string(),
            "[sweep]\ndesign = \"lhs\"\nsamples = 4000\nseed = 2\n[parameters]\nk = [1.0]\n[from_fit]\nfile = \"fit.json\"\n",
        )
        .unwrap();
        assert_eq!(spec.parameters[1].0, "parameters.a");
        let p = crate::sweep::points(&spec);
        let (a, b) = (column(&p, 1), column(&p, 2));
        let ((ma, sa), (mb, sb)) = (moments(&a), moments(&b));
        #[allow(clippy::cast_precision_loss)]
        let cov = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - ma) * (y - mb))
            .sum::<f64>()
            / (a.len() as f64 - 1.0);
        assert!(
            (ma - 10.0).abs() < 0.02 && (mb - 20.0).abs() < 0.02,
            "{ma} {mb}"
        );
        assert!(
            (sa / 2.0 - 1.0).abs() < 0.02 && (sb - 1.0).abs() < 0.02,
            "{sa} {sb}"
        );
        // correlation 0.6 kept (its standard error is ~0.01 at n = 4000)
        assert!((cov / (sa * sb) - 0.6).abs() < 0.04, "{}", cov / (sa * sb));
    }

    #[test]
    fn band_quantiles() {
        // 101 runs of one row, values 0..100: mean 50, q05 = 5, q95 = 95
        let runs: Vec<Vec<Vec<f64>>> = (0..=100).map(|i| vec![vec![f64::from(i)]]).collect();
        let b = band(&runs, 1);
        assert_eq!(b[0][0], (50.0, 5.0, 95.0));
    }
}
