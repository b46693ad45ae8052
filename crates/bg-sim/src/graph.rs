//! `bg-sim graph`: a model's bond graph drawn as SVG (or written as Graphviz DOT).
//!
//! Elements are drawn by their bond-graph symbol and name (`C: spring`, `1`, `Se: gravity`);
//! a domain kind gets the symbol its causal rule implies (a storage that imposes its effort
//! is a `C`, one that imposes its flow an `I`, a resistive one an `R`, …) with the kind's
//! name beneath. Every bond is a line with a half-arrow at its head (the direction of
//! positive power, `from -> to` in the file) and one causal stroke across the end that
//! *receives* the effort: the end opposite the element that sets the bond's effort
//! ([`bondgraph::CausalGraph::effort_setter`]). A signal an element reads is a dashed line
//! with a full arrowhead. A composite (`hydraulics.cylinder`, `manipulator.planar_arm`) is one
//! box with its exposed ports named where its bonds attach, or, expanded, a dashed frame
//! around its members.
//!
//! The layout is our own layered drawing ([`layout`]): composites expanded are laid out
//! on their own first and placed as one block.

pub mod layout;

use std::fmt::Write as _;

use bg_model::Structure;
use bondgraph::{BondGraph, CausalRule, PortCausality};

use layout::{Edge, Pin, Placed, Size, Spacing};

/// Width of one character of the monospace font, in px per px of font size.
const CHAR_W: f64 = 0.6;
/// Font size of element labels (px).
const FONT: f64 = 13.0;
/// Font size of kind names, bond names and port names (px).
const SMALL: f64 = 10.0;
/// Length of the causal stroke (px).
const STROKE: f64 = 14.0;
/// Length of the half-arrow's barb (px).
const BARB: f64 = 11.0;

/// What a node of the drawing stands for.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Shape {
    /// A bond-graph element drawn as its symbol and name.
    Element,
    /// A 0- or 1-junction: the symbol large, the name small.
    Junction,
    /// A signal block (no ports): a framed box.
    Block,
    /// A collapsed composite: a framed box with its kind.
    Composite,
}

/// One node: an element, or a collapsed composite.
#[derive(Clone, Debug)]
struct Node {
    /// Name in the model (global).
    name: String,
    /// First line: the symbol and the short name (`C: chamber_p`), or the junction's symbol.
    label: String,
    /// Second line, small: the kind (domain kinds, composites) or a junction's name.
    sub: Option<String>,
    shape: Shape,
    /// The expanded composite it belongs to.
    cluster: Option<usize>,
    size: Size,
}

/// Which end of a bond carries the causal stroke.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    Tail,
    Head,
}

/// A bond or a signal between two nodes.
#[derive(Clone, Debug)]
struct Link {
    from: usize,
    to: usize,
    /// `Some` for a bond: its name, dimension, causal stroke, and the composite port names at
    /// its ends (collapsed composites).
    bond: Option<BondLink>,
    /// A signal's name (`crane_act1.l1`).
    signal: String,
}

#[derive(Clone, Debug)]
struct BondLink {
    name: String,
    /// The name drawn: without its composite's prefix inside a frame.
    label: String,
    dim: usize,
    stroke: Option<End>,
    ports: [Option<String>; 2],
}

/// An expanded composite: a frame around its members.
#[derive(Clone, Debug)]
struct Cluster {
    name: String,
    kind: String,
    members: Vec<usize>,
}

/// A model's bond graph ready to draw: nodes, bonds and signals, composites.
#[derive(Clone, Debug)]
pub struct Drawing {
    title: String,
    nodes: Vec<Node>,
    links: Vec<Link>,
    clusters: Vec<Cluster>,
    /// Why there are no causal strokes, if causality could not be assigned.
    problem: Option<String>,
}

impl Drawing {
    /// Bonds drawn (each with one half-arrow and, if causality was assigned, one stroke).
    #[must_use]
    pub fn n_bonds(&self) -> usize {
        self.links.iter().filter(|l| l.bond.is_some()).count()
    }

    /// Why no causal strokes are drawn (the causality error), if so.
    #[must_use]
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }
}

