//! The Bode diagram of `bg-sim linearize --bode IN:OUT`: magnitude (dB) and phase (degrees)
//! over a logarithmic frequency axis, with the poles' natural frequencies marked.

use std::path::{Path, PathBuf};

use bondgraph::BodePoint;
use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, PALETTE, TITLE_HEIGHT, WIDTH};

/// Draw the Bode diagram of `points` (ascending frequencies) as a PNG at `path`; `marks` are
/// frequencies (Hz) drawn as dashed verticals (the poles' natural frequencies in range).
pub fn bode(
    title: &str,
    points: &[BodePoint],
    marks: &[f64],
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
    let pts: Vec<&BodePoint> = points
        .iter()
        .filter(|p| p.f_hz > 0.0 && p.db.is_finite() && p.phase_deg.is_finite())
        .collect();
    let (f0, f1) = match (pts.first(), pts.last()) {
        (Some(a), Some(b)) if b.f_hz > a.f_hz => (a.f_hz, b.f_hz),
        _ => (0.1, 100.0),
    };
    let range = |v: &dyn Fn(&BodePoint) -> f64, pad: f64| {
        let (lo, hi) = pts
            .iter()
            .map(|p| v(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        if lo.is_finite() && hi > lo {
            (lo - pad * (hi - lo), hi + pad * (hi - lo))
        } else if lo.is_finite() {
            (lo - 1.0, lo + 1.0)
        } else {
            (-1.0, 1.0)
        }
    };
    let (m0, m1) = range(&|p| p.db, 0.08);
    let (p0, p1) = range(&|p| p.phase_deg, 0.08);
    {
        let root = BitMapBackend::new(path, (WIDTH, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let (upper, lower) = body.split_vertically((640 - TITLE_HEIGHT) / 2);
        let magnitude: fn(&BodePoint) -> f64 = |p| p.db;
        let phase: fn(&BodePoint) -> f64 = |p| p.phase_deg;
        let panels = [
            (&upper, "magnitude [dB]", (m0, m1), magnitude, false),
            (&lower, "phase [°]", (p0, p1), phase, true),
        ];
        for (k, (area, label, (y0, y1), value, last)) in panels.into_iter().enumerate() {
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(if last { 40 } else { 10 })
                .y_label_area_size(78)
                .build_cartesian_2d((f0..f1).log_scale(), y0..y1)
                .map_err(|e| fail(&e))?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(label)
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 15))
                .x_label_formatter(&|v| significant(*v))
                .y_label_formatter(&|v| significant(*v))
                .light_line_style(RGBColor(245, 245, 245));
            if last {
                mesh.x_desc("frequency [Hz]");
            } else {
                mesh.x_labels(0);
            }
            mesh.draw().map_err(|e| fail(&e))?;
            for &f in marks.iter().filter(|f| (f0..=f1).contains(*f)) {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(f, y0), (f, y1)],
                        6,
                        4,
                        RGBColor(150, 150, 150).stroke_width(1),
                    ))
                    .map_err(|e| fail(&e))?;
            }
            let line: Vec<(f64, f64)> = pts.iter().map(|p| (p.f_hz, value(p))).collect();
            chart
                .draw_series(LineSeries::new(line, PALETTE[k].stroke_width(2)))
                .map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
