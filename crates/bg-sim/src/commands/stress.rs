//! `bg-sim stress`: run a model with its arms' stress blocks on a grid of sections and
//! report, per flexible link, the envelopes of N, V, M, σ_top and σ_bottom over the run (max
//! and min at every x with the time each occurs), the hot spot (the largest |σ|) and its
//! history, and per hydraulic cylinder its peak pressure and forces (docs/stress.md).
//!
//! The section forces are the arm's ([`bg_manipulator::stress`]): evaluated at the output rows
//! only, from the state and its derivative there. The rod buckling margin of each cylinder
//! is the smallest over the run of its rod check's `buckling_margin`
//! (`bg_hydraulics::buckling`), `null` for a cylinder without one.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::registry;
use bondgraph::Output;
use serde_json::{json, Value};

use super::{interrupt_on_signals, BAD_INPUT, FAILED};

/// How `bg-sim stress` reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum StressFormat {
    /// Tables for a person.
    #[default]
    Text,
    /// One JSON document (the shape docs/stress.md fixes).
    Json,
    /// CSV, one row per link and section.
    Csv,
}

/// The options of `bg-sim stress` (its summary is on `Command::Stress` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Only this link (1, 2, …).
    #[arg(long)]
    pub link: Option<usize>,
    /// Sections per link, equally spaced from the joint to the far end.
    #[arg(long, default_value_t = 200)]
    pub points: usize,
    /// text, json or csv.
    #[arg(long, value_enum, default_value_t = StressFormat::Text)]
    pub format: StressFormat,
    /// Draw the envelopes and the hot spot's history into this folder (PNG).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// End time (s).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Output interval (s): the times the envelopes see.
    #[arg(long)]
    pub dt_out: Option<f64>,
    /// Relative tolerance.
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    #[arg(long)]
    pub atol: Option<f64>,
    /// Override a value of the model file: --set parameters.k=5 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Drive the model's inputs from a CSV (as `bg-sim run --inputs`, linear, data must cover
    /// the run).
    #[arg(long, value_name = "DATA.csv")]
    pub inputs: Option<PathBuf>,
}

/// The quantities of the envelopes, in the JSON's order.
const QUANTITIES: [&str; 5] = ["N", "V", "M", "sigma_top", "sigma_bottom"];

/// One link's envelopes.
struct LinkEnvelope {
    arm: String,
    link: usize,
    x: Vec<f64>,
    /// Per quantity, its envelope.
    env: Vec<Envelope>,
    has_sigma: bool,
    /// (x index, t, σ) of the largest |σ|, and the column of its history.
    hot: Option<(usize, f64, f64, String)>,
}

/// The max and min of a quantity at each x over the run, with their times.
struct Envelope {
    max: Vec<f64>,
    t_max: Vec<f64>,
    min: Vec<f64>,
    t_min: Vec<f64>,
}

impl Envelope {
    fn unknown(n: usize) -> Self {
        Self {
            max: vec![f64::NAN; n],
            t_max: vec![f64::NAN; n],
            min: vec![f64::NAN; n],
            t_min: vec![f64::NAN; n],
        }
    }
}

/// A cylinder's peaks.
struct CylinderPeaks {
    name: String,
    p_max: f64,
    push: f64,
    pull: f64,
    /// The smallest buckling margin of the run (`<cyl>_rod_check.buckling_margin`), if the
    /// cylinder has a rod check.
    margin: Option<f64>,
}

fn elements_of_kind(text: &str, kind: &str) -> Vec<String> {
    let Ok(doc) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    doc.get("elements")
        .and_then(|e| e.as_table())
        .map(|t| {
            t.iter()
                .filter(|(_, v)| v.get("kind").and_then(|k| k.as_str()) == Some(kind))
                .map(|(n, _)| n.clone())
                .collect()
        })
        .unwrap_or_default()
}

