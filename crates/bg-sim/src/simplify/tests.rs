#![allow(clippy::unwrap_used)]
use super::*;
use bondgraph::kind::{Change, KindDecl};

const TEXT: &str = r#"
[elements]
a = { kind = "t.k", r = 1.0, n = 4, list = [{ modes = 3 }, { other = 1 }, { modes = 2 }] }
b = { kind = "t.k", n = 2 }

[elements.c]
kind = "t.k"
r = 2.0
"#;

const PARAMS: &[bondgraph::kind::ParamDecl] = &[
    bondgraph::kind::ParamDecl::number("r", "1", "r").optional("none"),
    bondgraph::kind::ParamDecl::count("n", "n").default(2.0),
    bondgraph::kind::ParamDecl::number("x", "1", "x").default(0.0),
];

fn never(
    _: &dyn bondgraph::kind::Params,
) -> Result<Box<dyn bondgraph::Element>, bondgraph::kind::BuildError> {
    Err(bondgraph::kind::BuildError::invalid("r", "never built"))
}

const KIND: KindDecl = KindDecl::element("t.k", "test", PARAMS, never).simplifications(&[
    Simplification::new("no_r", "no r", &[Change::Unset("r")]),
    Simplification::new("n2", "n = 2", &[Change::Set("n", "2")]),
    Simplification::new("rigid", "no modes", &[Change::Set("list[*].modes", "0")]),
]);

const KIND_WITH_MEMBERS: KindDecl = KindDecl::element("t.k", "test", PARAMS, never)
    .simplifications(&[
        Simplification::new("no_r", "no r", &[Change::Unset("r")]).members(&["leak"]),
        Simplification::new("n2", "n = 3", &[Change::Set("n", "3")]),
    ]);

fn kind() -> KindDecl {
    KIND
}

#[test]
fn only_simplifications_that_change_something_are_candidates() {
    let mut reg = Registry::empty();
    reg.register(kind());
    let c = candidates(TEXT, &reg, &[]).unwrap();
    let labels: Vec<String> = c.iter().map(Candidate::label).collect();
    // b: n = 2 already, no r, no list; c: n absent = default 2
    assert_eq!(labels, ["a: no_r", "a: n2", "a: rigid", "c: no_r"]);
}

#[test]
fn applying_sets_unsets_and_sets_in_every_entry_of_a_list() {
    let mut reg = Registry::empty();
    reg.register(kind());
    let c = candidates(TEXT, &reg, &[]).unwrap();
    let picks: Vec<&Candidate> = c.iter().collect();
    let out = apply(TEXT, &picks).unwrap();
    assert!(
        out.contains(
            r#"a = { kind = "t.k", n = 2, list = [{ modes = 0 }, { other = 1 }, { modes = 0 }] }"#
        ),
        "{out}"
    );
    assert!(out.contains("[elements.c]\nkind = \"t.k\"\n"), "{out}");
    assert!(!out.contains("r = 2.0"), "{out}");
    // applied again, nothing is left to change
    assert!(candidates(&out, &reg, &[]).unwrap().is_empty());
}

#[test]
fn a_share_is_the_sum_of_the_members_it_removes() {
    let mut reg = Registry::empty();
    reg.register(KIND_WITH_MEMBERS);
    let act = |name: &str, composite: &str, share: f64| ElementActivity {
        name: name.into(),
        composite: composite.into(),
        activity: share,
        share,
    };
    let ranking = [
        act("a_leak", "a", 0.01),
        act("a_other", "a", 0.2),
        act("c_leak", "c", 0.03),
        act("b", "b", 0.5),
    ];
    let c = candidates(TEXT, &reg, &ranking).unwrap();
    let expected = [
        ("a: no_r", 0.01),
        ("c: no_r", 0.03),
        ("c: n2", 0.03),
        ("a: n2", 0.21),
        ("b: n2", 0.5),
    ];
    assert_eq!(c.len(), expected.len());
    for (c, (label, share)) in c.iter().zip(expected) {
        assert_eq!(c.label(), label);
        assert!((c.share - share).abs() < 1e-15, "{label}: {}", c.share);
    }
}
