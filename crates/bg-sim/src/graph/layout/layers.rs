//! Steps 1 and 2 of the layered drawing: break the cycles, then assign the layers.

use super::{Edge, Pin};

/// Which edges to reverse so that the graph has no cycle: among the strong edges those a
/// depth-first search (from the nodes in index order) finds pointing back to a node on its
/// stack; then each weak edge in turn keeps its direction unless that closes a cycle, those
/// from nodes without strong edges first.
pub(super) fn back_edges(n: usize, edges: &[Edge]) -> Vec<bool> {
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
pub(super) fn layers(n: usize, dir: &[(usize, usize)], pins: &[(usize, Pin)]) -> Vec<usize> {
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
