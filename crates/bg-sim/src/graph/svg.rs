//! The [`Drawing`] as an SVG document: symbols, half-arrows, causal strokes, signals,
//! composite frames and a legend.

use std::fmt::Write as _;

use super::place::{clip, place};
use super::{text_w, Drawing, End, Shape, BARB, FONT, SMALL, STROKE};

/// Text escaped for XML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn unit(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let l = (dx * dx + dy * dy).sqrt().max(1e-12);
    (dx / l, dy / l)
}

/// The drawing as an SVG document.
#[must_use]
pub fn svg(d: &Drawing) -> String {
    let geo = place(d);
    let legend1 = "⇀ half-arrow: direction of positive power (from → to)   | causal stroke: at the end that receives the effort";
    let legend2 = "- - ▸ signal read by an element   [n] multibond of n efforts and flows";
    let problem = d
        .problem
        .as_ref()
        .map(|p| format!("no causal strokes: {p}"));
    let head = if problem.is_some() { 44.0 } else { 28.0 };
    let legend = 40.0;
    let width = [
        geo.width,
        text_w(legend1, SMALL) + 40.0,
        text_w(&d.title, 14.0) + 40.0,
        problem.as_deref().map_or(0.0, |p| text_w(p, SMALL) + 40.0),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    let height = geo.height + head + legend;
    let mut o = String::new();
    let _ = writeln!(
        o,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.1} {h:.1}" font-family="DejaVu Sans Mono, Menlo, Consolas, monospace">
<defs><marker id="signal-head" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="#777"/></marker></defs>
<rect width="100%" height="100%" fill="white"/>"##,
        w = width,
        h = height
    );
    let _ = writeln!(
        o,
        r#"<text x="20" y="20" font-size="14" font-weight="bold">{}</text>"#,
        esc(&d.title)
    );
    let _ = writeln!(o, r#"<g transform="translate(0,{head})">"#);
    // cluster frames
    for (c, &(x, y, w, h)) in d.clusters.iter().zip(&geo.frames) {
        let _ = writeln!(
            o,
            r##"<g class="composite" data-name="{n}"><rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" rx="8" fill="#f4f7fb" stroke="#8aa" stroke-dasharray="6 3"/><text x="{tx:.1}" y="{ty:.1}" font-size="{SMALL}" fill="#456"><tspan font-weight="bold">{n}</tspan>  {k}</text></g>"##,
            n = esc(&c.name),
            k = esc(&c.kind),
            tx = x + 8.0,
            ty = y + 14.0
        );
    }
    // links
    for (l, route) in d.links.iter().zip(&geo.routes) {
        if route.len() < 2 {
            continue;
        }
        let mut pts = route.clone();
        let last = pts.len() - 1;
        pts[0] = clip(pts[0], d.nodes[l.from].size, pts[1]);
        pts[last] = clip(pts[last], d.nodes[l.to].size, pts[last - 1]);
        let path: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", p.0, p.1))
            .collect();
        let Some(b) = &l.bond else {
            let _ = writeln!(
                o,
                r##"<polyline class="signal" data-signal="{s}" points="{p}" fill="none" stroke="#777" stroke-width="1" stroke-dasharray="4 3" marker-end="url(#signal-head)"/>"##,
                s = esc(&l.signal),
                p = path.join(" ")
            );
            continue;
        };
        let width = if b.dim > 1 { 2.6 } else { 1.4 };
        let _ = writeln!(
            o,
            r#"<g class="bond" data-bond="{n}"><polyline points="{p}" fill="none" stroke="black" stroke-width="{width}"/>"#,
            n = esc(&b.name),
            p = path.join(" ")
        );
        // half-arrow at the head: one barb, on the left of the direction of power
        let tip = pts[last];
        let (ux, uy) = unit(pts[last - 1], tip);
        let barb = (
            tip.0 - BARB * ux + 0.55 * BARB * uy,
            tip.1 - BARB * uy - 0.55 * BARB * ux,
        );
        let _ = writeln!(
            o,
            r#"<line class="half-arrow" x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="black" stroke-width="{width}"/>"#,
            tip.0, tip.1, barb.0, barb.1
        );
        if let Some(end) = b.stroke {
            let (p, q) = match end {
                End::Head => (tip, pts[last - 1]),
                End::Tail => (pts[0], pts[1]),
            };
            let (ux, uy) = unit(q, p);
            let h = STROKE / 2.0;
            let _ = writeln!(
                o,
                r#"<line class="causal-stroke" x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="black" stroke-width="{}"/>"#,
                p.0 - h * uy,
                p.1 + h * ux,
                p.0 + h * uy,
                p.1 - h * ux,
                width + 0.4
            );
        }
        // name (and dimension) beside the middle of the longest segment
        let k = (0..last)
            .max_by(|&i, &j| {
                let len = |i: usize| (pts[i + 1].0 - pts[i].0).hypot(pts[i + 1].1 - pts[i].1);
                len(i).total_cmp(&len(j))
            })
            .unwrap_or(0);
        let mid = (
            (pts[k].0 + pts[k + 1].0) / 2.0,
            (pts[k].1 + pts[k + 1].1) / 2.0,
        );
        let dim = if b.dim > 1 {
            format!(" [{}]", b.dim)
        } else {
            String::new()
        };
        // on the side of the barb, clear of the line
        let (vx, vy) = unit(pts[k], pts[k + 1]);
        let (nx, ny) = (vy, -vx);
        let anchor = if nx > 0.4 {
            "start"
        } else if nx < -0.4 {
            "end"
        } else {
            "middle"
        };
        let _ = writeln!(
            o,
            r##"<text class="bond-name" x="{:.1}" y="{:.1}" font-size="9" fill="#888" text-anchor="{anchor}">{}{dim}</text>"##,
            mid.0 + 5.0 * nx,
            mid.1 + 5.0 * ny + if ny > 0.0 { 7.0 } else { 0.0 },
            esc(&b.label)
        );
        // composite ports where the bond attaches
        for (port, at, towards) in [
            (&b.ports[0], pts[0], pts[1]),
            (&b.ports[1], tip, pts[last - 1]),
        ] {
            if let Some(port) = port {
                // just outside the box, above the bond
                let (ux, uy) = unit(at, towards);
                let anchor = if ux > 0.3 {
                    "start"
                } else if ux < -0.3 {
                    "end"
                } else {
                    "middle"
                };
                let _ = writeln!(
                    o,
                    r##"<text class="port" x="{:.1}" y="{:.1}" font-size="{SMALL}" fill="#a40" text-anchor="{anchor}">{}</text>"##,
                    at.0 + 4.0 * ux,
                    at.1 + 4.0 * uy - 6.0,
                    esc(port)
                );
            }
        }
        let _ = writeln!(o, "</g>");
    }
    // nodes
    for (node, &(x, y)) in d.nodes.iter().zip(&geo.centre) {
        let s = node.size;
        let (main, weight) = match node.shape {
            Shape::Junction => (18.0, "bold"),
            Shape::Composite => (FONT, "bold"),
            _ => (FONT, "normal"),
        };
        let cls = match node.shape {
            Shape::Junction => "junction",
            Shape::Element => "element",
            Shape::Block => "block",
            Shape::Composite => "composite-box",
        };
        let _ = write!(o, r#"<g class="{cls}" data-name="{}">"#, esc(&node.name));
        match node.shape {
            Shape::Block => {
                let _ = write!(
                    o,
                    r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" rx="3" fill="#fffbe8" stroke="#b90"/>"##,
                    x - s.w / 2.0,
                    y - s.h / 2.0,
                    s.w,
                    s.h
                );
            }
            Shape::Composite => {
                let _ = write!(
                    o,
                    r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" rx="6" fill="#f4f7fb" stroke="#456" stroke-width="1.5"/>"##,
                    x - s.w / 2.0,
                    y - s.h / 2.0,
                    s.w,
                    s.h
                );
            }
            Shape::Element | Shape::Junction => {}
        }
        let top = y - s.h / 2.0
            + (s.h - main * 1.25 - node.sub.as_ref().map_or(0.0, |_| SMALL * 1.3)) / 2.0;
        let _ = write!(
            o,
            r#"<text x="{x:.1}" y="{:.1}" font-size="{main}" font-weight="{weight}" text-anchor="middle">{}</text>"#,
            top + main,
            esc(&node.label)
        );
        if let Some(sub) = &node.sub {
            let _ = write!(
                o,
                r##"<text x="{x:.1}" y="{:.1}" font-size="{SMALL}" fill="#666" text-anchor="middle">{}</text>"##,
                top + main * 1.25 + SMALL,
                esc(sub)
            );
        }
        let _ = writeln!(o, "</g>");
    }
    let _ = writeln!(o, "</g>");
    if let Some(p) = &problem {
        let _ = writeln!(
            o,
            r##"<text class="problem" x="20" y="38" font-size="{SMALL}" fill="#b00">{}</text>"##,
            esc(p)
        );
    }
    // legend
    let ly = head + geo.height + 14.0;
    let _ = writeln!(
        o,
        r##"<text x="20" y="{ly:.1}" font-size="{SMALL}" fill="#444">{}</text>
<text x="20" y="{:.1}" font-size="{SMALL}" fill="#444">{}</text>"##,
        esc(legend1),
        ly + 14.0,
        esc(legend2)
    );
    let _ = writeln!(o, "</svg>");
    o
}
