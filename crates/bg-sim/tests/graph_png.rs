//! `bg-sim graph --format png` (issue 24, item 5): the SVG drawing rendered with resvg and
//! the DejaVu faces shipped in the binary; and the bond-graph figures of the docs
//! (`docs/graphs/NAME.svg` and `NAME.png`), which must be what `bg-sim graph` draws today,
//! so the PNG and the SVG cannot drift from each other or from the code.
//! `BG_UPDATE_DOCS=1 cargo test -p bg-sim --test graph_png` redraws them.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use resvg::tiny_skia::Pixmap;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Pixels per SVG pixel of the docs' PNGs: one (a page shows them narrower than that anyway;
/// the SVG beside each is for zooming), which keeps the six under 1.6 MB.
const DOCS_SCALE: f32 = 1.0;

/// The docs' bond-graph figures: model, expanded, file stem under `docs/graphs/`.
const FIGURES: &[(&str, bool, &str)] = &[
    ("knuckle_boom", false, "knuckle_boom"),
    ("knuckle_boom", true, "knuckle_boom_expanded"),
    ("cylinder_lift", true, "cylinder_lift_expanded"),
    ("lift_circuit", false, "lift_circuit"),
    ("lift_circuit", true, "lift_circuit_expanded"),
    ("ls_circuit", false, "ls_circuit"),
];

/// The `width="…" height="…"` of an SVG's root element.
fn svg_size(svg: &str) -> (f32, f32) {
    let attr = |name: &str| -> f32 {
        let at = svg.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        svg[at..at + svg[at..].find('"').unwrap()].parse().unwrap()
    };
    (attr("width"), attr("height"))
}

/// Sum of the three channels of the darkest pixel in a rectangle (px of the image).
fn darkest(p: &Pixmap, (x0, y0): (u32, u32), (x1, y1): (u32, u32)) -> u32 {
    (y0..y1.min(p.height()))
        .flat_map(|y| (x0..x1.min(p.width())).map(move |x| (x, y)))
        .map(|(x, y)| {
            let c = p.pixel(x, y).unwrap();
            u32::from(c.red()) + u32::from(c.green()) + u32::from(c.blue())
        })
        .min()
        .unwrap_or(u32::MAX)
}

