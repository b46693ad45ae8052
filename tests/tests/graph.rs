//! `bg-sim graph`: every model in `models/` draws to well-formed SVG with exactly one
//! half-arrow and one causal stroke per bond drawn, composites collapsed and expanded; the
//! stroke sits at the end that receives the effort; a model refused for derivative
//! causality is drawn without strokes, saying why.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeMap, BTreeSet};

use bg_model::{structure, Structure};
use bg_sim::graph::{dot, drawing, svg};
use bg_tests::model_files;

/// The bonds a drawing must show: all of them expanded; collapsed, those not inside one
/// composite.
fn expected_bonds(s: &Structure, expand: bool) -> BTreeSet<String> {
    let g = &s.graph;
    let composite = |id: usize| {
        let name = &g.node(id).name;
        s.entries
            .iter()
            .position(|e| !e.ports.is_empty() && e.members.contains(name))
    };
    g.bonds()
        .filter(|b| {
            expand
                || composite(b.from.element).is_none()
                || composite(b.from.element) != composite(b.to.element)
        })
        .map(|b| b.name.clone())
        .collect()
}

/// Count the children of each `g.bond` by class, keyed by bond name.
fn bond_parts(svg: &str) -> BTreeMap<String, BTreeMap<String, usize>> {
    let doc = roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("not XML: {e}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    let mut out: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for g in doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("bond"))
    {
        let name = g.attribute("data-bond").expect("data-bond").to_owned();
        assert!(!out.contains_key(&name), "bond {name} drawn twice");
        let parts = out.entry(name).or_default();
        for c in g.children().filter(roxmltree::Node::is_element) {
            if let Some(cls) = c.attribute("class") {
                *parts.entry(cls.to_owned()).or_default() += 1;
            }
        }
    }
    // no stroke or half-arrow outside a bond
    for cls in ["causal-stroke", "half-arrow"] {
        let all = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some(cls))
            .count();
        let inside: usize = out.values().map(|p| p.get(cls).copied().unwrap_or(0)).sum();
        assert_eq!(all, inside, "{cls} outside a bond");
    }
    out
}

#[test]
fn every_model_draws_one_half_arrow_and_one_causal_stroke_per_bond() {
    let mut drawn = 0;
    for path in model_files() {
        let s = structure(&path, &bg_sim::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
        for expand in [false, true] {
            let d = drawing(&s, expand);
            let text = svg(&d);
            let parts = bond_parts(&text);
            let want = expected_bonds(&s, expand);
            let got: BTreeSet<String> = parts.keys().cloned().collect();
            assert_eq!(got, want, "{} (expand {expand})", path.display());
            let strokes = usize::from(s.causality.is_ok());
            for (bond, p) in &parts {
                let n = |c: &str| p.get(c).copied().unwrap_or(0);
                assert_eq!(n("half-arrow"), 1, "{}: bond {bond}", path.display());
                assert_eq!(
                    n("causal-stroke"),
                    strokes,
                    "{}: bond {bond}",
                    path.display()
                );
            }
            // the DOT text names every bond drawn, once
            let dot = dot(&d);
            assert!(dot.starts_with("digraph") && dot.trim_end().ends_with('}'));
            for b in &want {
                let n = dot.matches(&format!("label=\"{b}\"")).count()
                    + dot.matches(&format!("label=\"{b} [")).count();
                assert_eq!(n, 1, "{}: {b} in DOT", path.display());
            }
            drawn += 1;
        }
    }
    assert!(drawn >= 18, "drew {drawn}");
}

/// Endpoints of a `<line>`.
fn line(n: roxmltree::Node<'_, '_>) -> [(f64, f64); 2] {
    let f = |a: &str| n.attribute(a).unwrap().parse::<f64>().unwrap();
    [(f("x1"), f("y1")), (f("x2"), f("y2"))]
}

#[test]
fn the_stroke_sits_at_the_end_that_receives_the_effort() {
    // the stroke's midpoint is the bond's end: the head (the half-arrow's tip) when the
    // tail's element sets the effort, else the tail
    let path = bg_tests::root().join("models/mass_spring_damper.toml");
    let s = structure(&path, &bg_sim::registry(), &[]).unwrap();
    let setter = s.causality.as_ref().unwrap();
    let text = svg(&drawing(&s, false));
    let doc = roxmltree::Document::parse(&text).unwrap();
    for (b, bond) in s.graph.bonds().enumerate() {
        let g = doc
            .descendants()
            .find(|n| n.attribute("data-bond") == Some(bond.name.as_str()))
            .unwrap();
        let child = |cls: &str| {
            g.children()
                .find(|n| n.attribute("class") == Some(cls))
                .unwrap()
        };
        let tip = line(child("half-arrow"))[0];
        let stroke = line(child("causal-stroke"));
        let mid = (
            (stroke[0].0 + stroke[1].0) / 2.0,
            (stroke[0].1 + stroke[1].1) / 2.0,
        );
        let at_head = (mid.0 - tip.0).hypot(mid.1 - tip.1) < 1e-6;
        let head_receives = setter[b] == bond.from.element;
        assert_eq!(at_head, head_receives, "bond {}", bond.name);
    }
}

#[test]
fn a_model_refused_for_derivative_causality_is_drawn_without_strokes() {
    let path = bg_tests::root().join("models/derivative_causality.toml");
    let s = structure(&path, &bg_sim::registry(), &[]).unwrap();
    let d = drawing(&s, false);
    assert!(
        d.problem()
            .is_some_and(|p| p.contains("derivative causality")),
        "{:?}",
        d.problem()
    );
    let text = svg(&d);
    assert_eq!(text.matches("causal-stroke").count(), 0);
    assert_eq!(
        text.matches("class=\"half-arrow\"").count(),
        s.graph.n_bonds()
    );
    assert!(text.contains("no causal strokes"));
}

#[test]
fn composites_collapse_into_one_box_with_their_ports() {
    let path = bg_tests::root().join("models/knuckle_boom.toml");
    let s = structure(&path, &bg_sim::registry(), &[]).unwrap();
    let collapsed = svg(&drawing(&s, false));
    assert_eq!(collapsed.matches("class=\"composite-box\"").count(), 3);
    // the cylinders' `mech` ports and the arm's `cyl1`, `cyl2` where the bonds attach
    for port in ["mech", "cyl1", "cyl2"] {
        assert!(collapsed.contains(&format!(">{port}</text>")), "{port}");
    }
    let expanded = svg(&drawing(&s, true));
    assert_eq!(expanded.matches("class=\"composite\"").count(), 3);
    assert_eq!(expanded.matches("class=\"composite-box\"").count(), 0);
    // every element of the model is a node of the expanded drawing
    for id in 0..s.graph.n_elements() {
        let name = &s.graph.node(id).name;
        assert!(
            expanded.contains(&format!("data-name=\"{name}\"")),
            "{name}"
        );
    }
}