/// `bg-sim stress`.
pub fn command(a: &Args) -> ExitCode {
    let bad = |m: String| {
        tell!("error: {m}");
        ExitCode::from(BAD_INPUT)
    };
    let text = match std::fs::read_to_string(&a.model) {
        Ok(t) => t,
        Err(e) => return bad(format!("{}: {e}", a.model.display())),
    };
    let text = match bg_model::overrides::apply(&a.model.display().to_string(), &text, &a.set) {
        Ok(t) => t,
        Err(e) => return bad(e.to_string()),
    };
    let arms = elements_of_kind(&text, "manipulator.planar_arm");
    if arms.is_empty() {
        return bad(format!(
            "{}: no `manipulator.planar_arm` element: nothing to compute stresses of",
            a.model.display()
        ));
    }
    if a.points < 2 || a.points > 4096 {
        return bad(format!("--points {}: needs 2 to 4096", a.points));
    }
    let cylinders = elements_of_kind(&text, "hydraulics.cylinder");
    let mut sets = a.set.clone();
    sets.extend(
        arms.iter()
            .map(|arm| format!("elements.{arm}.stress_grid={}", a.points)),
    );
    let mut model = match Model::load(&a.model, &registry(), &sets) {
        Ok(m) => m,
        Err(e) => return bad(e.to_string()),
    };
    if let Some(v) = a.t_end {
        model.settings.t_end = v;
    }
    if let Some(v) = a.dt_out {
        model.settings.dt_out = v;
    }
    if let Some(v) = a.rtol {
        model.settings.rtol = v;
    }
    if let Some(v) = a.atol {
        model.settings.atol = v;
    }
    if let Err(e) = model.settings.validate() {
        return bad(format!("{}: {e}", model.file()));
    }
    if let Some(path) = &a.inputs {
        if let Err(e) = model.set_inputs_from_csv(
            path,
            bondgraph::Interp::Linear,
            bg_model::Extrapolate::Error,
        ) {
            return bad(e.to_string());
        }
    }
    // The columns: every grid signal of every link, and the cylinders' pressures and forces.
    let mut links: Vec<(String, usize, bool)> = Vec::new();
    for arm in &arms {
        for k in 1..=64 {
            let probe = |q: &str| {
                model
                    .equations
                    .probe(&format!("{arm}_stress.grid{k}.{q}[0]"))
            };
            if probe("N").is_none() {
                continue;
            }
            if a.link.is_some_and(|l| l != k) {
                continue;
            }
            links.push((arm.clone(), k, probe("sigma_top").is_some()));
        }
    }
    if links.is_empty() {
        return bad(match a.link {
            Some(l) => {
                format!("--link {l}: the arms have no such link with distributed mass or a section")
            }
            None => "the arms have no link with distributed mass or a section".to_owned(),
        });
    }
    if let Some((arm, k, _)) = links.iter().find(|(_, _, s)| !s) {
        tell!("warning: {arm} link {k} declares no `section`: sigma_top and sigma_bottom are null (docs/stress.md)");
    }
    let add = |model: &mut Model, name: String| -> bool {
        match model.equations.probe(&name) {
            Some(probe) => {
                model.outputs.push(Output { name, probe });
                true
            }
            None => false,
        }
    };
    model.outputs.clear();
    for (arm, k, sigma) in &links {
        let qs: &[&str] = if *sigma {
            &QUANTITIES
        } else {
            &QUANTITIES[..3]
        };
        for q in std::iter::once(&"x").chain(qs) {
            for j in 0..a.points {
                add(&mut model, format!("{arm}_stress.grid{k}.{q}[{j}]"));
            }
        }
    }
    let mut cyl_cols = Vec::new();
    for c in &cylinders {
        let cols = [
            format!("{c}_chamber_p.p"),
            format!("{c}_chamber_r.p"),
            format!("{c}_piston.mech.e"),
        ];
        if cols.iter().all(|n| model.equations.probe(n).is_some()) {
            for n in &cols {
                add(&mut model, n.clone());
            }
            let margin = format!("{c}_rod_check.buckling_margin");
            let margin = add(&mut model, margin.clone()).then_some(margin);
            cyl_cols.push((c.clone(), cols, margin));
        }
    }
    model.settings.interrupt = Some(interrupt_on_signals());
    let outcome = match model.run() {
        Ok(o) => o,
        Err(e) => return bad(e.to_string()),
    };
    let mut code = ExitCode::SUCCESS;
    if let Some(e) = &outcome.error {
        tell!(
            "error: {}: the run stopped early: {e}; the envelopes cover the rows computed",
            model.file()
        );
        code = ExitCode::from(FAILED);
    }
    let tr = &outcome.trajectory;
    let t = tr.column("t").unwrap_or_default();
    if t.is_empty() {
        tell!("error: {}: the run has no rows", model.file());
        return ExitCode::from(FAILED);
    }
    let col = |n: &str| tr.column(n).unwrap_or_default();
    let mut envelopes = Vec::new();
    for (arm, k, sigma) in &links {
        let x: Vec<f64> = (0..a.points)
            .map(|j| col(&format!("{arm}_stress.grid{k}.x[{j}]"))[0])
            .collect();
        let mut env = Vec::new();
        let mut hot: Option<(usize, f64, f64, String)> = None;
        for q in QUANTITIES {
            let mut e = Envelope::unknown(a.points);
            if q.starts_with("sigma") && !sigma {
                env.push(e);
                continue;
            }
            for j in 0..a.points {
                let name = format!("{arm}_stress.grid{k}.{q}[{j}]");
                let v = col(&name);
                let (mut imax, mut imin) = (0, 0);
                for (r, y) in v.iter().enumerate() {
                    if *y > v[imax] {
                        imax = r;
                    }
                    if *y < v[imin] {
                        imin = r;
                    }
                }
                e.max[j] = v[imax];
                e.t_max[j] = t[imax];
                e.min[j] = v[imin];
                e.t_min[j] = t[imin];
                if q.starts_with("sigma") {
                    for r in [imax, imin] {
                        if hot.as_ref().is_none_or(|h| v[r].abs() > h.2.abs()) {
                            hot = Some((j, t[r], v[r], name.clone()));
                        }
                    }
                }
            }
            env.push(e);
        }
        envelopes.push(LinkEnvelope {
            arm: arm.clone(),
            link: *k,
            x,
            env,
            has_sigma: *sigma,
            hot,
        });
    }
    let peaks: Vec<CylinderPeaks> = cyl_cols
        .iter()
        .map(|(name, cols, margin)| {
            let (pp, pr, f) = (col(&cols[0]), col(&cols[1]), col(&cols[2]));
            CylinderPeaks {
                name: name.clone(),
                p_max: pp
                    .iter()
                    .chain(&pr)
                    .fold(f64::NEG_INFINITY, |m, v| m.max(*v)),
                push: f.iter().fold(0.0, |m: f64, v| m.max(*v)),
                pull: f.iter().fold(0.0, |m: f64, v| m.max(-*v)),
                margin: margin
                    .as_ref()
                    .map(|m| col(m).iter().fold(f64::INFINITY, |a, v| a.min(*v))),
            }
        })
        .collect();
    for c in peaks.iter().filter(|c| c.margin.is_none()) {
        tell!("warning: {}: buckling_margin is null: the cylinder has no rod check (rod_d, E, buckling; docs/fatigue.md)", c.name);
    }
    match a.format {
        StressFormat::Json => say!("{:#}", json_report(&envelopes, &peaks)),
        StressFormat::Csv => say!("{}", csv_report(&envelopes).trim_end()),
        StressFormat::Text => say!("{}", text_report(&envelopes, &peaks).trim_end()),
    }
    if let Some(dir) = &a.plot {
        match figures(
            dir,
            &envelopes,
            tr,
            model.title.as_deref().unwrap_or(model.file()),
        ) {
            Ok(files) => {
                for f in files {
                    tell!("wrote {}", f.display());
                }
            }
            Err(e) => {
                tell!("error: {e}");
                code = ExitCode::from(FAILED);
            }
        }
    }
    code
}

fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

fn json_report(links: &[LinkEnvelope], cyl: &[CylinderPeaks]) -> Value {
    let arr = |v: &[f64]| Value::Array(v.iter().map(|x| num(*x)).collect());
    let links: Vec<Value> = links
        .iter()
        .map(|l| {
            let mut o = serde_json::Map::new();
            o.insert("link".into(), json!(l.link));
            o.insert("x".into(), arr(&l.x));
            for (q, e) in QUANTITIES.iter().zip(&l.env) {
                o.insert(
                    (*q).into(),
                    json!({"max": arr(&e.max), "min": arr(&e.min), "t_max": arr(&e.t_max), "t_min": arr(&e.t_min)}),
                );
            }
            o.insert(
                "hot_spot".into(),
                match &l.hot {
                    Some((j, t, s, _)) => json!({"x": l.x[*j], "t": t, "sigma": s}),
                    None => json!({"x": null, "t": null, "sigma": null}),
                },
            );
            Value::Object(o)
        })
        .collect();
    let cylinders: Vec<Value> = cyl
        .iter()
        .map(|c| {
            json!({"name": c.name, "p_max": num(c.p_max), "force_push_max": num(c.push),
                   "force_pull_max": num(c.pull), "buckling_margin": c.margin.map_or(Value::Null, num)})
        })
        .collect();
    json!({"links": links, "cylinders": cylinders})
}

