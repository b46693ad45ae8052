//! The map of `bg-sim sweep-plot`: one summary column over two swept parameters as filled
//! contour bands.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, LEGEND_WIDTH, TITLE_HEIGHT, WIDTH};

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
