//! The energy figure of `bg-sim energy --plot`: two stacked bars, Sankey-style — where the
//! energy came from (the sources, energy released by storages) and where it went (work on
//! loads, energy stored, the losses of each component) — one segment per composite, losses
//! in warm colours, useful work in cool ones, with a legend of every segment.

use std::path::{Path, PathBuf};

use bondgraph::{EnergyReport, EnergyRole};
use plotters::prelude::*;

use super::{font, significant, PlotError, FONT, TITLE_HEIGHT};

/// One segment of a bar: what, how much (J), and whether it is a loss.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// The composite (or element) and what it did: `pump (shaft)`, `relief (loss)`.
    pub label: String,
    /// Energy, J (positive).
    pub value: f64,
    /// A loss (dissipated) rather than useful work or storage.
    pub loss: bool,
}

/// The two bars of the figure: (came from, went to), each segment positive, largest first
/// within each kind (useful first, then losses).
#[must_use]
pub fn energy_segments(report: &EnergyReport, expand: bool) -> (Vec<Segment>, Vec<Segment>) {
    let rows = if expand {
        report.elements.clone()
    } else {
        report.by_composite()
    };
    let (mut came, mut useful, mut losses) = (Vec::new(), Vec::new(), Vec::new());
    let seg = |name: &str, what: &str, value: f64, loss: bool| Segment {
        label: format!("{name} ({what})"),
        value,
        loss,
    };
    for r in &rows {
        if r.supplied > 0.0 {
            came.push(seg(&r.name, "supplied", r.supplied, false));
        } else if r.supplied < 0.0 {
            useful.push(seg(&r.name, "work on it", -r.supplied, false));
        }
        if r.stored < 0.0 {
            came.push(seg(&r.name, "released", -r.stored, false));
        } else if r.stored > 0.0 && r.role != EnergyRole::Conservative {
            useful.push(seg(&r.name, "stored", r.stored, false));
        }
        if r.dissipated > 0.0 {
            losses.push(seg(&r.name, "loss", r.dissipated, true));
        }
    }
    let by_size = |v: &mut Vec<Segment>| v.sort_by(|a, b| b.value.total_cmp(&a.value));
    by_size(&mut came);
    by_size(&mut useful);
    by_size(&mut losses);
    useful.extend(losses);
    (small_as_others(came), small_as_others(useful))
}

/// Segments below 1 % of their bar summed into one `others` segment (a loss if they all are).
fn small_as_others(v: Vec<Segment>) -> Vec<Segment> {
    let total: f64 = v.iter().map(|s| s.value).sum();
    let (keep, small): (Vec<Segment>, Vec<Segment>) =
        v.into_iter().partition(|s| s.value >= 0.01 * total);
    let mut keep = keep;
    match small.len() {
        0 => {}
        1 => keep.extend(small),
        n => keep.push(Segment {
            label: format!("{n} others (each < 1 %)"),
            value: small.iter().map(|s| s.value).sum(),
            loss: small.iter().all(|s| s.loss),
        }),
    }
    keep
}

const COOL: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(23, 190, 207),
    RGBColor(107, 174, 214),
    RGBColor(116, 196, 118),
    RGBColor(57, 59, 121),
    RGBColor(82, 84, 163),
];
const WARM: [RGBColor; 6] = [
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
    RGBColor(227, 119, 194),
    RGBColor(140, 86, 75),
    RGBColor(250, 170, 90),
    RGBColor(240, 110, 100),
];
const GREY: RGBColor = RGBColor(150, 150, 150);

/// Energy in J, kJ or MJ, three significant digits.
fn energy_label(v: f64) -> String {
    let (x, unit) = if v.abs() >= 1e6 {
        (v / 1e6, "MJ")
    } else if v.abs() >= 1e3 {
        (v / 1e3, "kJ")
    } else {
        (v, "J")
    };
    format!("{} {unit}", significant(x))
}