fn csv_report(links: &[LinkEnvelope]) -> String {
    let mut s = String::from("arm,link,x");
    for q in QUANTITIES {
        let _ = write!(s, ",{q}_max,{q}_t_max,{q}_min,{q}_t_min");
    }
    s.push('\n');
    for l in links {
        for (j, x) in l.x.iter().enumerate() {
            let _ = write!(s, "{},{},{x}", l.arm, l.link);
            for e in &l.env {
                let _ = write!(
                    s,
                    ",{},{},{},{}",
                    e.max[j], e.t_max[j], e.min[j], e.t_min[j]
                );
            }
            s.push('\n');
        }
    }
    s
}

fn text_report(links: &[LinkEnvelope], cyl: &[CylinderPeaks]) -> String {
    let mut s = String::new();
    for l in links {
        let _ = writeln!(
            s,
            "{} link {}: {} sections, x = 0 … {} m",
            l.arm,
            l.link,
            l.x.len(),
            l.x.last().copied().unwrap_or(0.0)
        );
        let units = [
            ("N", 1e-3, "kN"),
            ("V", 1e-3, "kN"),
            ("M", 1e-3, "kN·m"),
            ("sigma_top", 1e-6, "MPa"),
            ("sigma_bottom", 1e-6, "MPa"),
        ];
        for ((q, scale, unit), e) in units.iter().zip(&l.env) {
            if q.starts_with("sigma") && !l.has_sigma {
                continue;
            }
            let (jmax, jmin) = (argmax(&e.max), argmin(&e.min));
            let _ = writeln!(
                s,
                "  {q:<13} max {:>10.3} {unit} at x = {:.3} m, t = {:.3} s;  min {:>10.3} {unit} at x = {:.3} m, t = {:.3} s",
                e.max[jmax] * scale, l.x[jmax], e.t_max[jmax], e.min[jmin] * scale, l.x[jmin], e.t_min[jmin]
            );
        }
        if let Some((j, t, sg, _)) = &l.hot {
            let _ = writeln!(
                s,
                "  hot spot: σ = {:.3} MPa at x = {:.3} m, t = {t:.3} s",
                sg * 1e-6,
                l.x[*j]
            );
        }
    }
    for c in cyl {
        let _ = writeln!(
            s,
            "cylinder {}: p_max {:.3} MPa, push {:.1} kN, pull {:.1} kN, buckling margin {}",
            c.name,
            c.p_max * 1e-6,
            c.push * 1e-3,
            c.pull * 1e-3,
            c.margin.map_or_else(
                || "not declared".to_owned(),
                |m| format!("{m:.3} (smallest of the run)")
            )
        );
    }
    s
}

fn argmax(v: &[f64]) -> usize {
    (0..v.len()).fold(0, |b, j| if v[j] > v[b] { j } else { b })
}
fn argmin(v: &[f64]) -> usize {
    (0..v.len()).fold(0, |b, j| if v[j] < v[b] { j } else { b })
}

