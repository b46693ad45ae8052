//! Helpers for the workspace tests: where the models are, and how to load them with every
//! element kind the CLI knows.

use std::path::PathBuf;

use bg_model::{Model, ModelError};

/// The workspace root.
#[must_use]
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `models/*.toml`, sorted.
#[must_use]
pub fn model_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("models"))
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Models that are meant to be refused (their file name says so).
#[must_use]
pub fn is_refused(path: &std::path::Path) -> bool {
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    name == "derivative_causality" || name == "algebraic_loop"
}

/// Load `models/<name>.toml` with `--set` overrides.
pub fn load(name: &str, overrides: &[&str]) -> Result<Model, ModelError> {
    let set: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    Model::load(
        &root().join("models").join(format!("{name}.toml")),
        &bg_sim::registry(),
        &set,
    )
}