/// Draw the energy figure of `report` as a PNG at `path`; the subtitle line says the
/// overall efficiency (`useful / input`) when there is an input.
pub fn energy_bars(
    title: &str,
    report: &EnergyReport,
    expand: bool,
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
    let (came, went) = energy_segments(report, expand);
    let total = |v: &[Segment]| v.iter().map(|s| s.value).sum::<f64>();
    let width_j = total(&came).max(total(&went)).max(1e-300);
    // Colours: sources and useful work cool, losses warm, cycling; each label keeps its colour
    // on both bars.
    let mut colours: Vec<(String, RGBColor)> = Vec::new();
    let (mut n_cool, mut n_warm) = (0, 0);
    for s in came.iter().chain(&went) {
        if colours.iter().any(|(l, _)| *l == s.label) {
            continue;
        }
        let c = if s.label.contains(" others (") {
            GREY
        } else if s.loss {
            n_warm += 1;
            WARM[(n_warm - 1) % WARM.len()]
        } else {
            n_cool += 1;
            COOL[(n_cool - 1) % COOL.len()]
        };
        colours.push((s.label.clone(), c));
    }
    let colour = |label: &str| {
        colours
            .iter()
            .find(|(l, _)| l == label)
            .map_or(GREY, |(_, c)| *c)
    };
    let legend_rows = came.len() + went.len();
    let (w, legend_w) = (1100u32, 330u32);
    let h = (TITLE_HEIGHT + 60 + 20 * legend_rows as u32).max(420);
    {
        let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (top, body) = root.split_vertically(TITLE_HEIGHT + 22);
        top.titled(title, (FONT, 20).into_font().style(FontStyle::Bold))
            .map_err(|e| fail(&e))?;
        let e = crate::energy::Efficiency::of(report);
        let sub = if e.input > 0.0 {
            format!(
                "input {}, useful {} (work on loads {}, stored {}), losses {}: efficiency {:.1} %   (t = {} … {} s)",
                energy_label(e.input),
                energy_label(e.useful),
                energy_label(e.work_on_sources),
                energy_label(e.stored),
                energy_label(e.losses),
                100.0 * e.efficiency,
                report.t_start,
                report.t_end
            )
        } else {
            format!(
                "no source delivered energy: initial stored {}, losses {}   (t = {} … {} s)",
                energy_label(report.stored_initial),
                energy_label(e.losses),
                report.t_start,
                report.t_end
            )
        };
        top.draw(&Text::new(
            sub,
            (12, TITLE_HEIGHT as i32 - 2),
            (FONT, 14).into_font(),
        ))
        .map_err(|e| fail(&e))?;
        let (plot_area, legend_area) = body.split_horizontally(w - legend_w);
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(120)
            .build_cartesian_2d(0.0..width_j * 1.02, 0.0..2.0)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(5)
            .y_label_formatter(&|y: &f64| {
                if (*y - 1.5).abs() < 0.3 {
                    "came from".into()
                } else if (*y - 0.5).abs() < 0.3 {
                    "went to".into()
                } else {
                    String::new()
                }
            })
            .x_label_formatter(&|x: &f64| energy_label(*x))
            .x_desc("energy")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .map_err(|e| fail(&e))?;
        for (bar, y) in [(&came, 1.5), (&went, 0.5)] {
            let mut x = 0.0;
            for s in bar {
                let c = colour(&s.label);
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(x, y - 0.32), (x + s.value, y + 0.32)],
                        c.filled(),
                    )))
                    .map_err(|e| fail(&e))?;
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(x, y - 0.32), (x + s.value, y + 0.32)],
                        WHITE.stroke_width(1),
                    )))
                    .map_err(|e| fail(&e))?;
                if s.value > 0.09 * width_j {
                    let name = s.label.split(" (").next().unwrap_or(&s.label).to_owned();
                    let style = (FONT, 13).into_font().color(&WHITE);
                    chart
                        .draw_series([
                            Text::new(name, (x + 0.01 * width_j, y + 0.1), style.clone()),
                            Text::new(energy_label(s.value), (x + 0.01 * width_j, y - 0.05), style),
                        ])
                        .map_err(|e| fail(&e))?;
                }
                x += s.value;
            }
        }
        let mut ly = 16;
        for (head, bar) in [("came from", &came), ("went to", &went)] {
            legend_area
                .draw(&Text::new(
                    head,
                    (8, ly),
                    (FONT, 14).into_font().style(FontStyle::Bold),
                ))
                .map_err(|e| fail(&e))?;
            ly += 20;
            let sum = total(bar).max(1e-300);
            for s in bar.iter() {
                legend_area
                    .draw(&Rectangle::new(
                        [(8, ly + 2), (22, ly + 14)],
                        colour(&s.label).filled(),
                    ))
                    .map_err(|e| fail(&e))?;
                legend_area
                    .draw(&Text::new(
                        format!(
                            "{}  {}  {:.1} %",
                            s.label,
                            energy_label(s.value),
                            100.0 * s.value / sum
                        ),
                        (28, ly + 2),
                        (FONT, 12).into_font(),
                    ))
                    .map_err(|e| fail(&e))?;
                ly += 20;
            }
            ly += 8;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(path.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;
    use bondgraph::ElementEnergy;

    fn el(
        name: &str,
        role: EnergyRole,
        supplied: f64,
        stored: f64,
        dissipated: f64,
    ) -> ElementEnergy {
        ElementEnergy {
            name: name.into(),
            kind: "k".into(),
            composite: name.into(),
            role,
            supplied,
            stored,
            dissipated,
            net: 0.0,
            activity: 0.0,
            share: 0.0,
            through: 0.0,
            stored_by_function: false,
        }
    }

    #[test]
    fn the_two_bars_balance() {
        let r = EnergyReport {
            elements: vec![
                el("pump", EnergyRole::Source, 100.0, 0.0, 0.0),
                el("gravity", EnergyRole::Source, -30.0, 0.0, 0.0),
                el("acc", EnergyRole::Storage, 0.0, -10.0, 0.0),
                el("valve", EnergyRole::Dissipation, 0.0, 0.0, 80.0),
            ],
            ..EnergyReport::default()
        };
        let (came, went) = energy_segments(&r, false);
        let sum = |v: &[Segment]| v.iter().map(|s| s.value).sum::<f64>();
        assert!((sum(&came) - 110.0).abs() < 1e-12);
        assert!((sum(&went) - 110.0).abs() < 1e-12);
        assert_eq!(went[0].label, "gravity (work on it)");
        assert!(went[1].loss);
        let dir = tempfile::tempdir().unwrap();
        let p = energy_bars("test", &r, false, &dir.path().join("e.png")).unwrap();
        assert!(std::fs::metadata(p).unwrap().len() > 1000);
    }
}
