//! Step 4 of the layered drawing: the order inside each layer (barycentre sweeps, keeping
//! the order with the fewest crossings).

/// A first order: breadth-first from the first node of each component, so that
/// neighbours start near each other.
pub(super) fn initial_order(
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
pub(super) fn minimise_crossings(
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
