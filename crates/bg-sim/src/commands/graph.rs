//! `bg-sim graph`: draw a model's bond graph as SVG, PNG or DOT ([`bg_sim::graph`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::BAD_INPUT;

/// The options of `bg-sim graph` (its summary is on `Command::Graph` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Output file (default: out/<model name>.svg, or .dot, .png).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Draw the members of every composite inside a frame instead of one box.
    #[arg(long)]
    pub expand: bool,
    /// svg, dot or png (default: from the extension of --output, else svg).
    #[arg(long, value_enum)]
    pub format: Option<bg_sim::graph::Format>,
    /// PNG only: pixels per SVG pixel (2: a 737 px wide drawing becomes 1474 px).
    #[arg(long, default_value_t = bg_sim::graph::png::DEFAULT_SCALE)]
    pub scale: f32,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// `bg-sim graph`.
pub fn command(a: Args) -> ExitCode {
    let Args {
        model,
        output,
        expand,
        format,
        scale,
        set,
    } = a;
    graph(&model, output.as_deref(), expand, format, scale, &set)
}

fn graph(
    model: &Path,
    out: Option<&Path>,
    expand: bool,
    format: Option<bg_sim::graph::Format>,
    scale: f32,
    set: &[String],
) -> ExitCode {
    match bg_sim::graph::write(model, out, expand, format, scale, set) {
        Ok(w) => {
            if let Some(p) = &w.problem {
                tell!("note: drawn without causal strokes: {p}");
            }
            say!("{} nodes, {} bonds: {}", w.nodes, w.bonds, w.path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}
