//! The [`Drawing`] as Graphviz DOT.

use std::fmt::Write as _;

use super::{Drawing, End, Node, Shape};

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
