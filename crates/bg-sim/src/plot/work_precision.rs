//! The work–precision diagram of `bg-sim bench`: error against wall time per method.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, LEGEND_WIDTH, PALETTE, TITLE_HEIGHT, WIDTH};

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
