//! `bg-sim plot`: the figures a model declares in its `[[plot]]` tables
//! ([`bg_model::plots`]), drawn from a results CSV as PNG and SVG ([`draw_all`]); a quick
//! look at any columns of a CSV ([`quick_look`]); and the diagrams of `bench` and
//! `sweep-plot` ([`work_precision`], [`contour`]).
//!
//! A panel's dashed series are drawn on top of its solid ones, each in a darker shade of the
//! solid curve it goes with (the k-th dashed with the k-th solid), and the solid curves of
//! such a panel wider and paler: a reference lying on its curve shows as dark dashes on a
//! pale band. Text is set in DejaVu Sans, which the `dejavu` crate ships: no system fonts
//! are needed.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use bg_model::plots::{Panel, Plot, Series};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;

/// Why the figures could not be drawn.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The CSV could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The CSV is not a results file (header, then rows of numbers).
    #[error("{path}:{line}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The output folder could not be made.
    #[error("cannot create {path}: {source}")]
    Dir {
        /// The folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Drawing or encoding a figure failed.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The PNG.
        path: PathBuf,
        /// What the drawing backend said.
        message: String,
    },
    /// The bundled font was refused.
    #[error("cannot load the bundled font DejaVu Sans")]
    Font,
    /// `--columns` names a column the results do not have.
    #[error("{path}: {message}\n  hint: {hint}")]
    Column {
        /// The CSV.
        path: PathBuf,
        /// What is wrong.
        message: String,
        /// What to do about it.
        hint: String,
    },
    /// A plot of the model names a column the results do not have.
    #[error("{0}")]
    Model(Box<bg_model::ModelError>),
}

/// A results table: named columns of equal length, the first one `t`, at least one row
/// (made only by [`Results::read`] and [`Results::parse`], which check that).
#[derive(Clone, Debug)]
pub struct Results {
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
}

impl Results {
    /// Read a CSV written by `bg-sim run`: a header of column names, then rows of numbers.
    pub fn read(path: &Path) -> Result<Self, PlotError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlotError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text).map_err(|(line, message)| PlotError::Format {
            path: path.to_path_buf(),
            line,
            message,
        })
    }

    /// Parse CSV text; errors carry the 1-based line.
    pub fn parse(text: &str) -> Result<Self, (usize, String)> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| (1, "empty file: expected a header line".to_owned()))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_owned()).collect();
        if names.first().map(String::as_str) != Some("t") {
            return Err((1, "the first column must be `t`".to_owned()));
        }
        let mut columns = vec![Vec::new(); names.len()];
        for (i, line) in lines {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != names.len() {
                return Err((
                    i + 1,
                    format!("{} values, the header has {}", cells.len(), names.len()),
                ));
            }
            for (c, cell) in cells.iter().enumerate() {
                let v: f64 = cell
                    .trim()
                    .parse()
                    .map_err(|_| (i + 1, format!("`{cell}` is not a number")))?;
                columns[c].push(v);
            }
        }
        if columns[0].is_empty() {
            return Err((2, "no rows".to_owned()));
        }
        Ok(Self { names, columns })
    }

    /// The column called `name`.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }

    /// The column names, `t` first.
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The table as a [`Trajectory`](bondgraph::Trajectory) (rows of values, `t` first).
    #[must_use]
    pub fn to_trajectory(&self) -> bondgraph::Trajectory {
        let n = self.columns[0].len();
        bondgraph::Trajectory {
            columns: self.names.clone(),
            rows: (0..n)
                .map(|i| self.columns.iter().map(|c| c[i]).collect())
                .collect(),
        }
    }

    /// The time column.
    #[must_use]
    pub fn time(&self) -> &[f64] {
        &self.columns[0]
    }
}

/// Which files a plot is written as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Format {
    /// PNG (a bitmap, for the docs and a quick look).
    #[default]
    Png,
    /// SVG (vector, for papers).
    Svg,
    /// Both.
    Both,
}

