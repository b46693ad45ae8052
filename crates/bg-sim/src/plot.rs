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

mod bode;
mod boom;
mod contour;
mod energy;
mod fatigue;
mod figure;
mod quick;
mod results;
mod sea;
mod sensitivity;
mod work_precision;

use std::path::PathBuf;
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::register_font;

pub use bode::bode;
pub use boom::{boom_envelope, BoomLink};
pub use contour::{contour, Map};
pub use energy::{energy_bars, energy_segments, Segment};
pub use fatigue::fatigue;
pub use figure::{draw, draw_all};
pub use quick::quick_look;
pub use results::{not_a_regular_file, Results, PLOT_ROWS};
pub use sea::{sea_figure, SeaSeries};
pub use sensitivity::{sensitivity_bars, SensitivityBar};
pub use work_precision::{work_precision, WorkPrecisionLine};

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

/// A tick label with three significant digits and no trailing zeros (0.3, 12, 0.0025);
/// beyond 1e15 in powers of ten (2.5e20), not in 21 digits.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if v.abs() >= 1e15 {
        let s = format!("{v:.2e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        return format!("{m}e{e}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// The largest magnitude an axis end may have, so that the axis span, its padding and its
/// ticks stay finite: plotters loops forever over an infinite span (1e308 and −1e308 in one
/// column), and f64 holds no span of ±1.8e308.
const AXIS_LIMIT: f64 = 1e306;

/// An axis range plotters can draw from `lo..hi`: both ends finite and within
/// ±[`AXIS_LIMIT`], `lo < hi` by more than f64 resolves there. A range that already is one
/// is returned unchanged; a non-finite or reversed one becomes 0..1; a span too small
/// to resolve is widened around its middle.
fn axis(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) || lo > hi {
        return (0.0, 1.0);
    }
    let (lo, hi) = (
        lo.clamp(-AXIS_LIMIT, AXIS_LIMIT),
        hi.clamp(-AXIS_LIMIT, AXIS_LIMIT),
    );
    let size = lo.abs().max(hi.abs());
    if hi - lo > 1e-12 * size.max(1e-300) {
        return (lo, hi);
    }
    let pad = 0.5 * size.max(1e-9);
    (lo - pad, hi + pad)
}

/// `v` drawn on an axis `lo..hi`: values far outside it are brought to one span beyond
/// its ends (still outside the chart, so clipped), so that no pixel coordinate overflows
/// and no line is rasterised over billions of pixels.
fn on_axis(v: f64, (lo, hi): (f64, f64)) -> f64 {
    let span = hi - lo;
    v.clamp(lo - span, hi + span)
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];
