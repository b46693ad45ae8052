//! The figure of `bg-sim sea --plot`: the record (elevation, and the vessel's motions when
//! an RAO is given) over time, and the record's Welch spectrum against the target spectrum.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, PALETTE, TITLE_HEIGHT, WIDTH};

/// One series of the record: its name (legend) and its samples.
pub struct SeaSeries<'a> {
    /// Legend text, with the unit.
    pub name: &'a str,
    /// Samples at t = k·dt.
    pub values: &'a [f64],
}

/// Draw the sea-state figure as a PNG at `path`: `series` over time (sampled every `dt` s)
/// in the upper panel, its first `window` seconds at most; in the lower, the estimated spectrum `(omega, estimate)` of the
/// elevation and the target `(omega, target)` [m²·s/rad] over frequency.
pub fn sea_figure(
    title: &str,
    series: &[SeaSeries<'_>],
    dt: f64,
    window: f64,
    estimate: (&[f64], &[f64]),
    target: (&[f64], &[f64]),
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
    let all = series.iter().map(|s| s.values.len()).max().unwrap_or(0);
    let n = all.min((window / dt).floor() as usize + 1);
    let t1 = (n.max(2) - 1) as f64 * dt;
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in series {
        for v in s.values.iter().take(n).filter(|v| v.is_finite()) {
            y0 = y0.min(*v);
            y1 = y1.max(*v);
        }
    }
    if y1.partial_cmp(&y0) != Some(std::cmp::Ordering::Greater) {
        (y0, y1) = (-1.0, 1.0);
    }
    let pad = 0.08 * (y1 - y0);
    let w1 = target.0.last().copied().unwrap_or(1.0);
    let s1 = target
        .1
        .iter()
        .chain(
            estimate
                .1
                .iter()
                .zip(estimate.0)
                .filter(|(_, w)| **w <= w1)
                .map(|(s, _)| s),
        )
        .fold(0.0f64, |a, &b| if b.is_finite() { a.max(b) } else { a });
    let s1 = if s1 > 0.0 { 1.1 * s1 } else { 1.0 };
    {
        let root = BitMapBackend::new(path, (WIDTH, 720)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let (upper, lower) = body.split_vertically((720 - TITLE_HEIGHT) / 2);
        let mut chart = ChartBuilder::on(&upper)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(78)
            .build_cartesian_2d(0.0..t1, (y0 - pad)..(y1 + pad))
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc("value")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|v| significant(*v))
            .y_label_formatter(&|v| significant(*v))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        for (k, s) in series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let pts: Vec<(f64, f64)> = s
                .values
                .iter()
                .take(n)
                .enumerate()
                .map(|(j, v)| (j as f64 * dt, *v))
                .collect();
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(|e| fail(&e))?
                .label(s.name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| fail(&e))?;
        let mut chart = ChartBuilder::on(&lower)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(78)
            .build_cartesian_2d(0.0..w1, 0.0..s1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("ω [rad/s]")
            .y_desc("S(ω) [m²·s/rad]")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|v| significant(*v))
            .y_label_formatter(&|v| significant(*v))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        let est: Vec<(f64, f64)> = estimate
            .0
            .iter()
            .zip(estimate.1)
            .filter(|(w, _)| **w <= w1)
            .map(|(w, s)| (*w, *s))
            .collect();
        chart
            .draw_series(LineSeries::new(est, PALETTE[0].stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label("record (Welch estimate)")
            .legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], PALETTE[0].stroke_width(2))
            });
        let tgt: Vec<(f64, f64)> = target
            .0
            .iter()
            .zip(target.1)
            .map(|(w, s)| (*w, *s))
            .collect();
        chart
            .draw_series(DashedLineSeries::new(tgt, 8, 4, BLACK.stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label("target spectrum")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(2)));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
