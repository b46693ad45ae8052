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
    assert!(e.to_string().contains("[0, 64]"), "{e}");
}

/// The project stands on its own: no source, model, test or document cites a file outside the
/// repository (the scene's conventions are in docs/knuckle-boom.md, in our own words).
#[test]
fn nothing_cites_a_file_outside_the_repository() {
    fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().filter_map(Result::ok) {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if p.is_dir() {
                if !matches!(name.as_str(), "target" | ".git" | "venv" | "__pycache__") {
                    walk(&p, out);
                }
            } else if ["rs", "md", "toml", "py", "pyi", "sh", "txt"]
                .iter()
                .any(|x| name.ends_with(&format!(".{x}")))
                || name == "run"
            {
                out.push(p);
            }
        }
    }
    let root = root();
    let mut files = Vec::new();
    for top in [
        "README.md",
        "ARCHITECTURE.md",
        ".ci",
        "crates",
        "docs",
        "models",
        "tests",
        "scripts",
    ] {
        let p = root.join(top);
        if p.is_dir() {
            walk(&p, &mut files);
        } else if p.exists() {
            files.push(p);
        }
    }
    assert!(files.len() > 50, "{} files", files.len());
    // spelled in pieces, so that this file does not match itself
    let outside = [
        ["shared", "/design"].concat(),
        ["shared", "/papers"].concat(),
        ["shared", "/guides"].concat(),
        ["../", "shared"].concat(),
        ["design", " page"].concat(),
    ];
    let mut found = Vec::new();
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        for (i, line) in text.lines().enumerate() {
            if outside.iter().any(|o| line.contains(o.as_str())) {
                found.push(format!("{}:{}: {line}", f.display(), i + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "references outside the repository:\n{}",
        found.join("\n")
    );
}
