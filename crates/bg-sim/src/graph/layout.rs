//! A layered drawing of a directed graph, left to right (Sugiyama, Tagawa & Toda, "Methods
//! for visual understanding of hierarchical system structures", IEEE SMC 11(2), 1981):
//!
//! 1. cycles are broken by reversing the edges a depth-first search finds going back;
//! 2. layers by longest path from the sources, then each source is moved up next to its
//!    nearest successor (a source element beside its junction, not in the first column);
//! 3. an edge spanning several layers gets a dummy node in each layer it crosses;
//! 4. the order inside each layer by the barycentre heuristic, sweeping right and left,
//!    keeping the order with the fewest crossings;
//! 5. each node is pulled towards the mean height of its neighbours, keeping the order and
//!    the spacing (a least-squares projection: pool-adjacent-violators), a few sweeps.
//!
//! Sizes are in SVG user units (px). Nothing here knows about bond graphs.

/// A node to place: its width and height.
#[derive(Clone, Copy, Debug)]
pub struct Size {
    /// Width.
    pub w: f64,
    /// Height.
    pub h: f64,
}

/// An edge: drawn from `from` to `to`, preferably left to right.
#[derive(Clone, Copy, Debug)]
pub struct Edge {
    /// Tail.
    pub from: usize,
    /// Head.
    pub to: usize,
    /// A weak edge (a signal) is the one turned round when a cycle must be broken.
    pub weak: bool,
}

/// The placed graph: node centres, each edge's route (from the tail's centre through the
/// dummy nodes to the head's centre) and the drawing's extent.
#[derive(Clone, Debug, Default)]
pub struct Placed {
    /// Centre of each node.
    pub centre: Vec<(f64, f64)>,
    /// Route of each edge, tail first.
    pub routes: Vec<Vec<(f64, f64)>>,
    /// Width of the drawing (from 0).
    pub width: f64,
    /// Height of the drawing (from 0).
    pub height: f64,
}

/// Spacing of the drawing.
#[derive(Clone, Copy, Debug)]
pub struct Spacing {
    /// Between two columns (layers).
    pub column: f64,
    /// Between two nodes of one column.
    pub row: f64,
    /// Around the drawing.
    pub margin: f64,
}

/// Height a dummy node takes in its column (an edge passing through).
const DUMMY_H: f64 = 6.0;

/// A node held in the first or the last column (the stub of an edge that leaves a frame on
/// that side).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pin {
    /// The first column.
    First,
    /// The last column.
    Last,
}

