//! The figures of `bg-sim stress --plot DIR`: each link's envelopes along x and its hot
//! spot's history; per arm, the boom drawn in the pose of its hot spot with the moment
//! envelopes.

use std::fmt::Write as _;
use std::path::PathBuf;

use super::{LinkEnvelope, QUANTITIES};

/// The envelope of each link along x (N, V, M, σ) and the hot spots' histories.
pub(super) fn figures(
    dir: &std::path::Path,
    links: &[LinkEnvelope],
    poses: &[(String, Vec<(String, String)>)],
    tr: &bondgraph::Trajectory,
    title: &str,
) -> Result<Vec<PathBuf>, String> {
    use bg_model::plots::{Panel, Plot, Series};
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let series = |column: &str, label: &str, scale: f64, dashed: bool| Series {
        column: column.to_owned(),
        label: label.to_owned(),
        scale,
        offset: 0.0,
        dashed,
        line: 0,
    };
    let mut written = Vec::new();
    for l in links {
        // the plotting reads a CSV whose first column is `t`: here it holds x
        let mut csv = String::from("t");
        for q in QUANTITIES {
            let _ = write!(csv, ",{q}_max,{q}_min");
        }
        csv.push('\n');
        for j in 0..l.x.len() {
            let _ = write!(csv, "{}", l.x[j]);
            for e in &l.env {
                let _ = write!(csv, ",{},{}", e.max[j], e.min[j]);
            }
            csv.push('\n');
        }
        let results = bg_sim::plot::Results::parse(&csv).map_err(|(_, m)| m)?;
        let panel = |y: &str, unit: &str, cols: &[(&str, &str, f64, bool)]| Panel {
            y_label: y.to_owned(),
            unit: Some(unit.to_owned()),
            x_range: None,
            series: cols
                .iter()
                .map(|(c, lab, s, d)| series(c, lab, *s, *d))
                .collect(),
            line: 0,
        };
        let mut panels = vec![
            panel(
                "bending moment",
                "kN·m",
                &[
                    ("M_max", "max over the run", 1e-3, false),
                    ("M_min", "min over the run", 1e-3, true),
                ],
            ),
            panel(
                "shear force",
                "kN",
                &[("V_max", "max", 1e-3, false), ("V_min", "min", 1e-3, true)],
            ),
            panel(
                "axial force",
                "kN",
                &[("N_max", "max", 1e-3, false), ("N_min", "min", 1e-3, true)],
            ),
        ];
        if l.has_sigma {
            panels.push(panel(
                "normal stress",
                "MPa",
                &[
                    ("sigma_top_max", "top fibre, max", 1e-6, false),
                    ("sigma_top_min", "top fibre, min", 1e-6, true),
                    ("sigma_bottom_max", "bottom fibre, max", 1e-6, false),
                    ("sigma_bottom_min", "bottom fibre, min", 1e-6, true),
                ],
            ));
        }
        let plot = Plot {
            file: format!("stress-envelope-{}-link{}", l.arm, l.link),
            title: format!("{title}: link {} envelopes over the run", l.link),
            x: "t".to_owned(),
            x_label: "distance from the joint along the link [m]".to_owned(),
            panels,
            line: 0,
        };
        written.extend(
            bg_sim::plot::draw(&results, &plot, dir, bg_sim::plot::Format::Png)
                .map_err(|e| e.to_string())?,
        );
        if let Some((j, _, _, column)) = &l.hot {
            let hist = tr.column(column).unwrap_or_default();
            let t = tr.column("t").unwrap_or_default();
            let mut csv = String::from("t,sigma\n");
            for (a, b) in t.iter().zip(&hist) {
                let _ = writeln!(csv, "{a},{b}");
            }
            let results = bg_sim::plot::Results::parse(&csv).map_err(|(_, m)| m)?;
            let plot = Plot {
                file: format!("stress-hot-spot-{}-link{}", l.arm, l.link),
                title: format!(
                    "{title}: link {} hot spot at x = {:.3} m ({})",
                    l.link,
                    l.x[*j],
                    if column.contains("sigma_top") {
                        "top fibre"
                    } else {
                        "bottom fibre"
                    }
                ),
                x: "t".to_owned(),
                x_label: "time [s]".to_owned(),
                panels: vec![panel(
                    "normal stress",
                    "MPa",
                    &[("sigma", "σ at the hot spot", 1e-6, false)],
                )],
                line: 0,
            };
            written.extend(
                bg_sim::plot::draw(&results, &plot, dir, bg_sim::plot::Format::Png)
                    .map_err(|e| e.to_string())?,
            );
        }
    }
    for (arm, ends) in poses {
        written.extend(boom_figure(dir, arm, ends, links, tr)?);
    }
    Ok(written)
}

/// The arm `arm` drawn in the pose of its largest hot spot (the chords' ends `ends`, columns
/// of `tr`) with each link's moment envelope: `stress-boom-<arm>.png`; nothing for an arm
/// without a hot spot.
fn boom_figure(
    dir: &std::path::Path,
    arm: &str,
    ends: &[(String, String)],
    links: &[LinkEnvelope],
    tr: &bondgraph::Trajectory,
) -> Result<Option<PathBuf>, String> {
    let mine: Vec<&LinkEnvelope> = links.iter().filter(|l| l.arm == arm).collect();
    let Some((hot_link, t_hot)) = mine
        .iter()
        .filter_map(|l| l.hot.as_ref().map(|h| (l.link, h.1, h.2)))
        .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()))
        .map(|(k, t, _)| (k, t))
    else {
        return Ok(None);
    };
    let t = tr.column("t").unwrap_or_default();
    // the hot spot's row (its time is one of the column's)
    let Some(row) =
        (0..t.len()).min_by(|&a, &b| (t[a] - t_hot).abs().total_cmp(&(t[b] - t_hot).abs()))
    else {
        return Ok(None);
    };
    let mut start = (0.0, 0.0);
    let mut drawn = Vec::new();
    let empty: &[f64] = &[];
    for (i, (cx, cy)) in ends.iter().enumerate() {
        let (xs, ys) = (
            tr.column(cx).unwrap_or_default(),
            tr.column(cy).unwrap_or_default(),
        );
        let (Some(x), Some(y)) = (xs.get(row), ys.get(row)) else {
            return Ok(None);
        };
        let end = (*x, *y);
        let env = mine.iter().find(|l| l.link == i + 1);
        drawn.push(bg_sim::plot::BoomLink {
            start,
            end,
            x: env.map_or(empty, |l| &l.x),
            max: env.map_or(empty, |l| &l.env[2].max),
            min: env.map_or(empty, |l| &l.env[2].min),
            label: format!("link {}: M envelope over the run (max to min)", i + 1),
            hot: env.and_then(|l| {
                l.hot.as_ref().map(|(j, th, s, _)| {
                    (
                        l.x[*j],
                        format!(
                            "hot spot of link {}: σ = {:.0} MPa at x = {:.2} m, t = {th:.2} s",
                            l.link,
                            s * 1e-6,
                            l.x[*j]
                        ),
                    )
                })
            }),
        });
        start = end;
    }
    let path = dir.join(format!("stress-boom-{arm}.png"));
    bg_sim::plot::boom_envelope(
        &format!(
            "{arm}: bending-moment envelopes, pose at t = {t_hot:.2} s (hot spot of link {hot_link})"
        ),
        &drawn,
        &path,
    )
    .map(Some)
    .map_err(|e| e.to_string())
}
