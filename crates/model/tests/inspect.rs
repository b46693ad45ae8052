//! `inspect` reports every problem of a model file in one pass, each at its line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{inspect, ErrorKind, Registry};

/// Two independent mistakes: an unknown parameter (line 7), a negative mass (line 8); and
/// a bond to an unknown element (line 14), while the bond to the failed `mass` is not
/// reported again.
const TWO_MISTAKES: &str = r#"title = "two mistakes"
[parameters]
k = 100.0

[elements]
v      = { kind = "1" }
spring = { kind = "C", k = "k", qq0 = 0.01 }
mass   = { kind = "I", m = -1.0 }
damper = { kind = "R", r = 0.4 }

[bonds]
b1 = "v -> mass"
b2 = "v -> damper"
b3 = "v -> dampr"
"#;

#[test]
fn every_problem_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.toml");
    std::fs::write(&path, TWO_MISTAKES).unwrap();
    let out = inspect(&path, &Registry::with_core(), &[]);
    let found: Vec<(ErrorKind, Option<usize>, Option<&str>)> = out
        .problems
        .iter()
        .map(|e| (e.kind, e.line, e.element.as_deref()))
        .collect();
    assert_eq!(
        found,
        [
            (ErrorKind::ExtraParameter, Some(7), Some("spring")),
            (ErrorKind::BadParameter, Some(8), Some("mass")),
            (ErrorKind::UnknownElement, Some(14), None),
        ],
        "{:#?}",
        out.problems
    );
    assert!(out.problems[0].hint.as_deref().unwrap().contains("q0"));
    // the elements that were built are listed
    assert!(out
        .elements
        .iter()
        .any(|(n, _, l)| n == "damper" && *l == 9));
    // Model::load reports the first
    let first = bg_model::Model::load(&path, &Registry::with_core(), &[]).unwrap_err();
    assert_eq!(first, out.problems[0]);
}

#[test]
fn a_problem_serialises_with_its_fields() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.toml");
    std::fs::write(&path, TWO_MISTAKES).unwrap();
    let out = inspect(&path, &Registry::with_core(), &[]);
    // any serde format will do; the workspace has TOML
    let text = toml::to_string(&out.problems[1]).unwrap();
    for key in [
        "file = ",
        "line = 8",
        "column = 28",
        "element = \"mass\"",
        "kind = \"bad_parameter\"",
        "message = ",
        "hint = ",
    ] {
        assert!(text.contains(key), "{key} in {text}");
    }
}

#[test]
fn a_core_error_keeps_its_source_and_hint_apart() {
    let text = TWO_MISTAKES
        .replace("qq0", "q0")
        .replace("m = -1.0", "m = 1.0")
        .replace("b3 = \"v -> dampr\"", "b3 = \"v -> mass\"");
    let e = bg_model::Model::from_text("t.toml", &text, &Registry::with_core(), &[]).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Graph, "{e}");
    assert!(!e.message.contains("hint"), "{e}");
    assert!(e.hint.is_some(), "{e}");
    assert!(std::error::Error::source(&e).is_some(), "{e}");
}
