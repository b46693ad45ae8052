//! The figure "the boom drawn with its envelope" of `bg-sim stress --plot`: the arm in one
//! pose (each link as the straight chord between its joint and its end), and along each
//! flexible link its bending-moment envelope over the run (max and min M at every x) as a
//! filled band drawn perpendicular to the chord, on the tension side (a sagging M > 0 below
//! the chord, a hogging M < 0 above it: the +y "top" side of the link's frame,
//! docs/stress.md), with the hot spot marked. Equal scales on both axes; the moments share
//! one scale, given in the legend.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, PALETTE, TITLE_HEIGHT, WIDTH};

/// Points in frame 0 (m).
type Polyline = Vec<(f64, f64)>;

/// One link of the drawing.
pub struct BoomLink<'a> {
    /// Its joint and its end in frame 0 (m).
    pub start: (f64, f64),
    /// The end of its chord (m).
    pub end: (f64, f64),
    /// The sections along the chord from the joint (m) and the moment envelope there (N·m);
    /// empty for a link without one (drawn as a thin line: a pendulum, a rigid link).
    pub x: &'a [f64],
    /// Max of M over the run at each x (N·m).
    pub max: &'a [f64],
    /// Min of M over the run at each x (N·m).
    pub min: &'a [f64],
    /// The legend text of the band.
    pub label: String,
    /// The hot spot: its distance from the joint (m) and its label.
    pub hot: Option<(f64, String)>,
}

/// Draw the arm `links` in one pose with its moment envelopes as a PNG at `path`.
pub fn boom_envelope(
    title: &str,
    links: &[BoomLink<'_>],
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
    let length = |l: &BoomLink<'_>| (l.end.0 - l.start.0).hypot(l.end.1 - l.start.1);
    let longest = links.iter().map(length).fold(0.0, f64::max).max(1e-9);
    let m_abs = links
        .iter()
        .flat_map(|l| l.max.iter().chain(l.min))
        .filter(|v| v.is_finite())
        .fold(0.0f64, |a, v| a.max(v.abs()));
    // the largest |M| is drawn 0.2 of the longest link away from its chord
    let scale = if m_abs > 0.0 {
        0.2 * longest / m_abs
    } else {
        0.0
    };
    // a point at distance x along link l, offset by the moment m drawn on the tension side
    let at = |l: &BoomLink<'_>, x: f64, m: f64| {
        let len = length(l).max(1e-12);
        let (ux, uy) = ((l.end.0 - l.start.0) / len, (l.end.1 - l.start.1) / len);
        // ŷ = (−uy, ux) is the top side; a sagging M > 0 is drawn below (−ŷ)
        let off = -m * scale;
        (l.start.0 + ux * x - uy * off, l.start.1 + uy * x + ux * off)
    };
    let bands: Vec<(Polyline, Polyline)> = links
        .iter()
        .map(|l| {
            let up: Vec<_> = (0..l.x.len())
                .filter(|&j| l.max[j].is_finite() && l.min[j].is_finite())
                .map(|j| at(l, l.x[j], l.max[j]))
                .collect();
            let down: Vec<_> = (0..l.x.len())
                .filter(|&j| l.max[j].is_finite() && l.min[j].is_finite())
                .map(|j| at(l, l.x[j], l.min[j]))
                .collect();
            (up, down)
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for p in links
        .iter()
        .flat_map(|l| [l.start, l.end])
        .chain(bands.iter().flat_map(|(a, b)| a.iter().chain(b).copied()))
    {
        x0 = x0.min(p.0);
        x1 = x1.max(p.0);
        y0 = y0.min(p.1);
        y1 = y1.max(p.1);
    }
    let pad = 0.08 * (x1 - x0).max(y1 - y0).max(1e-9);
    let (x0, x1, y0, y1) = (x0 - pad, x1 + pad, y0 - pad, y1 + pad);
    // equal scales: the plot area's height follows the data's aspect
    let (label_x, label_y, margin) = (50u32, 60u32, 14u32);
    let area_w = WIDTH - label_y - 2 * margin;
    let area_h = ((f64::from(area_w) * (y1 - y0) / (x1 - x0)).round() as u32).clamp(200, 1400);
    let height = TITLE_HEIGHT + area_h + label_x + 2 * margin;
    {
        let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let mut chart = ChartBuilder::on(&body)
            .margin(margin)
            .x_label_area_size(label_x)
            .y_label_area_size(label_y)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("x₀ [m]")
            .y_desc("y₀ [m]")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .x_label_formatter(&|v| significant(*v))
            .y_label_formatter(&|v| significant(*v))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        for (k, (l, (up, down))) in links.iter().zip(&bands).enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            if !up.is_empty() {
                let mut poly = up.clone();
                poly.extend(down.iter().rev());
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        poly,
                        colour.mix(0.3).filled(),
                    )))
                    .map_err(|e| fail(&e))?
                    .label(l.label.clone())
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 18, y + 5)], colour.mix(0.3).filled())
                    });
                for edge in [up, down] {
                    chart
                        .draw_series(LineSeries::new(edge.clone(), colour.stroke_width(1)))
                        .map_err(|e| fail(&e))?;
                }
            }
            let wide = if l.x.is_empty() { 2 } else { 5 };
            chart
                .draw_series(LineSeries::new(
                    vec![l.start, l.end],
                    RGBColor(40, 40, 40).stroke_width(wide),
                ))
                .map_err(|e| fail(&e))?;
            chart
                .draw_series([l.start, l.end].map(|p| Circle::new(p, 5, WHITE.filled())))
                .map_err(|e| fail(&e))?;
            chart
                .draw_series([l.start, l.end].map(|p| Circle::new(p, 5, BLACK.stroke_width(2))))
                .map_err(|e| fail(&e))?;
        }
        // the hot spots: marked on their links, told in the legend
        for l in links {
            if let Some((x, text)) = &l.hot {
                let p = at(l, *x, 0.0);
                chart
                    .draw_series([
                        Circle::new(p, 8, RED.stroke_width(3)),
                        Circle::new(p, 3, RED.filled()),
                    ])
                    .map_err(|e| fail(&e))?
                    .label(text.clone())
                    .legend(|(x, y)| Circle::new((x + 9, y), 5, RED.stroke_width(2)));
            }
        }
        if m_abs > 0.0 {
            let per_m = 1.0 / scale;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x0, y0), (x0, y0)],
                    WHITE.stroke_width(0),
                )))
                .map_err(|e| fail(&e))?
                .label(format!(
                    "moment scale: 1 m = {} kN·m, drawn on the tension side",
                    significant(per_m * 1e-3)
                ))
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], WHITE.stroke_width(0))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(200, 200, 200))
            .label_font((FONT, 13))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}