/// Lay out `sizes` with `edges` (self-loops and repeated edges are allowed), the nodes of
/// `pins` held in the first or last column.
#[must_use]
pub fn layout(sizes: &[Size], edges: &[Edge], pins: &[(usize, Pin)], sp: Spacing) -> Placed {
    let n = sizes.len();
    if n == 0 {
        return Placed {
            width: 2.0 * sp.margin,
            height: 2.0 * sp.margin,
            ..Placed::default()
        };
    }
    // 1. acyclic orientation
    let flipped = back_edges(n, edges);
    let dir: Vec<(usize, usize)> = edges
        .iter()
        .zip(&flipped)
        .map(|(e, &f)| if f { (e.to, e.from) } else { (e.from, e.to) })
        .filter(|(a, b)| a != b)
        .collect();
    // 2. layers
    let mut layer = layers(n, &dir, pins);
    let last = layer.iter().max().copied().unwrap_or(0);
    for &(v, p) in pins {
        if p == Pin::Last && v < n {
            layer[v] = last;
        }
    }
    // 3. dummy nodes: every node (real or dummy) has a layer; chains join the layers
    let mut node_layer = layer.clone();
    let mut heights: Vec<f64> = sizes.iter().map(|s| s.h).collect();
    let mut widths: Vec<f64> = sizes.iter().map(|s| s.w).collect();
    // for each original edge: the chain of nodes from tail to head (in drawing direction)
    let mut chains: Vec<Vec<usize>> = Vec::with_capacity(edges.len());
    let mut adj: Vec<(usize, usize, f64)> = Vec::new(); // (left, right, weight) between layers l, l+1
    for (e, &f) in edges.iter().zip(&flipped) {
        let (a, b) = if f { (e.to, e.from) } else { (e.from, e.to) };
        let mut chain = vec![a];
        if a != b {
            let (la, lb) = (node_layer[a], node_layer[b]);
            // a same-layer edge (possible only between two nodes forced there) goes direct
            if lb > la {
                let mut prev = a;
                for l in la + 1..lb {
                    let d = node_layer.len();
                    node_layer.push(l);
                    heights.push(DUMMY_H);
                    widths.push(0.0);
                    // dummy–dummy segments weigh more: long edges come out straight
                    let w = if prev == a { 1.0 } else { 4.0 };
                    adj.push((prev, d, w));
                    chain.push(d);
                    prev = d;
                }
                adj.push((prev, b, 1.0));
            }
        }
        chain.push(b);
        if f {
            chain.reverse();
        }
        chains.push(chain);
    }
    let total = node_layer.len();
    let n_layers = node_layer.iter().max().map_or(1, |m| m + 1);
    let mut left: Vec<Vec<(usize, f64)>> = vec![Vec::new(); total];
    let mut right: Vec<Vec<(usize, f64)>> = vec![Vec::new(); total];
    for &(a, b, w) in &adj {
        right[a].push((b, w));
        left[b].push((a, w));
    }
    // 4. order in each layer
    let mut order: Vec<Vec<usize>> = vec![Vec::new(); n_layers];
    for v in initial_order(total, &left, &right, &node_layer) {
        order[node_layer[v]].push(v);
    }
    minimise_crossings(&mut order, &left, &right);
    // 5. coordinates
    let mut col_w = vec![0.0_f64; n_layers];
    for v in 0..total {
        col_w[node_layer[v]] = col_w[node_layer[v]].max(widths[v]);
    }
    let mut col_x = vec![0.0; n_layers];
    let mut x = sp.margin;
    for l in 0..n_layers {
        col_x[l] = x + col_w[l] / 2.0;
        x += col_w[l] + sp.column;
    }
    let width = x - sp.column + sp.margin;
    let y = heights_in_columns(&order, &heights, &left, &right, sp.row);
    let (y_min, y_max) = (0..total).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (
            lo.min(y[v] - heights[v] / 2.0),
            hi.max(y[v] + heights[v] / 2.0),
        )
    });
    let shift = sp.margin - y_min;
    // a node whose edges all leave to the right sits at the right of its column, one whose
    // edges all come from the left at the left: short bonds to wide neighbours
    let x_of: Vec<f64> = (0..total)
        .map(|v| {
            let (c, half) = (
                col_x[node_layer[v]],
                (col_w[node_layer[v]] - widths[v]) / 2.0,
            );
            match (left[v].is_empty(), right[v].is_empty()) {
                (true, false) => c + half,
                (false, true) => c - half,
                _ => c,
            }
        })
        .collect();
    let pos = |v: usize| (x_of[v], y[v] + shift);
    Placed {
        centre: (0..n).map(pos).collect(),
        routes: chains
            .iter()
            .map(|c| c.iter().map(|&v| pos(v)).collect())
            .collect(),
        width,
        height: y_max - y_min + 2.0 * sp.margin,
    }
}

/// Which edges to reverse so that the graph has no cycle: among the strong edges those a
/// depth-first search (from the nodes in index order) finds pointing back to a node on its
/// stack; then each weak edge in turn keeps its direction unless that closes a cycle, those
/// from nodes without strong edges first.
fn back_edges(n: usize, edges: &[Edge]) -> Vec<bool> {
    let mut flip = strong_back_edges(n, edges);
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (e, &f) in edges.iter().zip(&flip) {
        if !e.weak && e.from != e.to {
            let (a, b) = if f { (e.to, e.from) } else { (e.from, e.to) };
            succ[a].push(b);
        }
    }
    let reaches = |succ: &[Vec<usize>], from: usize, to: usize| {
        let mut seen = vec![false; n];
        let mut stack = vec![from];
        while let Some(v) = stack.pop() {
            if v == to {
                return true;
            }
            if !std::mem::replace(&mut seen[v], true) {
                stack.extend(&succ[v]);
            }
        }
        false
    };
    // first the signals a block without bonds sends (a controller's command), then those
    // read off the bond graph (a measurement): a feedback loop is cut at its measurement
    let mut bonded = vec![false; n];
    for e in edges.iter().filter(|e| !e.weak) {
        bonded[e.from] = true;
        bonded[e.to] = true;
    }
    let mut weak: Vec<usize> = (0..edges.len()).filter(|&i| edges[i].weak).collect();
    weak.sort_by_key(|&i| bonded[edges[i].from]);
    for i in weak {
        let (e, f) = (&edges[i], &mut flip[i]);
        if e.from != e.to {
            // a→b closes a cycle if b already reaches a; then b→a cannot (no cycle yet)
            *f = reaches(&succ, e.to, e.from);
            let (a, b) = if *f { (e.to, e.from) } else { (e.from, e.to) };
            succ[a].push(b);
        }
    }
    flip
}

