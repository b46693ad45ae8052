//! `bg-sim sensitivity`: one run with the forward sensitivities ∂y/∂p of the model's
//! `[outputs]` columns to chosen parameters ([`bg_model::Model::sensitivities`],
//! docs/sensitivity.md): the time series as CSV (`dy/dp` columns), a ranking of normalised
//! sensitivities p/scale(y)·∂y/∂p (RMS and maximum over the run, scale(y) = max|y| over the
//! run) as text or JSON, and its figure.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use bg_model::{Model, Sensitivities};
use bg_sim::plot::{sensitivity_bars, SensitivityBar};
use bg_sim::registry;
use serde_json::json;

use super::json::Format;
use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim sensitivity` (its summary is on `Command::Sensitivity` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// The parameters p, comma-separated: `beta` or `parameters.beta`, `elements.cyl1.beta`,
    /// `initial."spring.q"` (the keys of --set).
    #[arg(long, value_delimiter = ',', value_name = "NAMES", required = true)]
    pub params: Vec<String>,
    /// The outputs y: `[outputs]` columns, comma-separated (default: every one).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub outputs: Vec<String>,
    /// Write the time series ∂y/∂p here (CSV: `t`, then one `dy/dp` column per pair).
    #[arg(short, long, value_name = "S.csv")]
    pub output: Option<PathBuf>,
    /// Draw the ranking as a PNG here.
    #[arg(long, value_name = "S.png")]
    pub plot: Option<PathBuf>,
    /// text (the ranking table) or json.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Relative tolerance.
    #[arg(long)]
    pub rtol: Option<f64>,
    /// End time (s).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Output interval (s).
    #[arg(long)]
    pub dt_out: Option<f64>,
    /// Override a value of the model file: --set parameters.k=5 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Drive the model's inputs from a CSV, as `run --inputs`.
    #[arg(long, value_name = "DATA.csv")]
    pub inputs: Option<PathBuf>,
    /// How the data go from one sample to the next: linear, or hold.
    #[arg(long, value_name = "INTERP", default_value = "linear")]
    pub inputs_interp: String,
    /// Outside the data's times: error, or hold the first and last values.
    #[arg(long, value_name = "WHAT", default_value = "error")]
    pub inputs_extrapolate: String,
}

fn bad(message: &str) -> ExitCode {
    tell!("error: {message}");
    ExitCode::from(BAD_INPUT)
}

/// One (output, parameter) pair of the ranking.
struct Rank {
    output: usize,
    param: usize,
    rms: f64,
    max: f64,
}

/// The normalised sensitivities p/scale(y)·∂y/∂p of the pairs `cols` × every parameter,
/// ranked by their RMS over the run, largest first; and each column's scale.
fn ranking(s: &Sensitivities, cols: &[usize]) -> (Vec<Rank>, Vec<f64>) {
    let (m, np, rows) = (s.outputs.len(), s.params.len(), s.t.len());
    let scales: Vec<f64> = (0..m)
        .map(|j| (0..rows).fold(0.0f64, |a, r| a.max(s.y[r * m + j].abs())))
        .collect();
    let mut out = Vec::new();
    for &j in cols {
        let scale = if scales[j] > 0.0 { scales[j] } else { 1.0 };
        for k in 0..np {
            let f = s.values[k] / scale;
            let (mut sq, mut mx) = (0.0, 0.0f64);
            for r in 0..rows {
                let v = f * s.get(r, j, k);
                sq += v * v;
                mx = mx.max(v.abs());
            }
            out.push(Rank {
                output: j,
                param: k,
                rms: (sq / rows.max(1) as f64).sqrt(),
                max: mx,
            });
        }
    }
    out.sort_by(|a, b| b.rms.total_cmp(&a.rms));
    (out, scales)
}

/// `bg-sim sensitivity`.
pub fn command(a: &Args) -> ExitCode {
    if a.format == Format::Json {
        crate::report::keep_stdout_for_document();
    }
    let mut model = match Model::load(&a.model, &registry(), &a.set) {
        Ok(m) => m,
        Err(e) => return bad(&e.to_string()),
    };
    if let Some(v) = a.rtol {
        model.settings.rtol = v;
    }
    if let Some(v) = a.t_end {
        model.settings.t_end = v;
    }
    if let Some(v) = a.dt_out {
        model.settings.dt_out = v;
    }
    if let Err(e) = model.settings.validate() {
        return bad(&e.to_string());
    }
    if let Some(path) = &a.inputs {
        let Some(interp) = bondgraph::Interp::parse(&a.inputs_interp) else {
            return bad(&format!(
                "--inputs-interp {}: not an interpolation\n  hint: linear or hold",
                a.inputs_interp
            ));
        };
        let Some(extrapolate) = bg_model::Extrapolate::parse(&a.inputs_extrapolate) else {
            return bad(&format!(
                "--inputs-extrapolate {}: not a choice\n  hint: error or hold",
                a.inputs_extrapolate
            ));
        };
        if let Err(e) = model.set_inputs_from_csv(path, interp, extrapolate) {
            return bad(&e.to_string());
        }
    }
    let names: Vec<String> = model.outputs.iter().map(|o| o.name.clone()).collect();
    let mut cols = Vec::new();
    for o in &a.outputs {
        match names.iter().position(|n| n == o.trim()) {
            Some(j) => cols.push(j),
            None => {
                let hint = match bondgraph::kind::suggest(o, names.iter().map(String::as_str)) {
                    Some(c) => format!("did you mean `{c}`?"),
                    None => format!("the [outputs] columns: {}", names.join(", ")),
                };
                return bad(&format!(
                    "{}: --outputs `{o}` is not an [outputs] column\n  hint: {hint}",
                    model.file()
                ));
            }
        }
    }
    if cols.is_empty() {
        cols = (0..names.len()).collect();
    }
    if cols.is_empty() {
        return bad(&format!(
            "{}: the model has no [outputs] columns\n  hint: add an [outputs] table",
            model.file()
        ));
    }
    let start = std::time::Instant::now();
    let s = match model.sensitivities(&a.params) {
        Ok(s) => s,
        Err(e) if e.kind == bg_model::ErrorKind::Override => return bad(&e.to_string()),
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(FAILED);
        }
    };
    let wall = start.elapsed().as_secs_f64();
    if let Some(path) = &a.output {
        if let Err(e) = write_csv(&s, &cols, path) {
            tell!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(FAILED);
        }
    }
    let (ranks, scales) = ranking(&s, &cols);
    let title = model
        .title
        .clone()
        .unwrap_or_else(|| model.file().to_owned());
    match a.format {
        Format::Json => {
            let ranking: Vec<_> = ranks
                .iter()
                .map(|r| {
                    json!({
                        "output": s.outputs[r.output],
                        "param": s.params[r.param],
                        "rms": r.rms,
                        "max": r.max,
                    })
                })
                .collect();
            crate::report::document(&json!({
                "model": model.file(),
                "params": s.params,
                "values": s.values,
                "outputs": cols.iter().map(|&j| &s.outputs[j]).collect::<Vec<_>>(),
                "scales": cols.iter().map(|&j| scales[j]).collect::<Vec<_>>(),
                "ranking": ranking,
                "rows": s.t.len(),
                "steps": s.steps,
                "wall_s": wall,
                "csv": a.output.as_ref().map(|p| p.display().to_string()),
            }));
        }
        Format::Text => {
            let mut t = String::new();
            let _ = writeln!(
                t,
                "{title}: sensitivities of {} outputs to {} parameters, {} rows, {} steps, {wall:.2} s",
                cols.len(),
                s.params.len(),
                s.t.len(),
                s.steps
            );
            let _ = writeln!(
                t,
                "normalised: p/scale(y)·∂y/∂p, scale(y) = max|y| over the run\n"
            );
            let _ = writeln!(
                t,
                "{:<16} {:<24} {:>12} {:>12} {:>12}",
                "output", "parameter", "value", "RMS", "max"
            );
            for r in &ranks {
                let _ = writeln!(
                    t,
                    "{:<16} {:<24} {:>12.4e} {:>12.4e} {:>12.4e}",
                    s.outputs[r.output], s.params[r.param], s.values[r.param], r.rms, r.max
                );
            }
            say!("{}", t.trim_end());
        }
    }
    if let Some(path) = &a.plot {
        let bars: Vec<SensitivityBar> = ranks
            .iter()
            .take(30)
            .map(|r| SensitivityBar {
                label: format!("{} / {}", s.outputs[r.output], s.params[r.param]),
                rms: r.rms,
                max: r.max,
            })
            .collect();
        let sub = format!(
            "normalised sensitivities p/max|y|·∂y/∂p, t = {} … {} s ({} of {} pairs)",
            s.t.first().copied().unwrap_or(0.0),
            s.t.last().copied().unwrap_or(0.0),
            bars.len(),
            ranks.len()
        );
        if let Err(e) = sensitivity_bars(&title, &sub, &bars, path) {
            tell!("error: {e}");
            return ExitCode::from(FAILED);
        }
    }
    ExitCode::SUCCESS
}

/// The CSV: `t`, then `dy/dp` for every chosen output and parameter.
fn write_csv(s: &Sensitivities, cols: &[usize], path: &std::path::Path) -> std::io::Result<()> {
    use std::io::Write as _;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut head = vec!["t".to_owned()];
    for &j in cols {
        for p in &s.params {
            head.push(format!("d{}/d{}", s.outputs[j], p.replace(',', ";")));
        }
    }
    writeln!(w, "{}", head.join(","))?;
    for (r, t) in s.t.iter().enumerate() {
        let mut line = format!("{t}");
        for &j in cols {
            for k in 0..s.params.len() {
                let _ = write!(line, ",{}", s.get(r, j, k));
            }
        }
        writeln!(w, "{line}")?;
    }
    w.flush()
}
