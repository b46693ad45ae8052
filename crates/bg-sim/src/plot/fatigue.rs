//! The figure of `bg-sim fatigue --plot FILE`: left, the rainflow histogram (cycles per
//! range bin); right, the S–N curve on log–log axes with the history's spectrum on it (the
//! number of cycles at or above each range, against SCF·range): per pass, and over the
//! predicted life (per pass × the passes to D = 1).

use std::path::{Path, PathBuf};

use bg_fatigue::{Cycle, SnCurve};
use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, PALETTE, TITLE_HEIGHT, WIDTH};

/// Bins of the histogram.
const BINS: usize = 24;

/// Draw the fatigue figure of `cycles` (ranges in the column's unit; `scf` times that in Pa
/// for the S–N curve `curve`) as a PNG at `path`; `life` is the number of passes to D = 1,
/// if finite. `unit` labels the histogram's axis.
pub fn fatigue(
    title: &str,
    cycles: &[Cycle],
    curve: &SnCurve,
    scf: f64,
    life: Option<f64>,
    unit: &str,
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
    let r_max = cycles
        .iter()
        .map(|c| c.range)
        .filter(|r| r.is_finite())
        .fold(0.0_f64, f64::max);
    let width = if r_max > 0.0 {
        r_max / BINS as f64
    } else {
        1.0
    };
    let mut bins = [0.0_f64; BINS];
    for c in cycles {
        // truncation picks the bin; the largest range goes into the last one
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let k = ((c.range / width) as usize).min(BINS - 1);
        bins[k] += c.count;
    }
    let n_max = bins.iter().copied().fold(0.0_f64, f64::max).max(1.0);
    // the spectrum: cycles at or above each range (Pa, with the SCF), largest range first
    let mut sorted: Vec<&Cycle> = cycles.iter().filter(|c| c.range > 0.0).collect();
    sorted.sort_by(|a, b| b.range.total_cmp(&a.range));
    let mut cum = 0.0;
    let spectrum: Vec<(f64, f64)> = sorted
        .iter()
        .map(|c| {
            cum += c.count;
            (cum, scf * c.range)
        })
        .collect();
    // the S–N axes: N from 0.1 (a half cycle per pass) to 1e9, Δσ from a third of the curve's range at 1e9 (smaller
    // ranges do little or no damage) to above the largest range and the curve at 1e4
    let (n0, n1) = (0.1_f64, 1e9_f64);
    let s_curve = |n: f64| curve.range_at(n);
    let s_hi = spectrum.iter().map(|p| p.1).fold(s_curve(1e4), f64::max) * 1.5;
    let s_lo = s_curve(n1) / 3.0;
    {
        let root = BitMapBackend::new(path, (WIDTH, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let (left, right) = body.split_horizontally(WIDTH / 2);
        let mut hist = ChartBuilder::on(&left)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..width * BINS as f64, 0.0..n_max * 1.1)
            .map_err(|e| fail(&e))?;
        hist.configure_mesh()
            .x_desc(format!("range [{unit}]"))
            .y_desc("cycles per pass")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .x_labels(6)
            .x_label_formatter(&|v| format!("{v:.2e}"))
            .y_label_formatter(&|v| significant(*v))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        hist.draw_series(
            bins.iter()
                .enumerate()
                .filter(|b| *b.1 > 0.0)
                .map(|(k, n)| {
                    let x = k as f64 * width;
                    Rectangle::new([(x, 0.0), (x + width, *n)], PALETTE[0].mix(0.7).filled())
                }),
        )
        .map_err(|e| fail(&e))?;
        let mut sn = ChartBuilder::on(&right)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d((n0..n1).log_scale(), (s_lo..s_hi).log_scale())
            .map_err(|e| fail(&e))?;
        sn.configure_mesh()
            .x_desc("cycles N")
            .y_desc("stress range [MPa]")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| significant(*v / 1e6))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        let line: Vec<(f64, f64)> = (0..=240)
            .map(|k| {
                let n = n0 * (n1 / n0).powf(f64::from(k) / 240.0);
                (n, s_curve(n))
            })
            .filter(|p| curve.cutoff.is_none_or(|c| p.1 >= c * (1.0 - 1e-9)))
            .filter(|p| p.1 <= s_hi)
            .collect();
        sn.draw_series(LineSeries::new(line, PALETTE[1].stroke_width(2)))
            .map_err(|e| fail(&e))?
            .label(format!("S–N {}", curve.label))
            .legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], PALETTE[1].stroke_width(2))
            });
        if let Some(c) = curve.cutoff {
            let n_cut = curve.cycles(c * (1.0 + 1e-12));
            sn.draw_series(LineSeries::new(
                vec![(n_cut, c), (n1, c)],
                PALETTE[1].stroke_width(1),
            ))
            .map_err(|e| fail(&e))?;
        }
        let scaled = |factor: f64| -> Vec<(f64, f64)> {
            spectrum
                .iter()
                .map(|&(n, s)| (n * factor, s))
                .filter(|p| p.1 >= s_lo && (n0..=n1).contains(&p.0))
                .collect()
        };
        let mut lines = vec![(
            scaled(1.0),
            format!("spectrum per pass (SCF {})", significant(scf)),
            PALETTE[0],
        )];
        if let Some(l) = life.filter(|l| l.is_finite() && *l > 0.0) {
            lines.push((
                scaled(l),
                format!("over the life ({} passes)", significant(l)),
                PALETTE[2],
            ));
        }
        for (pts, label, colour) in lines {
            sn.draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(|e| fail(&e))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                });
            sn.draw_series(pts.iter().map(|p| Circle::new(*p, 2, colour.filled())))
                .map_err(|e| fail(&e))?;
        }
        sn.configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(200, 200, 200))
            .label_font((FONT, 13))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
