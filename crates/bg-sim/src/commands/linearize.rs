//! `bg-sim linearize`: the model's linear model (A, B, C, D) at its start or at time T of a
//! run, for the named inputs and outputs, exact ([`bondgraph::linearize`]); as a table, JSON
//! or CSV; with `--bode IN:OUT` the frequency response of one pair, and its figure.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::registry;
use bondgraph::linearize::log_frequencies;
use bondgraph::linearize::Complex;
use bondgraph::{BodePoint, Linearization};

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim linearize` (its summary is on `Command::Linearize` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// The inputs u (names from the model's [inputs]), comma-separated or repeated.
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub inputs: Vec<String>,
    /// The outputs y: [outputs] columns or any variable (`mass.p`, `spring.e`, `b3.f`),
    /// comma-separated or repeated.
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub outputs: Vec<String>,
    /// Linearise at this time of a run (s) instead of the initial state.
    #[arg(long, value_name = "T")]
    pub at: Option<f64>,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// `text` (the matrices with their names, poles, DC gains), `json` or `csv` (with
    /// --bode: the Bode data; without: one row per matrix entry).
    #[arg(long, default_value = "text", value_name = "FORMAT")]
    pub format: String,
    /// The frequency response of one input–output pair, `IN:OUT`.
    #[arg(long, value_name = "IN:OUT")]
    pub bode: Option<String>,
    /// The frequency range of --bode in Hz, `LO..HI`.
    #[arg(long, default_value = "0.1..100", value_name = "LO..HI")]
    pub freq: String,
    /// Frequencies of --bode, spaced evenly on a log scale.
    #[arg(long, default_value_t = 400)]
    pub points: usize,
    /// Draw the Bode diagram of --bode as a PNG here.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Text,
    Json,
    Csv,
}

fn bad(message: &str, hint: &str) -> ExitCode {
    tell!("error: {message}\n  hint: {hint}");
    ExitCode::from(BAD_INPUT)
}

/// `LO..HI` with 0 < LO < HI, both finite.
fn parse_range(s: &str) -> Option<(f64, f64)> {
    let (a, b) = s.split_once("..")?;
    let (lo, hi) = (a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?);
    (lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo).then_some((lo, hi))
}

/// `bg-sim linearize`.
pub fn command(a: &Args) -> ExitCode {
    let format = match a.format.as_str() {
        "text" => Format::Text,
        "json" => Format::Json,
        "csv" => Format::Csv,
        f => return bad(&format!("--format `{f}` is not known"), "text, json or csv"),
    };
    let Some((f_lo, f_hi)) = parse_range(&a.freq) else {
        return bad(
            &format!(
                "--freq `{}`: expected LO..HI in Hz with 0 < LO < HI",
                a.freq
            ),
            "--freq 0.1..100",
        );
    };
    if !(2..=100_000).contains(&a.points) {
        return bad(
            &format!("--points {}: expected 2 to 100000", a.points),
            "--points 400",
        );
    }
    if a.plot.is_some() && a.bode.is_none() {
        return bad(
            "--plot draws the Bode diagram of --bode",
            "--bode F:x --plot bode.png",
        );
    }
    let mut inputs = a.inputs.clone();
    let mut outputs = a.outputs.clone();
    let pair = match &a.bode {
        None => None,
        Some(s) => {
            let Some((i, o)) = s
                .split_once(':')
                .filter(|(i, o)| !i.is_empty() && !o.is_empty())
            else {
                return bad(&format!("--bode `{s}`: expected IN:OUT"), "--bode F:x");
            };
            if !inputs.iter().any(|n| n == i) {
                inputs.push(i.to_owned());
            }
            if !outputs.iter().any(|n| n == o) {
                outputs.push(o.to_owned());
            }
            let ii = inputs.iter().position(|n| n == i).unwrap_or(0);
            let oi = outputs.iter().position(|n| n == o).unwrap_or(0);
            Some((ii, oi))
        }
    };
    let mut model = match Model::load(&a.model, &registry(), &a.set) {
        Ok(m) => m,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    // Before any work (the run to --at included): everything here is dense.
    let n = model.equations.n_states();
    if n > bondgraph::MAX_LINEARIZE_STATES {
        tell!(
            "error: {}: {}\n  hint: linearise a smaller variant of the model (fewer segments of a line, fewer modes per link: --set, or the cheaper scenes of `bg-sim reduce`)",
            model.file(),
            bondgraph::ModesError::LinearizeTooLarge {
                n,
                limit: bondgraph::MAX_LINEARIZE_STATES,
                entries: bondgraph::MAX_LINEARIZE_STATES.pow(2) / 1_000_000,
                mb: bondgraph::MAX_LINEARIZE_STATES.pow(2) * 8 / 1_000_000,
            }
        );
        return ExitCode::from(BAD_INPUT);
    }
    if a.bode.is_some() && n > bondgraph::MAX_BODE_STATES {
        tell!(
            "error: {}: --bode: {n} states, more than the {} a frequency response takes (one dense complex LU per frequency, ≈ (8/3)n³ flops each)\n  hint: --format csv writes A, B, C and D for a tool of your own, or take a smaller variant of the model (--set)",
            model.file(),
            bondgraph::MAX_BODE_STATES
        );
        return ExitCode::from(BAD_INPUT);
    }
    if let Err(e) = model.check_linear_names(&inputs, &outputs) {
        tell!("error: {e}");
        return ExitCode::from(BAD_INPUT);
    }
    if let Some(t) = a.at {
        if !(t.is_finite() && t >= model.settings.t_start) {
            return bad(
                &format!(
                    "--at must be a finite time from t_start = {} s on, got {t}",
                    model.settings.t_start
                ),
                "--at 1.5",
            );
        }
    }
    let lin = match model.linearize(a.at, &inputs, &outputs) {
        Ok(l) => l,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(FAILED);
        }
    };
    // Above the modal analysis' size the poles are left out, with a note.
    let poles = match lin.poles() {
        Ok(p) => Some(p),
        Err(bondgraph::ModesError::TooLarge { .. }) => None,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(FAILED);
        }
    };
    let bode = pair.map(|(i, o)| {
        let f = log_frequencies(f_lo, f_hi, a.points);
        (i, o, lin.bode(i, o, &f))
    });
    let title = model
        .title
        .clone()
        .unwrap_or_else(|| model.file().to_owned());
    if let (Some(path), Some((i, o, pts))) = (&a.plot, &bode) {
        let marks: Vec<f64> = poles
            .iter()
            .flatten()
            .filter(|p| p.im >= 0.0)
            .map(|p| p.norm() / (2.0 * std::f64::consts::PI))
            .collect();
        let name = format!(
            "{title}: {} → {} at t = {} s",
            lin.inputs[*i], lin.outputs[*o], lin.t
        );
        match bg_sim::plot::bode(&name, pts, &marks, path) {
            Ok(p) => tell!("wrote {}", p.display()),
            Err(e) => {
                tell!("error: {e}");
                return ExitCode::from(FAILED);
            }
        }
    }
    let text = match format {
        Format::Text => text(&title, &lin, poles.as_deref(), bode.as_ref()),
        Format::Json => json(&lin, poles.as_deref(), bode.as_ref()),
        Format::Csv => csv(&lin, bode.as_ref()),
    };
    say!("{text}");
    ExitCode::SUCCESS
}

type Bode = (usize, usize, Vec<BodePoint>);

/// Most rows or columns a matrix is printed with in the text format; a larger one is
/// summarised (`--format csv` or `json` give every entry).
const MAX_PRINTED: usize = 60;

/// Why the poles are left out above the modal analysis' size.
fn poles_note(n: usize) -> String {
    format!(
        "not computed: {n} states, more than the {} the dense eigen-solver takes (about n⁴); `--format csv` writes A for an eigen-solver of your own",
        bondgraph::MAX_MODES_STATES
    )
}

fn matrix(
    out: &mut String,
    name: &str,
    m: &bondgraph::DMatrix<f64>,
    rows: &[String],
    cols: &[String],
) {
    let _ = writeln!(out, "{name} ({}×{}):", m.nrows(), m.ncols());
    if m.nrows() == 0 || m.ncols() == 0 {
        return;
    }
    if m.nrows() > MAX_PRINTED || m.ncols() > MAX_PRINTED {
        let nonzero = m.iter().filter(|v| **v != 0.0).count();
        let _ = writeln!(
            out,
            "  {nonzero} nonzero entries, too many rows or columns to print here (more than {MAX_PRINTED}): --format csv or json gives every entry"
        );
        return;
    }
    let w = rows.iter().map(|r| r.chars().count()).max().unwrap_or(0);
    let _ = write!(out, "  {:w$}", "");
    for c in cols {
        let _ = write!(out, " {:>13}", clip(c, 13));
    }
    let _ = writeln!(out);
    for (i, r) in rows.iter().enumerate() {
        let _ = write!(out, "  {r:w$}");
        for j in 0..m.ncols() {
            let _ = write!(out, " {:>13.6e}", m[(i, j)]);
        }
        let _ = writeln!(out);
    }
}

fn clip(s: &str, n: usize) -> String {
    let k = s.chars().count();
    if k <= n {
        s.to_owned()
    } else {
        format!("…{}", s.chars().skip(k - n + 1).collect::<String>())
    }
}

fn text(
    title: &str,
    lin: &Linearization,
    poles: Option<&[Complex<f64>]>,
    bode: Option<&Bode>,
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{title}: linearised at t = {} s ({} states, {} inputs, {} outputs)\n  dδx/dt = A δx + B δu,  δy = C δx + D δu",
        lin.t,
        lin.states.len(),
        lin.inputs.len(),
        lin.outputs.len()
    );
    let states: Vec<String> = lin.states.iter().map(|s| format!("{s}.dot")).collect();
    matrix(&mut out, "A = ∂f/∂x", &lin.a, &states, &lin.states);
    matrix(&mut out, "B = ∂f/∂u", &lin.b, &states, &lin.inputs);
    matrix(&mut out, "C = ∂y/∂x", &lin.c, &lin.outputs, &lin.states);
    matrix(&mut out, "D = ∂y/∂u", &lin.d, &lin.outputs, &lin.inputs);
    match poles {
        Some(poles) => {
            let _ = writeln!(out, "poles (1/s), fastest first:");
            for p in poles {
                let _ = writeln!(out, "  {}", pole(*p));
            }
        }
        None => {
            let _ = writeln!(out, "poles: {}", poles_note(lin.states.len()));
        }
    }
    if !lin.inputs.is_empty() && !lin.outputs.is_empty() {
        let _ = writeln!(out, "DC gains G(0) = D − C A⁻¹ B:");
        let gains = lin.dc_gains();
        for (o, on) in lin.outputs.iter().enumerate() {
            for (i, inn) in lin.inputs.iter().enumerate() {
                let g = gains.as_ref().map_or_else(
                    || "infinite (A is singular)".to_owned(),
                    |g| format!("{:.9e}", g[(o, i)]),
                );
                let _ = writeln!(out, "  {inn} → {on}: {g}");
            }
        }
    }
    if let Some((i, o, pts)) = bode {
        let _ = writeln!(
            out,
            "Bode {} → {} ({} frequencies):\n  {:>12} {:>14} {:>12}",
            lin.inputs[*i],
            lin.outputs[*o],
            pts.len(),
            "f [Hz]",
            "|G| [dB]",
            "phase [°]"
        );
        let step = (pts.len() / 20).max(1);
        for (k, p) in pts.iter().enumerate() {
            if k % step == 0 || k + 1 == pts.len() {
                let _ = writeln!(
                    out,
                    "  {:>12.5e} {:>14.6} {:>12.4}",
                    p.f_hz, p.db, p.phase_deg
                );
            }
        }
        if step > 1 {
            let _ = writeln!(out, "  (every {step}th shown: --format csv gives them all)");
        }
    }
    out.trim_end().to_owned()
}

fn pole(p: Complex<f64>) -> String {
    if p.im == 0.0 {
        format!("{:.9e}", p.re)
    } else {
        format!(
            "{:.9e} {} {:.9e}i",
            p.re,
            if p.im < 0.0 { '−' } else { '+' },
            p.im.abs()
        )
    }
}

fn rows_json(m: &bondgraph::DMatrix<f64>) -> serde_json::Value {
    let finite = |v: f64| {
        if v.is_finite() {
            serde_json::json!(v)
        } else {
            serde_json::Value::Null
        }
    };
    serde_json::Value::Array(
        (0..m.nrows())
            .map(|i| serde_json::Value::Array((0..m.ncols()).map(|j| finite(m[(i, j)])).collect()))
            .collect(),
    )
}

fn json(lin: &Linearization, poles: Option<&[Complex<f64>]>, bode: Option<&Bode>) -> String {
    let gains = lin.dc_gains();
    let dc: Vec<Vec<Option<f64>>> = (0..lin.outputs.len())
        .map(|o| {
            (0..lin.inputs.len())
                .map(|i| gains.as_ref().map(|g| g[(o, i)]))
                .collect()
        })
        .collect();
    let mut v = serde_json::json!({
        "t": lin.t,
        "states": lin.states,
        "inputs": lin.inputs,
        "outputs": lin.outputs,
        "x": lin.x,
        "A": rows_json(&lin.a),
        "B": rows_json(&lin.b),
        "C": rows_json(&lin.c),
        "D": rows_json(&lin.d),
        "poles": poles.map(|poles| poles.iter().map(|p| serde_json::json!({"re": p.re, "im": p.im})).collect::<Vec<_>>()),
        "dc_gain": dc,
    });
    if poles.is_none() {
        v["poles_note"] = serde_json::json!(poles_note(lin.states.len()));
    }
    if let Some((i, o, pts)) = bode {
        v["bode"] = serde_json::json!({
            "input": lin.inputs[*i],
            "output": lin.outputs[*o],
            "f_hz": pts.iter().map(|p| p.f_hz).collect::<Vec<_>>(),
            "magnitude": pts.iter().map(|p| p.magnitude).collect::<Vec<_>>(),
            "db": pts.iter().map(|p| p.db).collect::<Vec<_>>(),
            "phase_deg": pts.iter().map(|p| p.phase_deg).collect::<Vec<_>>(),
        });
    }
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

fn csv(lin: &Linearization, bode: Option<&Bode>) -> String {
    let mut out = String::new();
    if let Some((_, _, pts)) = bode {
        out.push_str("f_hz,magnitude,db,phase_deg\n");
        for p in pts {
            let _ = writeln!(
                out,
                "{:e},{:e},{:e},{:e}",
                p.f_hz, p.magnitude, p.db, p.phase_deg
            );
        }
        return out.trim_end().to_owned();
    }
    out.push_str("matrix,row,column,value\n");
    let states_dot: Vec<String> = lin.states.iter().map(|s| format!("{s}.dot")).collect();
    for (name, m, rows, cols) in [
        ("A", &lin.a, &states_dot, &lin.states),
        ("B", &lin.b, &states_dot, &lin.inputs),
        ("C", &lin.c, &lin.outputs, &lin.states),
        ("D", &lin.d, &lin.outputs, &lin.inputs),
    ] {
        for (i, r) in rows.iter().enumerate() {
            for (j, c) in cols.iter().enumerate() {
                let _ = writeln!(out, "{name},{r},{c},{:e}", m[(i, j)]);
            }
        }
    }
    out.trim_end().to_owned()
}