/// The bond-graph symbol of an element: the core kinds' own names; a domain kind's from its
/// causal rule (`None`: no symbol implied, the kind's name is shown).
fn symbol(kind: &str, rule: &CausalRule, n_ports: usize) -> Option<String> {
    use PortCausality::{EffortOut, FlowOut};
    const CORE: [&str; 11] = [
        "Se", "Sf", "R", "C", "I", "TF", "MTF", "GY", "MGY", "0", "1",
    ];
    if CORE.contains(&kind) {
        return Some(kind.to_owned());
    }
    // the kind's own name first: `manipulator.c_field` is a C-field, `actuator_mtf` an MTF
    let short = kind.rsplit('.').next().unwrap_or(kind).to_ascii_lowercase();
    let tokens: Vec<&str> = short.split('_').collect();
    for t in ["mtf", "tf", "mgy", "gy"] {
        if tokens.contains(&t) {
            return Some(t.to_ascii_uppercase());
        }
    }
    if tokens.len() == 2 && tokens[1] == "field" && ["c", "i", "r"].contains(&tokens[0]) {
        return Some(tokens[0].to_ascii_uppercase());
    }
    let all = |p: &[PortCausality], c| !p.is_empty() && p.iter().all(|x| *x == c);
    let s = match rule {
        CausalRule::Integral(p) if all(p, EffortOut) => "C",
        CausalRule::Integral(p) if all(p, FlowOut) => "I",
        CausalRule::Integral(_) => "IC",
        CausalRule::Resistive(_) => "R",
        CausalRule::Fixed(p) if n_ports == 1 && all(p, EffortOut) => "Se",
        CausalRule::Fixed(p) if n_ports == 1 && all(p, FlowOut) => "Sf",
        // a multiport that takes every effort and gives every flow (a valve): a resistance
        CausalRule::Fixed(p) if all(p, FlowOut) => "R",
        CausalRule::ExactlyOne(FlowOut) if !kind.contains('.') => "0",
        CausalRule::ExactlyOne(EffortOut) if !kind.contains('.') => "1",
        CausalRule::AllEqual => "GY",
        _ => return None,
    };
    Some(s.to_owned())
}

fn text_w(s: &str, font: f64) -> f64 {
    s.chars().count() as f64 * CHAR_W * font
}

fn node_size(label: &str, sub: Option<&str>, shape: &Shape) -> Size {
    let (main, pad) = match shape {
        Shape::Junction => (18.0, 4.0),
        Shape::Element => (FONT, 6.0),
        Shape::Block | Shape::Composite => (FONT, 10.0),
    };
    let w = text_w(label, main).max(sub.map_or(0.0, |s| text_w(s, SMALL)));
    let h = main * 1.25 + sub.map_or(0.0, |_| SMALL * 1.3);
    Size {
        w: w + 2.0 * pad,
        h: h + pad,
    }
}

/// The model-file entry each element came from: (entry index, is a composite).
fn owners(s: &Structure) -> Vec<Option<usize>> {
    let g = &s.graph;
    (0..g.n_elements())
        .map(|id| {
            let name = &g.node(id).name;
            s.entries
                .iter()
                .position(|e| !e.ports.is_empty() && e.members.iter().any(|m| m == name))
        })
        .collect()
}

