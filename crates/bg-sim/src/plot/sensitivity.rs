//! The figure of `bg-sim sensitivity`: the ranking of normalised sensitivities as
//! horizontal bars, the largest first (RMS over the run dark, maximum light behind it).

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{font, PlotError, FONT, TITLE_HEIGHT};

/// One bar: its label (`y / p`), the RMS and the maximum of |p/scale(y)·∂y/∂p| over the run.
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivityBar {
    /// `output / parameter`.
    pub label: String,
    /// RMS over the run.
    pub rms: f64,
    /// Maximum over the run.
    pub max: f64,
}

/// Draw `bars` (already ranked, at most a few dozen) as a PNG at `path`.
pub fn sensitivity_bars(
    title: &str,
    subtitle: &str,
    bars: &[SensitivityBar],
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
    let n = bars.len().max(1);
    let (w, h) = (1000u32, TITLE_HEIGHT + 110 + 26 * n as u32);
    let top = bars
        .iter()
        .map(|b| b.max.max(b.rms))
        .fold(0.0f64, f64::max)
        .max(1e-300)
        * 1.3;
    {
        let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (head, body) = root.split_vertically(TITLE_HEIGHT + 22);
        head.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        head.draw(&Text::new(
            subtitle.to_owned(),
            (12, TITLE_HEIGHT as i32 - 2),
            (FONT, 14).into_font(),
        ))
        .map_err(|e| fail(&e))?;
        let mut chart = ChartBuilder::on(&body)
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(30)
            .build_cartesian_2d(0.0..top, 0.0..n as f64)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(0)
            .x_desc("|p / scale(y) · ∂y/∂p|   (dark: RMS over the run, light: maximum)")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(|e| fail(&e))?;
        let light = RGBColor(158, 202, 225);
        let dark = RGBColor(33, 113, 181);
        for (i, b) in bars.iter().enumerate() {
            // the largest at the top
            let row = (n - 1 - i) as f64;
            for (value, colour, inset) in [(b.max, light, 0.12), (b.rms, dark, 0.26)] {
                let rect = Rectangle::new(
                    [(0.0, row + inset), (value, row + 1.0 - inset)],
                    colour.filled(),
                );
                chart
                    .draw_series(std::iter::once(rect))
                    .map_err(|e| fail(&e))?;
            }
            let text = Text::new(
                b.label.clone(),
                (b.max.max(b.rms) + 0.01 * top, row + 0.75),
                (FONT, 14).into_font(),
            );
            chart
                .draw_series(std::iter::once(text))
                .map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
