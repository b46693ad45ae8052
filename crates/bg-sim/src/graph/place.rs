//! Where everything of a [`Drawing`] goes: clusters laid out on their own and placed as
//! blocks, then the whole graph ([`layout`](super::layout)).

use super::layout::{self, Edge, Pin, Placed, Size, Spacing};
use super::{Cluster, Drawing};

/// Space around a cluster's members, and the height of its title.
const CLUSTER_PAD: f64 = 12.0;
const CLUSTER_TITLE: f64 = 18.0;

const SPACING: Spacing = Spacing {
    column: 56.0,
    row: 22.0,
    margin: 0.0,
};

/// Where everything goes: node centres, link routes, cluster frames (x, y, w, h).
pub(super) struct Geometry {
    pub(super) centre: Vec<(f64, f64)>,
    pub(super) routes: Vec<Vec<(f64, f64)>>,
    pub(super) frames: Vec<(f64, f64, f64, f64)>,
    pub(super) width: f64,
    pub(super) height: f64,
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
pub(super) fn place(d: &Drawing) -> Geometry {
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
pub(super) fn clip(c: (f64, f64), size: Size, p: (f64, f64)) -> (f64, f64) {
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
