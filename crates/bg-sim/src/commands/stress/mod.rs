//! `bg-sim stress`: run a model with its arms' stress blocks on a grid of sections and
//! report, per flexible link, the envelopes of N, V, M, σ_top and σ_bottom over the run (max
//! and min at every x with the time each occurs), the hot spot (the largest |σ|) and its
//! history, and per hydraulic cylinder its peak pressure and forces (docs/stress.md).
//!
//! The section forces are the arm's ([`bg_manipulator::stress`]): evaluated at the output rows
//! only, from the state and its derivative there. The rod buckling margin of each cylinder
//! is the smallest over the run of its rod check's `buckling_margin`
//! (`bg_hydraulics::buckling`), `null` for a cylinder without one.

use std::path::PathBuf;
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::registry;
use bondgraph::Output;

use super::{interrupt_on_signals, BAD_INPUT, FAILED};

mod fatigue;
mod plot;
mod report;

use fatigue::HotFatigue;

use plot::figures;
use report::{csv_report, json_report, text_report};

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
    /// Rainflow-count each link's hot-spot history and give its Miner damage on this S–N
    /// curve (as `bg-sim fatigue --sn`): a preset (`ec3-71`, `dnv-d`, …) or
    /// `m=3,range=71e6,cycles=2e6[,knee=5e6,m2=5,cutoff=1e8]` (range in Pa).
    #[arg(long, value_name = "CURVE")]
    pub fatigue: Option<String>,
    /// With --fatigue: the run repeats N times a year (the residue closed by the repetition,
    /// the life also in years).
    #[arg(long, value_name = "N", requires = "fatigue")]
    pub repeat_per_year: Option<f64>,
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
    /// The hot spot's fatigue (`--fatigue`).
    fatigue: Option<HotFatigue>,
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
    let curve = match a.fatigue.as_deref().map(bg_fatigue::SnCurve::parse) {
        None => None,
        Some(Ok(c)) => Some(c),
        Some(Err(e)) => return bad(format!("--fatigue: {e}")),
    };
    if let Some(n) = a.repeat_per_year {
        if !(n.is_finite() && n > 0.0) {
            return bad(format!(
                "--repeat-per-year {n}: expected a finite number > 0\n  hint: --repeat-per-year 2000"
            ));
        }
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
    // with --plot, the ends of every link's chord: the pose of the boom figure
    let mut poses: Vec<(String, Vec<(String, String)>)> = Vec::new();
    if a.plot.is_some() {
        for arm in &arms {
            let mut ends = Vec::new();
            for i in 1..=64 {
                let (x, y) = (format!("{arm}_arm.x_e{i}"), format!("{arm}_arm.y_e{i}"));
                if model.equations.probe(&x).is_none() || model.equations.probe(&y).is_none() {
                    break;
                }
                add(&mut model, x.clone());
                add(&mut model, y.clone());
                ends.push((x, y));
            }
            poses.push((arm.clone(), ends));
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
            fatigue: curve.as_ref().zip(hot.as_ref()).and_then(|(c, h)| {
                let history = col(&h.3);
                if history.iter().all(|v| v.is_finite()) {
                    Some(HotFatigue::of(&history, &h.3, c, a.repeat_per_year))
                } else {
                    tell!("warning: {arm} link {k}: the hot spot's history is not finite: no fatigue count");
                    None
                }
            }),
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
        StressFormat::Json => say!("{:#}", json_report(&envelopes, &peaks, curve.is_some())),
        StressFormat::Csv => say!("{}", csv_report(&envelopes).trim_end()),
        StressFormat::Text => say!("{}", text_report(&envelopes, &peaks).trim_end()),
    }
    if let Some(dir) = &a.plot {
        match figures(
            dir,
            &envelopes,
            &poses,
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