/// Build the drawing of `s`, composites collapsed into one box each unless `expand`.
#[must_use]
pub fn drawing(s: &Structure, expand: bool) -> Drawing {
    let g: &BondGraph = &s.graph;
    let owner = owners(s);
    let mut nodes: Vec<Node> = Vec::new();
    let mut clusters: Vec<Cluster> = Vec::new();
    // node of each element
    let mut node_of = vec![0usize; g.n_elements()];
    // node of each collapsed composite entry / cluster of each expanded one
    let mut entry_node: Vec<Option<usize>> = vec![None; s.entries.len()];
    for id in 0..g.n_elements() {
        let el = &g.node(id);
        match (owner[id], expand) {
            (Some(e), false) => {
                if let Some(n) = entry_node[e] {
                    node_of[id] = n;
                    continue;
                }
                let entry = &s.entries[e];
                let sub = Some(entry.kind.clone());
                let size = node_size(&entry.name, sub.as_deref(), &Shape::Composite);
                node_of[id] = nodes.len();
                entry_node[e] = Some(nodes.len());
                nodes.push(Node {
                    name: entry.name.clone(),
                    label: entry.name.clone(),
                    sub,
                    shape: Shape::Composite,
                    cluster: None,
                    size,
                });
            }
            (cluster_entry, _) => {
                let cluster = cluster_entry.map(|e| {
                    *entry_node[e].get_or_insert_with(|| {
                        clusters.push(Cluster {
                            name: s.entries[e].name.clone(),
                            kind: s.entries[e].kind.clone(),
                            members: Vec::new(),
                        });
                        clusters.len() - 1
                    })
                });
                let kind = el.element.kind();
                let n_ports = g.ports_of(id).len();
                let short = match cluster {
                    Some(c) => el
                        .name
                        .strip_prefix(&format!("{}_", clusters[c].name))
                        .unwrap_or(&el.name)
                        .to_owned(),
                    None => el.name.clone(),
                };
                let sym = symbol(kind, &el.element.causal_rule(n_ports), n_ports);
                let (label, sub, shape) = match sym.as_deref() {
                    Some(j @ ("0" | "1")) => (j.to_owned(), Some(short), Shape::Junction),
                    Some(sym) => (
                        format!("{sym}: {short}"),
                        (sym != kind).then(|| kind.to_owned()),
                        Shape::Element,
                    ),
                    None if n_ports == 0 => (short, Some(kind.to_owned()), Shape::Block),
                    None => (short, Some(kind.to_owned()), Shape::Element),
                };
                let size = node_size(&label, sub.as_deref(), &shape);
                node_of[id] = nodes.len();
                if let Some(c) = cluster {
                    clusters[c].members.push(nodes.len());
                }
                nodes.push(Node {
                    name: el.name.clone(),
                    label,
                    sub,
                    shape,
                    cluster,
                    size,
                });
            }
        }
    }
    let setter = s.causality.as_ref().ok();
    let mut links = Vec::new();
    for (b, bond) in g.bonds().enumerate() {
        let (a, z) = (node_of[bond.from.element], node_of[bond.to.element]);
        if a == z {
            continue; // inside a collapsed composite
        }
        let port = |end: bondgraph::Endpoint| -> Option<String> {
            let e = owner[end.element]?;
            if expand {
                return None;
            }
            let member = &g.node(end.element).name;
            let with_port = format!("{member}.{}", g.port_name(end.element, end.port));
            s.entries[e]
                .ports
                .iter()
                .find(|(_, inner)| *inner == with_port || inner == member)
                .map(|(n, _)| n.clone())
        };
        links.push(Link {
            from: a,
            to: z,
            bond: Some(BondLink {
                name: bond.name.clone(),
                label: match (nodes[a].cluster, nodes[z].cluster) {
                    (Some(c), Some(k)) if c == k => bond
                        .name
                        .strip_prefix(&format!("{}_", clusters[c].name))
                        .unwrap_or(&bond.name)
                        .to_owned(),
                    _ => bond.name.clone(),
                },
                dim: bond.dim,
                stroke: setter.map(|s| {
                    if s[b] == bond.from.element {
                        End::Head
                    } else {
                        End::Tail
                    }
                }),
                ports: [port(bond.from), port(bond.to)],
            }),
            signal: String::new(),
        });
    }
    // signals: `<element>.<…>` read by another element
    let mut seen = std::collections::HashSet::new();
    for id in 0..g.n_elements() {
        for spec in g.node(id).element.signal_inputs() {
            let src = spec.name.split('.').next().unwrap_or("");
            let Some(from) = g.find(src) else { continue };
            let (a, z) = (node_of[from], node_of[id]);
            if a != z && seen.insert((a, z)) {
                links.push(Link {
                    from: a,
                    to: z,
                    bond: None,
                    signal: spec.name.clone(),
                });
            }
        }
    }
    Drawing {
        title: s.title.clone().unwrap_or_default(),
        nodes,
        links,
        clusters,
        problem: s.causality.as_ref().err().map(|e| e.message.clone()),
    }
}

/// Space around a cluster's members, and the height of its title.
const CLUSTER_PAD: f64 = 12.0;
const CLUSTER_TITLE: f64 = 18.0;

const SPACING: Spacing = Spacing {
    column: 56.0,
    row: 22.0,
    margin: 0.0,
};

