//! `bg-sim plot`: the figures of Cibicik, Pedersen & Egeland (2019), section 6, drawn as PNG
//! from a results CSV of `models/knuckle_boom.toml` (or any CSV with the same columns).
//!
//! | file | the paper's | columns |
//! |---|---|---|
//! | `fig07_coordinates.png` | Fig. 7 | q1, q2, q3; qb1_1..3; qb2_1..3 |
//! | `fig08_lengths.png` | Fig. 8 | l1, l2; ldot1, ldot2 |
//! | `fig09_pressures.png` | Fig. 9 | p_p1, p_r1, p_p2, p_r2 |
//! | `fig10_flows.png` | Fig. 10 | Q_p1, Q_r1, Q_p2, Q_r2 |
//! | `fig11_valves.png` | Fig. 11 | x_v1, x_v2 (and the commands x_c1, x_c2) |
//! | `fig15_link1_end.png` | Fig. 15 | x_e1, y_e1 (and w1_mid) |
//! | `fig16_link2_end.png` | Fig. 16 | x_e2, y_e2 (and w2_mid) |
//! | `fig17_cylinder_forces.png` | Fig. 17 | F_c1, F_c2 |
//! | `fig18_reactions.png` | Fig. 18 | rho1..rho6 (and the paper's variant rho{k}_paper) |
//!
//! A figure whose required columns are missing is skipped (and reported); optional series
//! (drawn dashed) are drawn when their columns are there. Text is set in DejaVu Sans, which
//! the `dejavu` crate ships: no system fonts are needed.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

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

/// One curve: a column, its legend, whether the figure needs it and how it is drawn.
#[derive(Clone, Copy, Debug)]
pub struct Series {
    /// Column name.
    pub column: &'static str,
    /// Legend text.
    pub label: &'static str,
    /// Optional series are drawn only when their column exists; the figure is drawn without
    /// them.
    pub optional: bool,
    /// Drawn as a thin dashed line (a variant or a command beside the main curves).
    pub dashed: bool,
}

/// A required curve.
const fn s(column: &'static str, label: &'static str) -> Series {
    Series {
        column,
        label,
        optional: false,
        dashed: false,
    }
}

/// An optional curve, solid.
const fn opt(column: &'static str, label: &'static str) -> Series {
    Series {
        column,
        label,
        optional: true,
        dashed: false,
    }
}

/// An optional curve, dashed.
const fn variant(column: &'static str, label: &'static str) -> Series {
    Series {
        column,
        label,
        optional: true,
        dashed: true,
    }
}

/// One panel of a figure: curves over time on a common axis.
#[derive(Clone, Copy, Debug)]
pub struct Panel {
    /// The y-axis label, with its unit.
    pub y_label: &'static str,
    /// The column values are divided by this (Pa → MPa: 1e6).
    pub unit: f64,
    /// The curves.
    pub series: &'static [Series],
    /// A close-up: only this time window (s), or the whole run.
    pub window: Option<(f64, f64)>,
}

/// One PNG.
#[derive(Clone, Copy, Debug)]
pub struct Figure {
    /// File name.
    pub file: &'static str,
    /// Title.
    pub title: &'static str,
    /// Panels, top to bottom.
    pub panels: &'static [Panel],
}