/// The envelope of each link along x (N, V, M, σ) and the hot spots' histories.
fn figures(
    dir: &std::path::Path,
    links: &[LinkEnvelope],
    tr: &bondgraph::Trajectory,
    title: &str,
) -> Result<Vec<PathBuf>, String> {
    use bg_model::plots::{Panel, Plot, Series};
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let series = |column: &str, label: &str, scale: f64, dashed: bool| Series {
        column: column.to_owned(),
        label: label.to_owned(),
        scale,
        offset: 0.0,
        dashed,
        line: 0,
    };
    let mut written = Vec::new();
    for l in links {
        // the plotting reads a CSV whose first column is `t`: here it holds x
        let mut csv = String::from("t");
        for q in QUANTITIES {
            let _ = write!(csv, ",{q}_max,{q}_min");
        }
        csv.push('\n');
        for j in 0..l.x.len() {
            let _ = write!(csv, "{}", l.x[j]);
            for e in &l.env {
                let _ = write!(csv, ",{},{}", e.max[j], e.min[j]);
            }
            csv.push('\n');
        }
        let results = bg_sim::plot::Results::parse(&csv).map_err(|(_, m)| m)?;
        let panel = |y: &str, unit: &str, cols: &[(&str, &str, f64, bool)]| Panel {
            y_label: y.to_owned(),
            unit: Some(unit.to_owned()),
            x_range: None,
            series: cols
                .iter()
                .map(|(c, lab, s, d)| series(c, lab, *s, *d))
                .collect(),
            line: 0,
        };
        let mut panels = vec![
            panel(
                "bending moment",
                "kN·m",
                &[
                    ("M_max", "max over the run", 1e-3, false),
                    ("M_min", "min over the run", 1e-3, true),
                ],
            ),
            panel(
                "shear force",
                "kN",
                &[("V_max", "max", 1e-3, false), ("V_min", "min", 1e-3, true)],
            ),
            panel(
                "axial force",
                "kN",
                &[("N_max", "max", 1e-3, false), ("N_min", "min", 1e-3, true)],
            ),
        ];
        if l.has_sigma {
            panels.push(panel(
                "normal stress",
                "MPa",
                &[
                    ("sigma_top_max", "top fibre, max", 1e-6, false),
                    ("sigma_top_min", "top fibre, min", 1e-6, true),
                    ("sigma_bottom_max", "bottom fibre, max", 1e-6, false),
                    ("sigma_bottom_min", "bottom fibre, min", 1e-6, true),
                ],
            ));
        }
        let plot = Plot {
            file: format!("stress-envelope-{}-link{}", l.arm, l.link),
            title: format!("{title}: link {} envelopes over the run", l.link),
            x: "t".to_owned(),
            x_label: "distance from the joint along the link [m]".to_owned(),
            panels,
            line: 0,
        };
        written.extend(
            bg_sim::plot::draw(&results, &plot, dir, bg_sim::plot::Format::Png)
                .map_err(|e| e.to_string())?,
        );
        if let Some((j, _, _, column)) = &l.hot {
            let hist = tr.column(column).unwrap_or_default();
            let t = tr.column("t").unwrap_or_default();
            let mut csv = String::from("t,sigma\n");
            for (a, b) in t.iter().zip(&hist) {
                let _ = writeln!(csv, "{a},{b}");
            }
            let results = bg_sim::plot::Results::parse(&csv).map_err(|(_, m)| m)?;
            let plot = Plot {
                file: format!("stress-hot-spot-{}-link{}", l.arm, l.link),
                title: format!(
                    "{title}: link {} hot spot at x = {:.3} m ({})",
                    l.link,
                    l.x[*j],
                    if column.contains("sigma_top") {
                        "top fibre"
                    } else {
                        "bottom fibre"
                    }
                ),
                x: "t".to_owned(),
                x_label: "time [s]".to_owned(),
                panels: vec![panel(
                    "normal stress",
                    "MPa",
                    &[("sigma", "σ at the hot spot", 1e-6, false)],
                )],
                line: 0,
            };
            written.extend(
                bg_sim::plot::draw(&results, &plot, dir, bg_sim::plot::Format::Png)
                    .map_err(|e| e.to_string())?,
            );
        }
    }
    Ok(written)
}
