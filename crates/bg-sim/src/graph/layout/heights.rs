//! Step 5 of the layered drawing: the heights of the nodes in each column, pulled towards
//! their neighbours (a least-squares projection, pool-adjacent-violators).

use super::DUMMY_H;

/// Heights (centres) of the nodes: packed, then pulled towards their neighbours.
pub(super) fn heights_in_columns(
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
pub(super) fn project(want: &[f64], seps: &[f64]) -> Vec<f64> {
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