/// Where everything goes: node centres, link routes, cluster frames (x, y, w, h).
struct Geometry {
    centre: Vec<(f64, f64)>,
    routes: Vec<Vec<(f64, f64)>>,
    frames: Vec<(f64, f64, f64, f64)>,
    width: f64,
    height: f64,
}

/// A bond that crosses a frame, seen from inside: the link, the member it attaches to and
/// the side of the frame the other end lies on.
type Stub = (usize, usize, Pin);

/// Lay out the members of cluster `c`, with a zero-size node in the first or last column for
/// each stub (so a member bonded to something left of the frame sits at its left).
fn inner_layout(d: &Drawing, c: &Cluster, stubs: &[Stub]) -> (Placed, Vec<usize>, Vec<f64>) {
    let local: std::collections::HashMap<usize, usize> =
        c.members.iter().enumerate().map(|(i, &m)| (m, i)).collect();
    let mut sizes: Vec<Size> = c.members.iter().map(|&m| d.nodes[m].size).collect();
    let mut which = Vec::new();
    let mut edges: Vec<Edge> = d
        .links
        .iter()
        .enumerate()
        .filter_map(|(i, l)| {
            let (a, z) = (local.get(&l.from)?, local.get(&l.to)?);
            which.push(i);
            Some(Edge {
                from: *a,
                to: *z,
                weak: l.bond.is_none(),
            })
        })
        .collect();
    let mut pins = Vec::new();
    for &(_, member, pin) in stubs {
        let Some(&m) = local.get(&member) else {
            continue;
        };
        let stub = sizes.len();
        sizes.push(Size { w: 0.0, h: 4.0 });
        pins.push((stub, pin));
        edges.push(match pin {
            Pin::First => Edge {
                from: stub,
                to: m,
                weak: false,
            },
            Pin::Last => Edge {
                from: m,
                to: stub,
                weak: false,
            },
        });
    }
    let mut p = layout::layout(&sizes, &edges, &pins, SPACING);
    p.routes.truncate(which.len());
    let heights = p.centre[c.members.len()..].iter().map(|c| c.1).collect();
    (p, which, heights)
}

/// Lay out the drawing with the given stubs per cluster.
fn arrange(d: &Drawing, stubs: &[Vec<Stub>]) -> Geometry {
    let n = d.nodes.len();
    let inner: Vec<(Placed, Vec<usize>, Vec<f64>)> = d
        .clusters
        .iter()
        .zip(stubs)
        .map(|(c, s)| inner_layout(d, c, s))
        .collect();
    // the top level: nodes outside clusters, then one block per cluster
    let mut top_of = vec![0usize; n];
    let mut sizes = Vec::new();
    for (i, node) in d.nodes.iter().enumerate() {
        if node.cluster.is_none() {
            top_of[i] = sizes.len();
            sizes.push(node.size);
        }
    }
    let first_block = sizes.len();
    for (c, (p, _, _)) in d.clusters.iter().zip(&inner) {
        for &m in &c.members {
            top_of[m] = sizes.len();
        }
        sizes.push(Size {
            w: p.width + 2.0 * CLUSTER_PAD,
            h: p.height + 2.0 * CLUSTER_PAD + CLUSTER_TITLE,
        });
    }
    let mut top_links = Vec::new();
    let edges: Vec<Edge> = d
        .links
        .iter()
        .enumerate()
        .filter(|(_, l)| top_of[l.from] != top_of[l.to])
        .map(|(i, l)| {
            top_links.push(i);
            Edge {
                from: top_of[l.from],
                to: top_of[l.to],
                weak: l.bond.is_none(),
            }
        })
        .collect();
    let sp = Spacing {
        column: 90.0,
        row: 26.0,
        margin: 20.0,
    };
    let top = layout::layout(&sizes, &edges, &[], sp);
    let mut centre = vec![(0.0, 0.0); n];
    let mut frames = Vec::new();
    for (i, node) in d.nodes.iter().enumerate() {
        if node.cluster.is_none() {
            centre[i] = top.centre[top_of[i]];
        }
    }
    let mut routes = vec![Vec::new(); d.links.len()];
    // where each crossing bond passes its frame
    let mut gates: std::collections::HashMap<(usize, usize), (f64, f64)> =
        std::collections::HashMap::new();
    for (c, (cl, (p, which, heights))) in d.clusters.iter().zip(&inner).enumerate() {
        let (cx, cy) = top.centre[first_block + c];
        let s = sizes[first_block + c];
        let (x0, y0) = (cx - s.w / 2.0, cy - s.h / 2.0);
        frames.push((x0, y0, s.w, s.h));
        let (ox, oy) = (x0 + CLUSTER_PAD, y0 + CLUSTER_PAD + CLUSTER_TITLE);
        for (k, &m) in cl.members.iter().enumerate() {
            centre[m] = (p.centre[k].0 + ox, p.centre[k].1 + oy);
        }
        for (r, &l) in p.routes.iter().zip(which) {
            routes[l] = r.iter().map(|(x, y)| (x + ox, y + oy)).collect();
        }
        for (&(l, member, pin), y) in stubs[c].iter().zip(heights) {
            let x = if pin == Pin::First { x0 } else { x0 + s.w };
            gates.insert((l, member), (x, y + oy));
        }
    }
    for (r, &l) in top.routes.iter().zip(&top_links) {
        let mut r = r.clone();
        // from the member itself, not the cluster's centre
        let (from, to) = (d.links[l].from, d.links[l].to);
        if let Some(f) = r.first_mut() {
            *f = centre[from];
        }
        if let Some(z) = r.last_mut() {
            *z = centre[to];
        }
        // through the frame where the member's stub is
        if let Some(&g) = gates.get(&(l, from)) {
            r.insert(1, g);
        }
        if let Some(&g) = gates.get(&(l, to)) {
            r.insert(r.len() - 1, g);
        }
        routes[l] = r;
    }
    Geometry {
        centre,
        routes,
        frames,
        width: top.width,
        height: top.height,
    }
}