fn strong_back_edges(n: usize, edges: &[Edge]) -> Vec<bool> {
    let mut out: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (i, e) in edges.iter().enumerate() {
        if !e.weak {
            out[e.from].push((e.to, i));
        }
    }
    // 0 = new, 1 = on the stack, 2 = done
    let mut state = vec![0u8; n];
    let mut flip = vec![false; edges.len()];
    for root in 0..n {
        if state[root] != 0 {
            continue;
        }
        let mut stack = vec![(root, 0usize)];
        state[root] = 1;
        while let Some(&mut (v, ref mut next)) = stack.last_mut() {
            if let Some(&(w, i)) = out[v].get(*next) {
                *next += 1;
                match state[w] {
                    0 => {
                        state[w] = 1;
                        stack.push((w, 0));
                    }
                    1 => flip[i] = w != v,
                    _ => {}
                }
            } else {
                state[v] = 2;
                stack.pop();
            }
        }
    }
    flip
}

/// Longest-path layers of an acyclic graph, each source then moved right next to its
/// nearest successor.
fn layers(n: usize, dir: &[(usize, usize)], pins: &[(usize, Pin)]) -> Vec<usize> {
    let mut indeg = vec![0usize; n];
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(a, b) in dir {
        indeg[b] += 1;
        succ[a].push(b);
    }
    let mut layer = vec![0usize; n];
    let mut queue: Vec<usize> = (0..n).filter(|&v| indeg[v] == 0).collect();
    let mut remaining = indeg.clone();
    let mut topo = Vec::with_capacity(n);
    while let Some(v) = queue.pop() {
        topo.push(v);
        for &w in &succ[v] {
            layer[w] = layer[w].max(layer[v] + 1);
            remaining[w] -= 1;
            if remaining[w] == 0 {
                queue.push(w);
            }
        }
    }
    // sources next to their successors, latest first so that chains of sources follow
    for &v in topo.iter().rev() {
        if indeg[v] == 0 && !pins.iter().any(|&(p, _)| p == v) {
            if let Some(m) = succ[v].iter().map(|&w| layer[w]).min() {
                layer[v] = m.saturating_sub(1).max(layer[v]);
            }
        }
    }
    layer
}

/// A first order: breadth-first from the first node of each component, so that
/// neighbours start near each other.
fn initial_order(
    total: usize,
    left: &[Vec<(usize, f64)>],
    right: &[Vec<(usize, f64)>],
    node_layer: &[usize],
) -> Vec<usize> {
    let mut seen = vec![false; total];
    let mut out = Vec::with_capacity(total);
    let mut starts: Vec<usize> = (0..total).collect();
    starts.sort_by_key(|&v| node_layer[v]);
    for s in starts {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        let mut queue = std::collections::VecDeque::from([s]);
        while let Some(v) = queue.pop_front() {
            out.push(v);
            for &(w, _) in right[v].iter().chain(&left[v]) {
                if !seen[w] {
                    seen[w] = true;
                    queue.push_back(w);
                }
            }
        }
    }
    out
}

/// Crossings between two adjacent layers.
fn crossings(a: &[usize], b: &[usize], right: &[Vec<(usize, f64)>], pos: &[usize]) -> usize {
    let mut segs: Vec<(usize, usize)> = Vec::new();
    for &v in a {
        for &(w, _) in &right[v] {
            if b.contains(&w) {
                segs.push((pos[v], pos[w]));
            }
        }
    }
    let mut c = 0;
    for i in 0..segs.len() {
        for j in i + 1..segs.len() {
            let (p, q) = (segs[i], segs[j]);
            if (p.0 < q.0 && p.1 > q.1) || (p.0 > q.0 && p.1 < q.1) {
                c += 1;
            }
        }
    }
    c
}