/// The paper's figures (section 6).
pub const FIGURES: &[Figure] = &[
    Figure {
        file: "fig07_coordinates.png",
        title: "Fig. 7: generalized coordinates",
        panels: &[
            Panel {
                y_label: "joint angles [rad]",
                unit: 1.0,
                series: &[s("q1", "q1"), s("q2", "q2"), s("q3", "q3")],
                window: None,
            },
            Panel {
                y_label: "Link 1 modes [m]",
                unit: 1.0,
                series: &[
                    s("qb1_1", "qb1_1"),
                    s("qb1_2", "qb1_2"),
                    s("qb1_3", "qb1_3"),
                ],
                window: None,
            },
            Panel {
                y_label: "Link 2 modes [m]",
                unit: 1.0,
                series: &[
                    s("qb2_1", "qb2_1"),
                    s("qb2_2", "qb2_2"),
                    s("qb2_3", "qb2_3"),
                ],
                window: None,
            },
        ],
    },
    Figure {
        file: "fig08_lengths.png",
        title: "Fig. 8: cylinder lengths and their rates",
        panels: &[
            Panel {
                y_label: "length [m]",
                unit: 1.0,
                series: &[s("l1", "l1"), s("l2", "l2")],
                window: None,
            },
            Panel {
                y_label: "rate [m/s]",
                unit: 1.0,
                series: &[s("ldot1", "dl1/dt"), s("ldot2", "dl2/dt")],
                window: None,
            },
        ],
    },
    Figure {
        file: "fig09_pressures.png",
        title: "Fig. 9: chamber pressures",
        panels: &[Panel {
            y_label: "pressure [MPa]",
            unit: 1e6,
            series: &[
                s("p_p1", "P_p1"),
                s("p_r1", "P_r1"),
                s("p_p2", "P_p2"),
                s("p_r2", "P_r2"),
            ],
            window: None,
        }],
    },
    Figure {
        file: "fig10_flows.png",
        title: "Fig. 10: valve flows into the chambers",
        panels: &[Panel {
            y_label: "flow [l/s]",
            unit: 1e-3,
            series: &[
                s("Q_p1", "Q_p1"),
                s("Q_r1", "Q_r1"),
                s("Q_p2", "Q_p2"),
                s("Q_r2", "Q_r2"),
            ],
            window: None,
        }],
    },
    Figure {
        file: "fig11_valves.png",
        title: "Fig. 11: valve strokes",
        panels: &[Panel {
            y_label: "stroke [-]",
            unit: 1.0,
            series: &[
                s("x_v1", "x_v1"),
                s("x_v2", "x_v2"),
                variant("x_c1", "command 1"),
                variant("x_c2", "command 2"),
            ],
            window: None,
        }],
    },
    Figure {
        file: "fig15_link1_end.png",
        title: "Fig. 15: end point of Link 1 (frame 0)",
        panels: &[
            Panel {
                y_label: "x [m]",
                unit: 1.0,
                series: &[s("x_e1", "x_e1")],
                window: None,
            },
            Panel {
                y_label: "y [m]",
                unit: 1.0,
                series: &[s("y_e1", "y_e1")],
                window: None,
            },
            Panel {
                y_label: "mid-span deflection [mm]",
                unit: 1e-3,
                series: &[opt("w1_mid", "w1(L1/2)")],
                window: None,
            },
            Panel {
                y_label: "close-up [mm]",
                unit: 1e-3,
                series: &[opt("w1_mid", "w1(L1/2), 0-2 s")],
                window: Some((0.0, 2.0)),
            },
        ],
    },
    Figure {
        file: "fig16_link2_end.png",
        title: "Fig. 16: end point of Link 2 (frame 0)",
        panels: &[
            Panel {
                y_label: "x [m]",
                unit: 1.0,
                series: &[s("x_e2", "x_e2")],
                window: None,
            },
            Panel {
                y_label: "y [m]",
                unit: 1.0,
                series: &[s("y_e2", "y_e2")],
                window: None,
            },
            Panel {
                y_label: "mid-span deflection [mm]",
                unit: 1e-3,
                series: &[opt("w2_mid", "w2(L2/2)")],
                window: None,
            },
            Panel {
                y_label: "close-up [mm]",
                unit: 1e-3,
                series: &[opt("w2_mid", "w2(L2/2), 0-2 s")],
                window: Some((0.0, 2.0)),
            },
        ],
    },
    Figure {
        file: "fig17_cylinder_forces.png",
        title: "Fig. 17: cylinder forces",
        panels: &[Panel {
            y_label: "force [kN]",
            unit: 1e3,
            series: &[s("F_c1", "F_c1"), s("F_c2", "F_c2")],
            window: None,
        }],
    },
    Figure {
        file: "fig18_reactions.png",
        title: "Fig. 18: reaction forces (dashed: lumped masses rigid with their pins, eqs. 91-94)",
        panels: &[
            Panel {
                y_label: "Joint 1 [kN]",
                unit: 1e3,
                series: &[
                    s("rho1", "rho1"),
                    s("rho2", "rho2"),
                    variant("rho1_paper", "rho1 paper"),
                    variant("rho2_paper", "rho2 paper"),
                ],
                window: None,
            },
            Panel {
                y_label: "Joint 2 [kN]",
                unit: 1e3,
                series: &[
                    s("rho3", "rho3"),
                    s("rho4", "rho4"),
                    variant("rho3_paper", "rho3 paper"),
                    variant("rho4_paper", "rho4 paper"),
                ],
                window: None,
            },
            Panel {
                y_label: "pendulum pivot [kN]",
                unit: 1e3,
                series: &[
                    s("rho5", "rho5"),
                    s("rho6", "rho6"),
                    variant("rho5_paper", "rho5 paper"),
                    variant("rho6_paper", "rho6 paper"),
                ],
                window: None,
            },
        ],
    },
];