/// `bg-sim graph --format png` writes a PNG that decodes, of the SVG's size times `--scale`,
/// drawn (not blank) and with its text set: the bold title at (20, 20) is black ink where
/// the background is white. `-o X.png` alone chooses PNG too.
#[test]
fn graph_writes_a_png_of_the_svg_with_its_text() {
    let dir = tempfile::tempdir().unwrap();
    let model = root().join("models/cylinder_lift.toml");
    let svg_path = dir.path().join("g.svg");
    let st = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .args(["graph", "--expand", "-o"])
        .arg(&svg_path)
        .arg(&model)
        .status()
        .unwrap();
    assert!(st.success());
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let (w, h) = svg_size(&svg);
    for (args, scale) in [
        (vec!["--format", "png", "--scale", "1"], 1.0),
        (vec!["--scale", "2.5"], 2.5),
        (vec![], 2.0),
    ] {
        let png = dir.path().join(format!("g{scale}.png"));
        let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
            .arg("graph")
            .arg(&model)
            .arg("--expand")
            .args(&args)
            .arg("-o")
            .arg(&png)
            .output()
            .unwrap();
        assert!(o.status.success(), "{args:?}: {o:?}");
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{args:?}");
        let p = Pixmap::decode_png(&bytes).unwrap();
        assert_eq!(
            (p.width(), p.height()),
            ((w * scale).ceil() as u32, (h * scale).ceil() as u32),
            "{args:?}"
        );
        // not blank: a good share of the pixels are not white
        let inked = p
            .pixels()
            .iter()
            .filter(|c| u32::from(c.red()) + u32::from(c.green()) + u32::from(c.blue()) < 600)
            .count();
        let share = inked as f64 / p.pixels().len() as f64;
        assert!(
            share > 0.01 && share < 0.5,
            "{args:?}: {share} of the pixels inked"
        );
        // the title, bold 14 px at x = 20, baseline y = 20: black ink in its box …
        let s = |v: f32| (v * scale) as u32;
        assert!(
            darkest(&p, (s(20.0), s(9.0)), (s(120.0), s(21.0))) < 150,
            "{args:?}: no title text"
        );
        // … and white above it
        assert_eq!(darkest(&p, (0, 0), (s(200.0), s(4.0))), 765, "{args:?}");
    }
    // a scale that makes no image is bad input
    for bad in ["0", "-1", "nan", "1000"] {
        let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
            .arg("graph")
            .arg(&model)
            .arg(format!("--scale={bad}"))
            .arg("-o")
            .arg(dir.path().join("bad.png"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--scale {bad}: {err}");
        assert!(err.contains("--scale"), "--scale {bad}: {err}");
    }
}

/// Largest channel difference and the share of pixels differing by more than 8 levels.
fn difference(a: &Pixmap, b: &Pixmap) -> (u8, f64) {
    let mut worst = 0u8;
    let mut off = 0usize;
    for (x, y) in a.pixels().iter().zip(b.pixels()) {
        let d = [
            x.red().abs_diff(y.red()),
            x.green().abs_diff(y.green()),
            x.blue().abs_diff(y.blue()),
            x.alpha().abs_diff(y.alpha()),
        ]
        .into_iter()
        .max()
        .unwrap_or(0);
        worst = worst.max(d);
        off += usize::from(d > 8);
    }
    (worst, off as f64 / a.pixels().len().max(1) as f64)
}

/// Every figure of `docs/graphs/` is what `bg-sim graph` draws from its model today: the
/// SVG byte for byte, the PNG that SVG rendered at [`DOCS_SCALE`] (pixel for pixel, but for
/// rounding: a renderer on another CPU may differ in the last bits of anti-aliasing).
#[test]
fn the_docs_bond_graph_figures_are_the_drawings_of_today() {
    let update = std::env::var_os("BG_UPDATE_DOCS").is_some();
    let docs = root().join("docs/graphs");
    let dir = tempfile::tempdir().unwrap();
    let mut stale = Vec::new();
    for &(model, expand, stem) in FIGURES {
        let out = dir.path().join(format!("{stem}.svg"));
        bg_sim::graph::write(
            &root().join(format!("models/{model}.toml")),
            Some(&out),
            expand,
            None,
            DOCS_SCALE,
            &[],
        )
        .unwrap();
        let svg = std::fs::read_to_string(&out).unwrap();
        let pixmap = bg_sim::graph::png::render(&svg, DOCS_SCALE).unwrap();
        let (svg_doc, png_doc) = (
            docs.join(format!("{stem}.svg")),
            docs.join(format!("{stem}.png")),
        );
        if update {
            std::fs::write(&svg_doc, &svg).unwrap();
            std::fs::write(&png_doc, pixmap.encode_png().unwrap()).unwrap();
            continue;
        }
        if std::fs::read_to_string(&svg_doc).ok().as_deref() != Some(svg.as_str()) {
            stale.push(format!("{} differs from the drawing", rel(&svg_doc)));
        }
        match std::fs::read(&png_doc)
            .ok()
            .and_then(|b| Pixmap::decode_png(&b).ok())
        {
            None => stale.push(format!("{} is missing or no PNG", rel(&png_doc))),
            Some(p) if (p.width(), p.height()) != (pixmap.width(), pixmap.height()) => {
                stale.push(format!(
                    "{} is {}×{} px, the drawing {}×{}",
                    rel(&png_doc),
                    p.width(),
                    p.height(),
                    pixmap.width(),
                    pixmap.height()
                ));
            }
            Some(p) => {
                let (worst, share) = difference(&p, &pixmap);
                if share > 0.002 {
                    stale.push(format!(
                        "{}: {:.2} % of the pixels differ (by up to {worst} levels)",
                        rel(&png_doc),
                        100.0 * share
                    ));
                }
            }
        }
    }
    assert!(
        stale.is_empty(),
        "{}\nredraw them: BG_UPDATE_DOCS=1 cargo test -p bg-sim --test graph_png",
        stale.join("\n")
    );
}

fn rel(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}