impl Format {
    /// `png`, `svg` or `both`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "png" => Some(Self::Png),
            "svg" => Some(Self::Svg),
            "both" => Some(Self::Both),
            _ => None,
        }
    }

    fn extensions(self) -> &'static [&'static str] {
        match self {
            Self::Png => &["png"],
            Self::Svg => &["svg"],
            Self::Both => &["png", "svg"],
        }
    }
}

const FONT: &str = "sans-serif";
const WIDTH: u32 = 1040;
const TITLE_HEIGHT: u32 = 36;
const LEGEND_WIDTH: u32 = 130;
/// A model plot: width, legend width, height of a panel.
const FIG_WIDTH: u32 = 1100;
const FIG_LEGEND_WIDTH: u32 = 230;
const PANEL_HEIGHT: u32 = 250;
/// Left edge (px) of a model plot's legend: every legend entry's text starts right of it,
/// every other text left of it.
pub const LEGEND_LEFT: u32 = FIG_WIDTH - FIG_LEGEND_WIDTH;

fn font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// A quick look at some columns of a results CSV (`bg-sim plot --columns`): one panel per
/// column over `t`, each labelled with the column's name, in a plot whose file is `stem`. A
/// column the results do not have is an error naming it and the similar ones.
pub fn quick_look(
    results: &Results,
    csv: &Path,
    stem: &str,
    columns: &[String],
) -> Result<Plot, PlotError> {
    if columns.is_empty() {
        return Err(PlotError::Column {
            path: csv.to_path_buf(),
            message: "--columns names no column".to_owned(),
            hint: bg_model::plots::column_hint("", results.names()),
        });
    }
    if let Some(c) = columns.iter().find(|c| results.column(c).is_none()) {
        return Err(PlotError::Column {
            path: csv.to_path_buf(),
            message: format!("no column `{}`", bg_model::error::clip(c)),
            hint: bg_model::plots::column_hint(c, results.names()),
        });
    }
    Ok(Plot {
        file: stem.to_owned(),
        title: format!(
            "{} of {}",
            columns.join(", "),
            csv.file_name().map_or_else(
                || csv.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            )
        ),
        x: "t".to_owned(),
        x_label: "time [s]".to_owned(),
        panels: columns
            .iter()
            .map(|c| Panel {
                y_label: c.clone(),
                unit: None,
                x_range: None,
                series: vec![Series {
                    column: c.clone(),
                    label: c.clone(),
                    scale: 1.0,
                    offset: 0.0,
                    dashed: false,
                    line: 0,
                }],
                line: 0,
            })
            .collect(),
        line: 0,
    })
}

/// Draw every plot of `plots` (a model's `[[plot]]` tables; `model` names the file in
/// errors) from `results` into `dir` (created if needed), as `format`. The columns of every
/// plot are checked first, so that a misnamed column draws nothing. Returns the files
/// written.
pub fn draw_all(
    results: &Results,
    plots: &[Plot],
    model: &str,
    dir: &Path,
    format: Format,
) -> Result<Vec<PathBuf>, PlotError> {
    for p in plots {
        p.check_columns(model, results.names())
            .map_err(|e| PlotError::Model(Box::new(e)))?;
    }
    std::fs::create_dir_all(dir).map_err(|source| PlotError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    for p in plots {
        written.extend(draw(results, p, dir, format)?);
    }
    Ok(written)
}

/// Draw one plot into `dir` as `format` (its columns checked by the caller: a missing one
/// is left out). Returns the files written.
pub fn draw(
    results: &Results,
    plot: &Plot,
    dir: &Path,
    format: Format,
) -> Result<Vec<PathBuf>, PlotError> {
    font()?;
    let height = TITLE_HEIGHT + PANEL_HEIGHT * plot.panels.len().max(1) as u32;
    let mut written = Vec::new();
    for ext in format.extensions() {
        let path = dir.join(format!("{}.{ext}", plot.file));
        let fail = |message: String| PlotError::Draw {
            path: path.clone(),
            message,
        };
        if *ext == "svg" {
            let root = SVGBackend::new(&path, (FIG_WIDTH, height)).into_drawing_area();
            render(&root, results, plot).map_err(fail)?;
        } else {
            let root = BitMapBackend::new(&path, (FIG_WIDTH, height)).into_drawing_area();
            render(&root, results, plot).map_err(fail)?;
        }
        written.push(path);
    }
    Ok(written)
}

/// Draw `plot` on `root` (any backend) and present it.
fn render<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    results: &Results,
    plot: &Plot,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let (top, body) = root.split_vertically(TITLE_HEIGHT);
    top.titled(&plot.title, (FONT, 20).into_font().style(FontStyle::Bold))
        .map_err(e)?;
    let n = plot.panels.len().max(1);
    for (panel, area) in plot.panels.iter().zip(body.split_evenly((n, 1))) {
        draw_panel(results, plot, panel, &area).map_err(e)?;
    }
    root.present().map_err(e)
}

