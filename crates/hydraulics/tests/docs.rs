//! Every ```toml block of `docs/hydraulics.md` is a complete model that loads, runs and
//! passes its checks.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

#[test]
fn hydraulics_doc_examples_load_and_run() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/hydraulics.md");
    let text = std::fs::read_to_string(path).unwrap();
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_start()) {
            (None, "```toml") => current = Some(String::new()),
            (Some(_), "```") => blocks.extend(current.take()),
            (Some(b), _) => {
                b.push_str(line);
                b.push('\n');
            }
            _ => {}
        }
    }
    assert!(!blocks.is_empty());
    for (i, block) in blocks.iter().enumerate() {
        let name = format!("docs/hydraulics.md block {}", i + 1);
        let mut m = bg_model::Model::from_text(&name, block, &common::registry(), &[])
            .unwrap_or_else(|e| panic!("{e}"));
        let out = m.run().unwrap();
        assert!(out.error.is_none(), "{name}: {:?}", out.error);
        let checks = m.verify(&out.trajectory);
        assert!(!checks.is_empty(), "{name} has no [[check]]");
        for c in checks {
            assert!(
                c.passed,
                "{name}: check {} failed: {:e}",
                c.value, c.max_error
            );
        }
    }
}