fn total_crossings(order: &[Vec<usize>], right: &[Vec<(usize, f64)>], pos: &[usize]) -> usize {
    order
        .windows(2)
        .map(|w| crossings(&w[0], &w[1], right, pos))
        .sum()
}

fn positions(order: &[Vec<usize>], total: usize) -> Vec<usize> {
    let mut pos = vec![0; total];
    for layer in order {
        for (i, &v) in layer.iter().enumerate() {
            pos[v] = i;
        }
    }
    pos
}

/// Barycentre sweeps, keeping the best order seen.
fn minimise_crossings(
    order: &mut [Vec<usize>],
    left: &[Vec<(usize, f64)>],
    right: &[Vec<(usize, f64)>],
) {
    let total = left.len();
    let mut pos = positions(order, total);
    let mut best = order.to_vec();
    let mut best_c = total_crossings(order, right, &pos);
    for iter in 0..24 {
        let rightward = iter % 2 == 0;
        let layers: Vec<usize> = if rightward {
            (1..order.len()).collect()
        } else {
            (0..order.len().saturating_sub(1)).rev().collect()
        };
        for l in layers {
            let nb = if rightward { left } else { right };
            let mut keyed: Vec<(f64, usize)> = order[l]
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    let (s, w) = nb[v]
                        .iter()
                        .fold((0.0, 0.0), |(s, w), &(u, k)| (s + k * pos[u] as f64, w + k));
                    // a node without neighbours on that side keeps its place
                    (if w > 0.0 { s / w } else { i as f64 }, v)
                })
                .collect();
            keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
            order[l] = keyed.into_iter().map(|(_, v)| v).collect();
            for (i, &v) in order[l].iter().enumerate() {
                pos[v] = i;
            }
        }
        let c = total_crossings(order, right, &pos);
        if c < best_c {
            best_c = c;
            best = order.to_vec();
        }
        if best_c == 0 {
            break;
        }
    }
    order.clone_from_slice(&best);
}

/// Heights (centres) of the nodes: packed, then pulled towards their neighbours.
fn heights_in_columns(
    order: &[Vec<usize>],
    heights: &[f64],
    left: &[Vec<(usize, f64)>],
    right: &[Vec<(usize, f64)>],
    row: f64,
) -> Vec<f64> {
    let total = heights.len();
    let gap = |a: usize, b: usize| {
        let g = if heights[a] <= DUMMY_H || heights[b] <= DUMMY_H {
            row / 2.0
        } else {
            row
        };
        (heights[a] + heights[b]) / 2.0 + g
    };
    let mut y = vec![0.0; total];
    for layer in order {
        let mut at = 0.0;
        for (i, &v) in layer.iter().enumerate() {
            if i > 0 {
                at += gap(layer[i - 1], v);
            }
            y[v] = at;
        }
        // centre each column on 0
        let mid = at / 2.0;
        for &v in layer {
            y[v] -= mid;
        }
    }
    for iter in 0..16 {
        let seq: Vec<usize> = match iter % 3 {
            0 => (0..order.len()).collect(),
            1 => (0..order.len()).rev().collect(),
            _ => (0..order.len()).collect(),
        };
        for l in seq {
            let layer = &order[l];
            let want: Vec<f64> = layer
                .iter()
                .map(|&v| {
                    let nb: Vec<&(usize, f64)> = match iter % 3 {
                        0 => left[v].iter().collect(),
                        1 => right[v].iter().collect(),
                        _ => left[v].iter().chain(&right[v]).collect(),
                    };
                    let (s, w) = nb
                        .iter()
                        .fold((0.0, 0.0), |(s, w), &&(u, k)| (s + k * y[u], w + k));
                    if w > 0.0 {
                        s / w
                    } else {
                        y[v]
                    }
                })
                .collect();
            let seps: Vec<f64> = layer.windows(2).map(|p| gap(p[0], p[1])).collect();
            let placed = project(&want, &seps);
            for (&v, p) in layer.iter().zip(placed) {
                y[v] = p;
            }
        }
    }
    y
}