/// One line of a work–precision diagram: a method's runs as (wall time in ms, error) points,
/// in order of tolerance.
#[derive(Clone, Debug)]
pub struct WorkPrecisionLine {
    /// Legend text (the method).
    pub label: String,
    /// (wall time ms, worst scaled error) per run; non-positive or non-finite points are left out.
    pub points: Vec<(f64, f64)>,
}

/// Draw a work–precision diagram (error against wall time, both logarithmic, one line per
/// method) as a PNG at `path`.
pub fn work_precision(
    title: &str,
    lines: &[WorkPrecisionLine],
    path: &Path,
) -> Result<PathBuf, PlotError> {
    font()?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| PlotError::Dir {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    let fail = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && p.0 > 0.0 && p.1 > 0.0;
    let pts: Vec<(f64, f64)> = lines
        .iter()
        .flat_map(|l| l.points.iter().copied())
        .filter(ok)
        .collect();
    let bounds = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = pts
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if lo.is_finite() {
            (lo / 2.0, hi * 2.0)
        } else {
            (1e-3, 1.0)
        }
    };
    let (x0, x1) = bounds(|p| p.0);
    let (y0, y1) = bounds(|p| p.1);
    {
        let root = BitMapBackend::new(path, (WIDTH, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let (plot_area, legend_area) = body.split_horizontally(WIDTH - LEGEND_WIDTH);
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(78)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("wall time [ms]")
            .y_desc("worst scaled error")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_label_formatter(&|v| significant(*v))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        for (i, line) in lines.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let p: Vec<(f64, f64)> = line.points.iter().copied().filter(ok).collect();
            chart
                .draw_series(LineSeries::new(p.clone(), color.stroke_width(2)))
                .map_err(|e| fail(&e))?;
            chart
                .draw_series(p.iter().map(|&q| Circle::new(q, 4, color.filled())))
                .map_err(|e| fail(&e))?;
            let y = 24 + 22 * i as i32;
            legend_area
                .draw(&PathElement::new(
                    vec![(4, y), (28, y)],
                    color.stroke_width(2),
                ))
                .map_err(|e| fail(&e))?;
            legend_area
                .draw(&Text::new(
                    line.label.clone(),
                    (34, y - 8),
                    (FONT, 14).into_font().color(&BLACK),
                ))
                .map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}

/// A tick label with three significant digits and no trailing zeros (0.3, 12, 0.0025).
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The y range of the curves, padded by 5 % (and widened around a constant).
fn y_range(curves: &[Vec<(f64, f64)>]) -> (f64, f64) {
    let (lo, hi) = curves
        .iter()
        .flat_map(|pts| pts.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        0.05 * span
    } else {
        0.5 * lo.abs().max(1e-9)
    };
    (lo - pad, hi + pad)
}

/// A tick label on an axis spanning `span`: a value that is zero but for rounding (2e-17
/// on an axis of 2) is written 0.
fn tick(v: f64, span: f64) -> String {
    significant(if v.abs() <= 1e-9 * span.abs() { 0.0 } else { v })
}

/// The colour `c` mixed with white (`w` = 0: `c`, 1: white) or, for negative `w`, with
/// black.
fn shade(c: RGBColor, w: f64) -> RGBColor {
    let to = if w >= 0.0 { 255.0 } else { 0.0 };
    let w = w.abs();
    let m = |v: u8| (f64::from(v) + w * (to - f64::from(v))).round() as u8;
    RGBColor(m(c.0), m(c.1), m(c.2))
}

/// How each series of a panel is drawn: its colour and width. The k-th dashed series is the
/// counterpart of the k-th solid one (a reference, a command, a variant): the same hue,
/// darker, drawn on top; where a panel has dashed series its solid curves are wider and
/// lighter, so that a dashed curve lying on its solid one shows as dark dashes on a pale
/// band.
fn styles(panel: &Panel) -> Vec<(RGBColor, u32)> {
    let any_dashed = panel.series.iter().any(|s| s.dashed);
    let any_solid = panel.series.iter().any(|s| !s.dashed);
    let (mut solid, mut dashed) = (0, 0);
    panel
        .series
        .iter()
        .map(|s| {
            if s.dashed {
                dashed += 1;
                let base = PALETTE[(dashed - 1) % PALETTE.len()];
                if any_solid {
                    (shade(base, -0.45), 2)
                } else {
                    (base, 2)
                }
            } else {
                solid += 1;
                let base = PALETTE[(solid - 1) % PALETTE.len()];
                if any_dashed {
                    (shade(base, 0.45), 5)
                } else {
                    (base, 2)
                }
            }
        })
        .collect()
}

fn draw_panel<DB: DrawingBackend>(
    results: &Results,
    plot: &Plot,
    panel: &Panel,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let empty: &[f64] = &[];
    let x = results.column(&plot.x).unwrap_or(empty);
    let (mut x0, mut x1) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    if let Some((a, b)) = panel.x_range {
        (x0, x1) = (x0.max(a), x1.min(b));
    }
    let x1 = x1.max(x0 + 1e-12);
    let curves: Vec<Vec<(f64, f64)>> = panel
        .series
        .iter()
        .map(|s| {
            results.column(&s.column).map_or_else(Vec::new, |c| {
                x.iter()
                    .zip(c)
                    .map(|(&x, &v)| (x, s.show(v)))
                    .filter(|&(x, v)| (x0..=x1).contains(&x) && v.is_finite())
                    .collect()
            })
        })
        .collect();
    let (y0, y1) = y_range(&curves);
    let width = area.dim_in_pixel().0;
    // the legend sits right of the chart, so it never hides a curve
    let (plot_area, legend_area) = area.split_horizontally(width.saturating_sub(FIG_LEGEND_WIDTH));
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(84)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(panel.axis_label())
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .x_label_formatter(&|v| tick(*v, x1 - x0))
        .y_label_formatter(&|v| tick(*v, y1 - y0))
        .light_line_style(RGBColor(238, 238, 238))
        .max_light_lines(2)
        .draw()?;
    let styles = styles(panel);
    // solid curves first, the dashed ones on top
    for dashed in [false, true] {
        for ((s, pts), (color, w)) in panel.series.iter().zip(&curves).zip(&styles) {
            if s.dashed != dashed {
                continue;
            }
            let style = color.stroke_width(*w);
            if dashed {
                chart.draw_series(DashedLineSeries::new(pts.iter().copied(), 7, 5, style))?;
            } else {
                chart.draw_series(LineSeries::new(pts.iter().copied(), style))?;
            }
        }
    }
    for (i, (s, (color, w))) in panel.series.iter().zip(&styles).enumerate() {
        let y = 24 + 22 * i as i32;
        let style = color.stroke_width(*w);
        if s.dashed {
            for x in [4, 17] {
                legend_area.draw(&PathElement::new(vec![(x, y), (x + 8, y)], style))?;
            }
        } else {
            legend_area.draw(&PathElement::new(vec![(4, y), (29, y)], style))?;
        }
        legend_area.draw(&Text::new(
            s.label.clone(),
            (36, y - 8),
            (FONT, 14).into_font().color(&BLACK),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn parse_reads_columns_and_names_bad_lines() {
        let r = Results::parse("t,a\n0,1\n0.5,2\n").unwrap();
        assert_eq!(r.column("a"), Some(&[1.0, 2.0][..]));
        assert_eq!(r.time(), &[0.0, 0.5]);
        assert!(r.column("b").is_none());
        assert_eq!(Results::parse("t,a\n0,x\n").err().map(|e| e.0), Some(2));
        assert_eq!(Results::parse("t,a\n0\n").err().map(|e| e.0), Some(2));
        assert_eq!(Results::parse("x,a\n0,1\n").err().map(|e| e.0), Some(1));
        assert!(Results::parse("").is_err());
        assert!(Results::parse("t\n").is_err());
    }

    #[test]
    fn y_range_pads_and_widens_constants() {
        let c = |v: &[f64]| vec![v.iter().map(|&y| (0.0, y)).collect::<Vec<_>>()];
        let (lo, hi) = y_range(&c(&[0.0, 10.0]));
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
        let (lo, hi) = y_range(&c(&[2.0, 2.0]));
        assert!(lo < 2.0 && hi > 2.0);
        let (lo, hi) = y_range(&c(&[0.0]));
        assert!(lo < 0.0 && hi > 0.0);
        assert_eq!(y_range(&c(&[f64::NAN])), (-1.0, 1.0));
    }
}

/// A map of one value over two swept parameters ([`contour`]).
#[derive(Clone, Debug)]
pub struct Map {
    /// Grid values along x (ascending).
    pub x: Vec<f64>,
    /// Grid values along y (ascending).
    pub y: Vec<f64>,
    /// `z[i][j]` at (`x[i]`, `y[j]`); `None` where the run gave no value.
    pub z: Vec<Vec<Option<f64>>>,
}

/// Bands of a filled-contour map.
const BANDS: usize = 10;

/// The colour of `u` in [0, 1]: light yellow to dark blue (a sequential scale).
fn ramp(u: f64) -> RGBColor {
    let stops = [
        (255.0, 255.0, 204.0),
        (161.0, 218.0, 180.0),
        (65.0, 182.0, 196.0),
        (44.0, 127.0, 184.0),
        (37.0, 52.0, 148.0),
    ];
    let s = u.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let i = (s.floor() as usize).min(stops.len() - 2);
    let f = s - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draw `map` as filled contours (the grid interpolated bilinearly, coloured in ten bands
/// from its minimum to its maximum; cells with a missing corner left blank), with the
/// labels and a colour bar, as a PNG at `path`.
pub fn contour(
    title: &str,
    labels: (&str, &str, &str),
    map: &Map,
    path: &Path,
) -> Result<PathBuf, PlotError> {
    font()?;
    let fail = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let (nx, ny) = (map.x.len(), map.y.len());
    if nx < 2 || ny < 2 || map.z.len() != nx || map.z.iter().any(|r| r.len() != ny) {
        return Err(fail(&"a map needs at least 2 × 2 grid values"));
    }
    let (lo, hi) = map
        .z
        .iter()
        .flatten()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return Err(fail(&"the map has no values"));
    }
    let span = if hi > lo { hi - lo } else { 1.0 };
    let band = |v: f64| {
        let k = ((v - lo) / span * BANDS as f64)
            .floor()
            .clamp(0.0, (BANDS - 1) as f64);
        ramp((k + 0.5) / BANDS as f64)
    };
    let (x0, x1) = (map.x[0], map.x[nx - 1]);
    let (y0, y1) = (map.y[0], map.y[ny - 1]);
    {
        let root = BitMapBackend::new(path, (WIDTH, 620)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let (plot_area, bar_area) = body.split_horizontally(WIDTH - LEGEND_WIDTH - 40);
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| fail(&e))?;
        // a fine raster of bilinear values, each cell one band colour
        let (rx, ry) = (200usize, 120usize);
        let mut cells = Vec::with_capacity(rx * ry);
        for a in 0..rx {
            for b in 0..ry {
                let xa = x0 + (x1 - x0) * a as f64 / rx as f64;
                let xb = x0 + (x1 - x0) * (a + 1) as f64 / rx as f64;
                let ya = y0 + (y1 - y0) * b as f64 / ry as f64;
                let yb = y0 + (y1 - y0) * (b + 1) as f64 / ry as f64;
                let (xm, ym) = (0.5 * (xa + xb), 0.5 * (ya + yb));
                let i = map.x.partition_point(|&v| v <= xm).clamp(1, nx - 1) - 1;
                let j = map.y.partition_point(|&v| v <= ym).clamp(1, ny - 1) - 1;
                let corners = [
                    map.z[i][j],
                    map.z[i + 1][j],
                    map.z[i][j + 1],
                    map.z[i + 1][j + 1],
                ];
                let [Some(z00), Some(z10), Some(z01), Some(z11)] = corners else {
                    continue;
                };
                let u = (xm - map.x[i]) / (map.x[i + 1] - map.x[i]);
                let v = (ym - map.y[j]) / (map.y[j + 1] - map.y[j]);
                let z = z00 * (1.0 - u) * (1.0 - v)
                    + z10 * u * (1.0 - v)
                    + z01 * (1.0 - u) * v
                    + z11 * u * v;
                cells.push(Rectangle::new([(xa, ya), (xb, yb)], band(z).filled()));
            }
        }
        chart.draw_series(cells).map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(labels.0)
            .y_desc(labels.1)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|v| significant(*v))
            .y_label_formatter(&|v| significant(*v))
            .draw()
            .map_err(|e| fail(&e))?;
        // the runs themselves: a dot per grid point, a cross where the run gave no value
        for (i, &x) in map.x.iter().enumerate() {
            for (j, &y) in map.y.iter().enumerate() {
                if map.z[i][j].is_some() {
                    chart
                        .draw_series(std::iter::once(Circle::new((x, y), 2, BLACK.filled())))
                        .map_err(|e| fail(&e))?;
                } else {
                    chart
                        .draw_series(std::iter::once(Cross::new((x, y), 4, RED.stroke_width(2))))
                        .map_err(|e| fail(&e))?;
                }
            }
        }
        // the colour bar: one box per band, its lower bound beside it
        bar_area
            .draw(&Text::new(
                labels.2.to_owned(),
                (4, 8),
                (FONT, 14).into_font().color(&BLACK),
            ))
            .map_err(|e| fail(&e))?;
        for k in 0..BANDS {
            let top_y = 40 + 40 * (BANDS - 1 - k) as i32;
            bar_area
                .draw(&Rectangle::new(
                    [(8, top_y), (34, top_y + 40)],
                    ramp((k as f64 + 0.5) / BANDS as f64).filled(),
                ))
                .map_err(|e| fail(&e))?;
            let at = lo + span * k as f64 / BANDS as f64;
            bar_area
                .draw(&Text::new(
                    significant(at),
                    (40, top_y + 32),
                    (FONT, 13).into_font().color(&BLACK),
                ))
                .map_err(|e| fail(&e))?;
        }
        bar_area
            .draw(&Text::new(
                significant(hi),
                (40, 32),
                (FONT, 13).into_font().color(&BLACK),
            ))
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
