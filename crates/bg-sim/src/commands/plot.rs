//! `bg-sim plot`: a model's `[[plot]]` figures from a results CSV, or a quick look at some of
//! its columns. `run --plots` draws through the same [`plot`].

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::Model;
use bg_sim::plot::Results;
use bg_sim::registry;

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim plot` (its summary is on `Command::Plot` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// A CSV written by `bg-sim run`.
    pub results: PathBuf,
    /// The model file whose `[[plot]]` tables to draw.
    #[arg(short, long, value_name = "MODEL.toml")]
    pub model: Option<PathBuf>,
    /// Draw these columns instead, comma-separated, one panel each.
    #[arg(long, value_delimiter = ',', conflicts_with = "model")]
    pub columns: Option<Vec<String>>,
    /// Folder for the figures (created if needed).
    #[arg(
        short = 'o',
        long = "out",
        visible_alias = "output",
        default_value = "out/plots"
    )]
    pub out: PathBuf,
    /// png, svg or both.
    #[arg(long, default_value = "png")]
    pub format: String,
}

/// `bg-sim plot`.
pub fn command(a: &Args) -> ExitCode {
    let Args {
        results,
        model,
        columns,
        out,
        format,
    } = a;
    let what = match (model, columns) {
        (Some(m), _) => PlotWhat::Model(m, &[]),
        (None, Some(c)) => PlotWhat::Columns(c),
        (None, None) => PlotWhat::Nothing,
    };
    plot(results, what, out, format, false)
}

/// What `plot` draws.
pub enum PlotWhat<'a> {
    /// The `[[plot]]` tables of this model (with these `--set` overrides).
    Model(&'a Path, &'a [String]),
    /// A quick look at these columns.
    Columns(&'a [String]),
    /// Nothing was asked for.
    Nothing,
}

pub fn plot(results: &Path, what: PlotWhat<'_>, dir: &Path, format: &str, quiet: bool) -> ExitCode {
    use bg_sim::plot::{draw, draw_all, quick_look, Format};
    let Some(format) = Format::parse(format) else {
        tell!("error: --format {format}: expected png, svg or both");
        return ExitCode::from(BAD_INPUT);
    };
    // the model first: its plots say which columns to read (a big CSV is read for those only)
    let model = match what {
        PlotWhat::Model(path, set) => match Model::load(path, &registry(), set) {
            Ok(m) => {
                if m.plots().is_empty() {
                    tell!(
                        "error: {} has no [[plot]] tables\n  hint: add one (docs/model-format.md, section Plots), or look at columns with `bg-sim plot {} --columns a,b`",
                        path.display(),
                        results.display()
                    );
                    return ExitCode::from(FAILED);
                }
                Some(m)
            }
            Err(e) => {
                tell!("error: {e}");
                return ExitCode::from(BAD_INPUT);
            }
        },
        _ => None,
    };
    let wanted: Vec<&str> = match (&model, &what) {
        (Some(m), _) => m
            .plots()
            .iter()
            .flat_map(|p| {
                std::iter::once(p.x.as_str()).chain(
                    p.panels
                        .iter()
                        .flat_map(|panel| panel.series.iter().map(|s| s.column.as_str())),
                )
            })
            .collect(),
        (None, PlotWhat::Columns(c)) => c.iter().map(String::as_str).collect(),
        (None, _) => Vec::new(),
    };
    let table = match Results::read_for_plot(results, &wanted) {
        Ok(t) => t,
        Err(e) => {
            tell!("error: {e}");
            return ExitCode::from(BAD_INPUT);
        }
    };
    if table.bucket() > 1 && !quiet {
        tell!(
            "note: {} rows: drawn from {} (each run of {} rows keeps its first, last, smallest and largest values)",
            table.rows_read(),
            table.rows_held(),
            table.bucket()
        );
    }
    let drawn = match (what, &model) {
        (PlotWhat::Model(..), Some(model)) => {
            draw_all(&table, model.plots(), model.file(), dir, format)
        }
        (PlotWhat::Columns(columns), _) => {
            let stem = results.file_stem().map_or_else(
                || "columns".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            );
            quick_look(&table, results, &stem, columns).and_then(|p| {
                std::fs::create_dir_all(dir).map_err(|source| bg_sim::plot::PlotError::Dir {
                    path: dir.to_path_buf(),
                    source,
                })?;
                draw(&table, &p, dir, format)
            })
        }
        _ => {
            tell!(
                "error: say what to draw: --model MODEL.toml (its [[plot]] tables) or --columns a,b (a quick look)\n  hint: {} has the columns {}",
                results.display(),
                table.names().join(", ")
            );
            return ExitCode::from(BAD_INPUT);
        }
    };
    match drawn {
        Ok(files) => {
            if !quiet {
                for f in &files {
                    say!("wrote {}", f.display());
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
    }
}