/// Lay out the drawing: once to see on which side of each frame its bonds leave, and again
/// with the members that carry them moved to that side.
fn place(d: &Drawing) -> Geometry {
    let none = vec![Vec::new(); d.clusters.len()];
    let first = arrange(d, &none);
    if d.clusters.is_empty() {
        return first;
    }
    let mut stubs = none;
    for (i, l) in d.links.iter().enumerate().filter(|(_, l)| l.bond.is_some()) {
        for (inside, other) in [(l.from, l.to), (l.to, l.from)] {
            let Some(c) = d.nodes[inside].cluster else {
                continue;
            };
            if d.nodes[other].cluster == Some(c) {
                continue;
            }
            let (x0, _, w, _) = first.frames[c];
            let x = first.centre[other].0;
            if x < x0 {
                stubs[c].push((i, inside, Pin::First));
            } else if x > x0 + w {
                stubs[c].push((i, inside, Pin::Last));
            }
        }
    }
    arrange(d, &stubs)
}

/// Where the segment from the centre of a `w × h` box at `c` towards `p` leaves the box
/// (with a small gap).
fn clip(c: (f64, f64), size: Size, p: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (p.0 - c.0, p.1 - c.1);
    let (hw, hh) = (size.w / 2.0 + 3.0, size.h / 2.0 + 3.0);
    if dx.abs() < 1e-9 && dy.abs() < 1e-9 {
        return c;
    }
    let t = (hw / dx.abs().max(1e-12))
        .min(hh / dy.abs().max(1e-12))
        .min(1.0);
    (c.0 + t * dx, c.1 + t * dy)
}

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

