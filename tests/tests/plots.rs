//! Every model's `[[plot]]` figures render to PNG and SVG from a run of the model, with one
//! legend entry and one curve per series; a model's plots are checked against the columns
//! its run writes.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_sim::plot::{draw_all, Format, Results, LEGEND_LEFT};
use bg_tests::{is_refused, model_files};

/// The texts of an SVG with their x coordinate.
fn svg_texts(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (attrs, rest) = t.split_once('>')?;
            let x = attrs
                .split("x=\"")
                .nth(1)?
                .split('"')
                .next()?
                .parse()
                .ok()?;
            let body = rest.split("</text>").next()?.trim();
            let body = body
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&quot;", "\"")
                .replace("&apos;", "'")
                .replace("&#39;", "'")
                .replace("&amp;", "&");
            Some((x, body))
        })
        .collect()
}

/// Number of points and stroke width of each `<polyline>` of an SVG.
fn polylines(svg: &str) -> Vec<(usize, u32)> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let width = p
                .split("stroke-width=\"")
                .nth(1)?
                .split('"')
                .next()?
                .parse()
                .ok()?;
            let pts = p.split("points=\"").nth(1)?.split('"').next()?;
            Some((pts.split_whitespace().count(), width))
        })
        .collect()
}

#[test]
fn every_model_has_plots_that_render_to_png_and_svg() {
    let dir = tempfile_dir();
    let mut drawn = 0;
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let mut model = bg_model::Model::load(&path, &bg_sim::registry(), &[])
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(
            !model.plots().is_empty(),
            "{name} has no [[plot]]: every runnable model draws its results"
        );
        let plots = model.plots().to_vec();
        let (out, _) = model.run_checked().unwrap();
        assert!(out.error.is_none(), "{name}: {:?}", out.error);
        // the run as `bg-sim run` writes it
        let mut csv = out.trajectory.columns.join(",") + "\n";
        for row in &out.trajectory.rows {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
            csv += &(cells.join(",") + "\n");
        }
        let results = Results::parse(&csv).unwrap();
        let into = dir.join(&name);
        let files = draw_all(&results, &plots, model.file(), &into, Format::Both)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(files.len(), 2 * plots.len(), "{name}: {files:?}");
        for plot in &plots {
            let png = std::fs::read(into.join(format!("{}.png", plot.file))).unwrap();
            assert!(
                png.len() > 5_000 && png.starts_with(b"\x89PNG\r\n\x1a\n"),
                "{name}/{}: not a PNG, or empty",
                plot.file
            );
            let svg = std::fs::read_to_string(into.join(format!("{}.svg", plot.file))).unwrap();
            assert!(
                svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
                "{name}/{}",
                plot.file
            );
            // one legend entry per series, in words, right of the charts
            let legend: Vec<String> = svg_texts(&svg)
                .into_iter()
                .filter(|(x, _)| *x >= f64::from(LEGEND_LEFT))
                .map(|(_, t)| t)
                .collect();
            let labels: Vec<String> = plot
                .panels
                .iter()
                .flat_map(|p| p.series.iter().map(|s| s.label.clone()))
                .collect();
            assert_eq!(legend, labels, "{name}/{}", plot.file);
            // the title, the axis labels with their units
            let texts: Vec<String> = svg_texts(&svg).into_iter().map(|t| t.1).collect();
            assert!(texts.contains(&plot.title), "{name}/{}", plot.file);
            for p in &plot.panels {
                assert!(
                    texts.contains(&p.axis_label()),
                    "{name}/{}: no axis label `{}`",
                    plot.file,
                    p.axis_label()
                );
            }
            // a solid series is one polyline through its points (in the panel's window); a
            // dashed one many dashes of a few points each
            let x = results.column(&plot.x).unwrap();
            let rows = |p: &bg_model::Panel| {
                x.iter()
                    .filter(|v| p.x_range.is_none_or(|(a, b)| (a..=b).contains(*v)))
                    .count()
            };
            let fewest = plot.panels.iter().map(rows).min().unwrap();
            assert!(
                fewest >= 10,
                "{name}/{}: {fewest} rows in a panel",
                plot.file
            );
            let long = polylines(&svg)
                .into_iter()
                .filter(|&(n, _)| n * 10 >= fewest * 9)
                .count();
            assert_eq!(
                long,
                solid_count(plot),
                "{name}/{}: curves drawn",
                plot.file
            );
            // the dashes: thin (2 px) short polylines besides the legend's (one per solid
            // series of a panel without dashed ones, two per dashed series)
            let dashed = plot
                .panels
                .iter()
                .flat_map(|p| p.series.iter())
                .filter(|s| s.dashed)
                .count();
            let legend_thin: usize = plot
                .panels
                .iter()
                .map(|p| {
                    let d = p.series.iter().filter(|s| s.dashed).count();
                    if d == 0 {
                        p.series.len()
                    } else {
                        2 * d
                    }
                })
                .sum();
            let thin = polylines(&svg)
                .into_iter()
                .filter(|&(n, w)| w == 2 && n * 10 < fewest * 9)
                .count();
            assert!(
                thin >= legend_thin + 10 * dashed,
                "{name}/{}: {thin} thin polylines for {dashed} dashed series",
                plot.file
            );
            drawn += 1;
        }
    }
    assert!(drawn >= 10, "only {drawn} plots drawn");
    std::fs::remove_dir_all(&dir).ok();
}

fn tempfile_dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("bg-plots-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn solid_count(plot: &bg_model::Plot) -> usize {
    plot.panels
        .iter()
        .flat_map(|p| p.series.iter())
        .filter(|s| !s.dashed)
        .count()
}
