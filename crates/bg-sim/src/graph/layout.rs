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

mod heights;
mod layers;
mod order;

use heights::heights_in_columns;
use layers::{back_edges, layers};
use order::{initial_order, minimise_crossings};

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

#[cfg(test)]
mod tests {
    use super::*;

    use super::heights::project;

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