/// The drawing as Graphviz DOT (`dot -Tsvg`): half-arrows are `lvee`, causal strokes `tee`,
/// expanded composites `cluster_` subgraphs.
#[must_use]
pub fn dot(d: &Drawing) -> String {
    let q = |s: &str| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""));
    let mut o = String::new();
    let _ = writeln!(o, "digraph {} {{", q(&d.title));
    let _ = writeln!(
        o,
        "  rankdir=LR; labelloc=t; label={};\n  node [shape=plaintext fontname=\"monospace\"];\n  edge [arrowsize=1.2];",
        q(&d.title)
    );
    let node_line = |i: usize, n: &Node| {
        let label = match &n.sub {
            Some(s) => format!("{}\\n{}", n.label, s),
            None => n.label.clone(),
        };
        let shape = match n.shape {
            Shape::Block | Shape::Composite => " shape=box style=rounded",
            _ => "",
        };
        format!("n{i} [label={}{shape}];", q(&label).replace("\\\\n", "\\n"))
    };
    for (c, cl) in d.clusters.iter().enumerate() {
        let _ = writeln!(
            o,
            "  subgraph cluster_{c} {{\n    label={}; style=dashed;",
            q(&format!("{} ({})", cl.name, cl.kind))
        );
        for &m in &cl.members {
            let _ = writeln!(o, "    {}", node_line(m, &d.nodes[m]));
        }
        let _ = writeln!(o, "  }}");
    }
    for (i, n) in d.nodes.iter().enumerate() {
        if n.cluster.is_none() {
            let _ = writeln!(o, "  {}", node_line(i, n));
        }
    }
    for l in &d.links {
        match &l.bond {
            Some(b) => {
                let head = if b.stroke == Some(End::Head) {
                    "teelvee"
                } else {
                    "lvee"
                };
                let tail = if b.stroke == Some(End::Tail) {
                    " dir=both arrowtail=tee"
                } else {
                    ""
                };
                let mut label = b.name.clone();
                if b.dim > 1 {
                    let _ = write!(label, " [{}]", b.dim);
                }
                let mut ports = String::new();
                if let Some(p) = &b.ports[0] {
                    let _ = write!(ports, " taillabel={}", q(p));
                }
                if let Some(p) = &b.ports[1] {
                    let _ = write!(ports, " headlabel={}", q(p));
                }
                let _ = writeln!(
                    o,
                    "  n{} -> n{} [arrowhead={head}{tail} label={}{ports}{}];",
                    l.from,
                    l.to,
                    q(&label),
                    if b.dim > 1 { " penwidth=2.5" } else { "" }
                );
            }
            None => {
                let _ = writeln!(
                    o,
                    "  n{} -> n{} [style=dashed color=gray40 arrowhead=normal tooltip={}];",
                    l.from,
                    l.to,
                    q(&l.signal)
                );
            }
        }
    }
    let _ = writeln!(o, "}}");
    o
}

/// What `bg-sim graph` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// An SVG drawing (drawn here, no Graphviz needed).
    Svg,
    /// Graphviz DOT, for `dot -Tsvg` or `dot -Tpdf`.
    Dot,
}

/// What [`write`] wrote.
#[derive(Clone, Debug)]
pub struct Written {
    /// The file.
    pub path: std::path::PathBuf,
    /// Elements or composite boxes drawn.
    pub nodes: usize,
    /// Bonds drawn.
    pub bonds: usize,
    /// Why there are no causal strokes, if so.
    pub problem: Option<String>,
}

/// `bg-sim graph`: load `model` (with `--set` overrides) as far as its causality, draw it and
/// write it to `out` (default `out/<model>.svg`, or `.dot`); the format is `format`, else
/// the extension of `out` (`.dot`/`.gv`: DOT), else SVG.
pub fn write(
    model: &std::path::Path,
    out: Option<&std::path::Path>,
    expand: bool,
    format: Option<Format>,
    set: &[String],
) -> Result<Written, String> {
    let format = format.unwrap_or_else(|| {
        match out
            .and_then(|p| p.extension())
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("dot" | "gv") => Format::Dot,
            _ => Format::Svg,
        }
    });
    let path = out.map_or_else(
        || {
            let stem = model
                .file_stem()
                .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
            let ext = if format == Format::Dot { "dot" } else { "svg" };
            std::path::PathBuf::from("out").join(format!("{stem}.{ext}"))
        },
        std::path::Path::to_path_buf,
    );
    if path == model {
        return Err(format!(
            "refusing to write the drawing over the model file {}",
            model.display()
        ));
    }
    let s = bg_model::structure(model, &crate::registry(), set).map_err(|e| e.to_string())?;
    let d = drawing(&s, expand);
    let text = match format {
        Format::Svg => svg(&d),
        Format::Dot => dot(&d),
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot write {}: {e}", dir.display()))?;
    }
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(Written {
        path,
        nodes: d.nodes.len(),
        bonds: d.n_bonds(),
        problem: d.problem.clone(),
    })
}