/// The positions closest (least squares) to `want` with `y[i+1] − y[i] ≥ seps[i]`:
/// with `z[i] = y[i] − Σ seps[..i]` the constraint is `z` non-decreasing, an isotonic
/// regression solved by pooling adjacent violators.
fn project(want: &[f64], seps: &[f64]) -> Vec<f64> {
    let mut offset = Vec::with_capacity(want.len());
    let mut acc = 0.0;
    for i in 0..want.len() {
        if i > 0 {
            acc += seps[i - 1];
        }
        offset.push(acc);
    }
    // blocks of (mean, count)
    let mut blocks: Vec<(f64, usize)> = Vec::new();
    for (w, o) in want.iter().zip(&offset) {
        blocks.push((w - o, 1));
        while blocks.len() > 1 {
            let (m2, c2) = blocks[blocks.len() - 1];
            let (m1, c1) = blocks[blocks.len() - 2];
            if m1 <= m2 {
                break;
            }
            blocks.pop();
            let c = c1 + c2;
            if let Some(b) = blocks.last_mut() {
                *b = ((m1 * c1 as f64 + m2 * c2 as f64) / c as f64, c);
            }
        }
    }
    let mut out = Vec::with_capacity(want.len());
    for (m, c) in blocks {
        for _ in 0..c {
            out.push(m + offset[out.len()]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SP: Spacing = Spacing {
        column: 40.0,
        row: 20.0,
        margin: 10.0,
    };

    fn sizes(n: usize) -> Vec<Size> {
        vec![Size { w: 30.0, h: 20.0 }; n]
    }

    #[test]
    fn a_chain_runs_left_to_right_in_one_row() {
        let e: Vec<Edge> = (0..3)
            .map(|i| Edge {
                from: i,
                to: i + 1,
                weak: false,
            })
            .collect();
        let p = layout(&sizes(4), &e, &[], SP);
        for w in p.centre.windows(2) {
            assert!(w[1].0 > w[0].0, "{:?}", p.centre);
            assert!((w[1].1 - w[0].1).abs() < 1e-9, "{:?}", p.centre);
        }
    }

    #[test]
    fn cycles_and_self_loops_are_drawn_without_overlap() {
        let e = [
            Edge {
                from: 0,
                to: 1,
                weak: false,
            },
            Edge {
                from: 1,
                to: 2,
                weak: false,
            },
            Edge {
                from: 2,
                to: 0,
                weak: false,
            },
            Edge {
                from: 1,
                to: 1,
                weak: false,
            },
            Edge {
                from: 0,
                to: 2,
                weak: false,
            },
        ];
        let p = layout(&sizes(3), &e, &[], SP);
        assert_eq!(p.routes.len(), e.len());
        for (i, a) in p.centre.iter().enumerate() {
            for b in &p.centre[i + 1..] {
                let apart = (a.0 - b.0).abs() >= 30.0 || (a.1 - b.1).abs() >= 20.0;
                assert!(apart, "{:?}", p.centre);
            }
        }
        // every route starts at its tail and ends at its head
        for (r, e) in p.routes.iter().zip(&e) {
            assert_eq!(r.first(), Some(&p.centre[e.from]));
            assert_eq!(r.last(), Some(&p.centre[e.to]));
        }
    }

    #[test]
    fn projection_keeps_order_and_spacing() {
        let y = project(&[5.0, 0.0, 1.0], &[2.0, 2.0]);
        assert!(
            y[1] - y[0] >= 2.0 - 1e-12 && y[2] - y[1] >= 2.0 - 1e-12,
            "{y:?}"
        );
        // the least-squares solution: all three pooled around their mean offset
        let mean = (5.0 + (0.0 - 2.0) + (1.0 - 4.0)) / 3.0;
        assert!((y[0] - mean).abs() < 1e-12, "{y:?}");
    }

    #[test]
    fn a_crossing_that_can_be_undone_is() {
        // 0→3, 1→2 with 2 first in the initial order would cross
        let e = [
            Edge {
                from: 0,
                to: 3,
                weak: false,
            },
            Edge {
                from: 1,
                to: 2,
                weak: false,
            },
            Edge {
                from: 0,
                to: 2,
                weak: false,
            },
        ];
        let p = layout(&sizes(4), &e, &[], SP);
        let (y0, y1, y2, y3) = (p.centre[0].1, p.centre[1].1, p.centre[2].1, p.centre[3].1);
        // 0 above 1 ⇔ 3 above 2 ... no crossing between 0→3 and 1→2
        assert_eq!(y0 < y1, y3 < y2, "{:?}", p.centre);
    }
}
