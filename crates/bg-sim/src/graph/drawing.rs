//! From a model's structure to a [`Drawing`]: nodes with their symbols and sizes, bonds
//! and signals as links, composites as boxes or clusters.

use bg_model::Structure;
use bondgraph::{BondGraph, CausalRule, PortCausality};

use super::layout::Size;
use super::{text_w, BondLink, Cluster, Drawing, End, Link, Node, Shape, FONT, SMALL};

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
