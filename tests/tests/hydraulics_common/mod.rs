//! Shared by the hydraulic model-file tests: the registry with the hydraulic kinds and the
//! workspace's models.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use bg_model::{Model, ModelError, Registry};
use bondgraph::Trajectory;

/// The core kinds plus `hydraulics.*`.
pub fn registry() -> Registry {
    let mut r = Registry::with_core();
    r.add(bg_hydraulics::KINDS);
    r
}

/// `models/<name>.toml` of the workspace.
pub fn model_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../models")
        .join(format!("{name}.toml"))
}

/// Load a workspace model with `--set` overrides.
pub fn load(name: &str, overrides: &[&str]) -> Result<Model, ModelError> {
    let set: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    Model::load(&model_path(name), &registry(), &set)
}

/// A column of a trajectory, by name.
pub fn col(t: &Trajectory, name: &str) -> Vec<f64> {
    t.column(name)
        .unwrap_or_else(|| panic!("no column `{name}` in {:?}", t.columns))
}
