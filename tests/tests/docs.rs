//! Every ```toml block of the documentation (`docs/*.md`, README) is a complete model that
//! loads, runs and passes its checks, so the docs cannot drift from the format.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_tests::root;

fn toml_blocks(text: &str) -> Vec<String> {
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
    blocks
}

#[test]
fn model_format_examples_load_and_run() {
    let mut n = 0;
    let mut docs: Vec<String> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .map(|p| format!("docs/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    docs.sort();
    docs.push("README.md".into());
    for doc in &docs {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        for (i, block) in toml_blocks(&text).into_iter().enumerate() {
            let name = format!("{doc} block {}", i + 1);
            let mut model = bg_model::Model::from_text(&name, &block, &bg_sim::registry(), &[])
                .unwrap_or_else(|e| panic!("{e}"));
            let (out, checks) = model.run_checked().unwrap();
            assert!(out.error.is_none(), "{name}: {:?}", out.error);
            for c in checks {
                assert!(
                    c.passed,
                    "{name}: check {} failed: {:e}",
                    c.value, c.max_error
                );
            }
            n += 1;
        }
    }
    assert!(n >= 4, "found only {n} examples");
}

/// Issue "hardening" #10: `parameters.modes1 = 11` was accepted although the docs said 0–10;
/// the bound of `manipulator.planar_arm` is 64, and the docs now say so.
#[test]
fn the_documented_range_of_modes_is_the_enforced_one() {
    for doc in ["docs/knuckle-boom.md", "models/knuckle_boom.toml"] {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        assert!(text.contains("0–64"), "{doc}");
        assert!(
            !text.contains("(0–10;") && !text.contains("link 0–10 "),
            "{doc}"
        );
    }
    let e = bg_tests::load("knuckle_boom", &["parameters.modes1=65"]).unwrap_err();
    assert!(e.to_string().contains("0..=64"), "{e}");
}
