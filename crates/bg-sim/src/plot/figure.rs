//! The figures of a model's `[[plot]]` tables: panels of curves over a shared time axis,
//! legends beside them, dashed series over paler solid ones.

use std::path::{Path, PathBuf};

use bg_model::plots::{Panel, Plot};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{
    axis, font, on_axis, significant, Format, PlotError, Results, FIG_LEGEND_WIDTH, FIG_WIDTH,
    FONT, PALETTE, PANEL_HEIGHT, TITLE_HEIGHT,
};

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
    // within what an axis can hold: the span of ±1e308 is no f64
    let (lo, hi) = axis(lo, hi);
    let span = hi - lo;
    let pad = if span > 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        0.05 * span
    } else {
        0.5 * lo.abs().max(1e-9)
    };
    axis(lo - pad, hi + pad)
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
    // an axis plotters can draw (a t column of ±1e308 has no finite span)
    let (x0, x1) = axis(x0, x1);
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
    let curves: Vec<Vec<(f64, f64)>> = curves
        .into_iter()
        .map(|pts| {
            pts.into_iter()
                .map(|(x, y)| (x, on_axis(y, (y0, y1))))
                .collect()
        })
        .collect();
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