/// What became of one figure.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Drawn {
    /// Written to this file.
    Written(PathBuf),
    /// Skipped: these required columns are missing.
    Skipped {
        /// The figure's file name.
        file: &'static str,
        /// The missing columns.
        missing: Vec<&'static str>,
    },
}

const FONT: &str = "sans-serif";
const WIDTH: u32 = 1040;
const PANEL_HEIGHT: u32 = 250;
const TITLE_HEIGHT: u32 = 36;
const LEGEND_WIDTH: u32 = 130;

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

/// Draw every figure of [`FIGURES`] whose columns `results` has into `dir` (created if
/// needed).
pub fn plot_all(results: &Results, dir: &Path) -> Result<Vec<Drawn>, PlotError> {
    std::fs::create_dir_all(dir).map_err(|source| PlotError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
    FIGURES.iter().map(|f| plot(results, f, dir)).collect()
}

/// Draw one figure into `dir`.
pub fn plot(results: &Results, figure: &Figure, dir: &Path) -> Result<Drawn, PlotError> {
    let missing: Vec<&'static str> = figure
        .panels
        .iter()
        .flat_map(|p| p.series.iter())
        .filter(|s| !s.optional && results.column(s.column).is_none())
        .map(|s| s.column)
        .collect();
    let panels: Vec<&Panel> = figure
        .panels
        .iter()
        .filter(|p| p.series.iter().any(|s| results.column(s.column).is_some()))
        .collect();
    if !missing.is_empty() || panels.is_empty() {
        return Ok(Drawn::Skipped {
            file: figure.file,
            missing,
        });
    }
    font()?;
    let path = dir.join(figure.file);
    let fail = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.clone(),
        message: e.to_string(),
    };
    let height = TITLE_HEIGHT + PANEL_HEIGHT * panels.len() as u32;
    {
        let root = BitMapBackend::new(&path, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(figure.title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        for (panel, area) in panels.iter().zip(body.split_evenly((panels.len(), 1))) {
            draw_panel(results, panel, &area).map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(Drawn::Written(path))
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

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type DrawResult<T> =
    Result<T, DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

const COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
];

/// The y range of the curves, padded by 5 % (and widened around a constant).
fn y_range(curves: &[(Series, Vec<(f64, f64)>)]) -> (f64, f64) {
    let (lo, hi) = curves
        .iter()
        .flat_map(|(_, pts)| pts.iter().map(|p| p.1))
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

fn draw_panel(results: &Results, panel: &Panel, area: &Area<'_>) -> DrawResult<()> {
    let t = results.time();
    let (mut t0, mut t1) = (t[0], t[t.len() - 1]);
    if let Some((a, b)) = panel.window {
        (t0, t1) = (t0.max(a), t1.min(b));
    }
    let t1 = t1.max(t0 + 1e-12);
    let curves: Vec<(Series, Vec<(f64, f64)>)> = panel
        .series
        .iter()
        .filter_map(|s| {
            results.column(s.column).map(|c| {
                let pts = t
                    .iter()
                    .zip(c)
                    .filter(|(&t, _)| (t0..=t1).contains(&t))
                    .map(|(&t, &v)| (t, v / panel.unit))
                    .collect();
                (*s, pts)
            })
        })
        .collect();
    let (y0, y1) = y_range(&curves);
    // the legend sits right of the chart, so it never hides a curve
    let (plot_area, legend_area) = area.split_horizontally(WIDTH - LEGEND_WIDTH);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(78)
        .build_cartesian_2d(t0..t1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc(panel.y_label)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .light_line_style(RGBColor(238, 238, 238))
        .max_light_lines(2)
        .draw()?;
    let mut solid = 0;
    let mut dashed = 0;
    for (i, (s, pts)) in curves.into_iter().enumerate() {
        let (color, width) = if s.dashed {
            dashed += 1;
            (COLORS[(dashed - 1) % COLORS.len()].mix(0.9), 1)
        } else {
            solid += 1;
            (COLORS[(solid - 1) % COLORS.len()].mix(1.0), 2)
        };
        let style = color.stroke_width(width);
        let y = 24 + 22 * i as i32;
        if s.dashed {
            chart.draw_series(DashedLineSeries::new(pts, 6, 4, style))?;
            for x in [4, 16] {
                legend_area.draw(&PathElement::new(vec![(x, y), (x + 8, y)], style))?;
            }
        } else {
            chart.draw_series(LineSeries::new(pts, style))?;
            legend_area.draw(&PathElement::new(vec![(4, y), (28, y)], style))?;
        }
        legend_area.draw(&Text::new(
            s.label,
            (34, y - 8),
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
        let c = |v: &[f64]| vec![(s("a", "a"), v.iter().map(|&y| (0.0, y)).collect())];
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
