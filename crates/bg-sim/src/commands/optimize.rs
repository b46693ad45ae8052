//! `bg-sim optimize`: minimise a sweep metric subject to constraints on others over
//! bounded parameters ([`bg_sim::sweep::optimize`]); every run on the sweep's rayon pool.

use std::path::PathBuf;
use std::process::ExitCode;

use bg_sim::registry;
use bg_sim::sweep::optimize::optimize_files;

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim optimize`.
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// The spec: [optimize], [parameters] with bounds, [metrics], [objective], [constraints].
    #[arg(long, value_name = "OPT.toml")]
    pub spec: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub jobs: usize,
    /// Every run (parameters, metrics, score, feasible) as CSV.
    #[arg(short, long, value_name = "RUNS.csv")]
    pub output: Option<PathBuf>,
    /// The best score per generation (PNG).
    #[arg(long, value_name = "HISTORY.png")]
    pub plot: Option<PathBuf>,
}

/// `bg-sim optimize`.
pub fn command(a: &Args) -> ExitCode {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(a.jobs).build() {
        Ok(p) => p,
        Err(e) => {
            tell!("error: cannot start the worker threads: {e}");
            return ExitCode::from(FAILED);
        }
    };
    let (spec, opt) = match pool.install(|| optimize_files(&a.model, &a.spec, registry)) {
        Ok(r) => r,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let names: Vec<&str> = spec.parameters.iter().map(|p| p.0.as_str()).collect();
    let metric_names: Vec<&str> = spec.metrics.iter().map(|m| m.name.as_str()).collect();
    for (g, s) in opt.history.iter().enumerate() {
        say!("generation {:>3}: best score {s:.6e}", g + 1);
    }
    say!(
        "{} runs in {:.1} s; {}",
        opt.runs.len(),
        opt.wall_s,
        if opt.converged {
            "converged"
        } else {
            "stopped at the budget"
        }
    );
    say!(
        "best ({}):",
        if opt.best.feasible {
            "every constraint holds"
        } else {
            "NO run kept every constraint"
        }
    );
    for (n, v) in names.iter().zip(&opt.best.p) {
        say!("  {n} = {v:.6e}");
    }
    for (n, v) in metric_names.iter().zip(&opt.best.metrics) {
        say!(
            "  {n}: {}",
            v.map_or_else(|| "(none)".to_owned(), |v| format!("{v:.6e}"))
        );
    }
    let mut code = if opt.best.feasible {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(FAILED)
    };
    if let Some(out) = &a.output {
        let mut csv = format!(
            "run,{},{},score,feasible\n",
            names.join(","),
            metric_names.join(",")
        );
        for (i, r) in opt.runs.iter().enumerate() {
            let p: Vec<String> = r.p.iter().map(|v| format!("{v:?}")).collect();
            let m: Vec<String> = r
                .metrics
                .iter()
                .map(|v| v.map_or_else(String::new, |v| format!("{v:?}")))
                .collect();
            csv.push_str(&format!(
                "{},{},{},{:?},{}\n",
                i + 1,
                p.join(","),
                m.join(","),
                r.score,
                r.feasible
            ));
        }
        if let Err(e) = std::fs::write(out, csv) {
            tell!("error: cannot write {}: {e}", out.display());
            code = ExitCode::from(FAILED);
        }
    }
    if let Some(png) = &a.plot {
        if let Err(e) = history_plot(
            &opt.history,
            metric_names[spec.objective.0.min(metric_names.len().saturating_sub(1))],
            png,
        ) {
            tell!("error: cannot draw {}: {e}", png.display());
            code = ExitCode::from(FAILED);
        }
    }
    code
}

fn history_plot(history: &[f64], objective: &str, png: &std::path::Path) -> Result<(), String> {
    use bg_model::plots::{Panel, Plot, Series};
    // the figure's x column is `t` by the plot module's rule; here it counts generations
    let mut csv = String::from("t,best\n");
    for (g, s) in history.iter().enumerate() {
        // infeasible generations (score ≥ 1e20) are left out of the curve
        if *s < 1e19 {
            csv.push_str(&format!("{},{s:?}\n", g + 1));
        }
    }
    let results = bg_sim::plot::Results::parse(&csv).map_err(|(l, m)| format!("line {l}: {m}"))?;
    let plot = Plot {
        file: png
            .file_stem()
            .map_or_else(|| "history".into(), |s| s.to_string_lossy().into_owned()),
        title: format!("Optimisation history: best {objective} (feasible runs)"),
        x: "t".into(),
        x_label: "generation".into(),
        panels: vec![Panel {
            y_label: objective.to_owned(),
            unit: None,
            x_range: None,
            series: vec![Series {
                column: "best".into(),
                label: "best so far".into(),
                scale: 1.0,
                offset: 0.0,
                dashed: false,
                line: 0,
            }],
            line: 0,
        }],
        line: 0,
    };
    let dir = png
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    bg_sim::plot::draw(&results, &plot, dir, bg_sim::plot::Format::Png)
        .map(drop)
        .map_err(|e| e.to_string())
}
