//! The summary table: one CSV line per run ([`header`], [`line`]), read back by
//! [`read_summary`].

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

use super::csv::{csv_field, csv_split};
use super::run::RunRow;
use super::spec::Spec;
use super::{err, SweepError};

/// The summary's header: run id, index, the swept paths, the metrics, then the run's facts.
#[must_use]
pub fn header(spec: &Spec) -> Vec<String> {
    let mut h = vec!["run".to_owned(), "index".to_owned()];
    h.extend(spec.parameters.iter().map(|(k, _)| k.clone()));
    h.extend(spec.metrics.iter().map(|m| m.name.clone()));
    h.extend(["status", "steps", "wall_s", "error"].map(str::to_owned));
    h
}

/// One summary line (no line break).
#[must_use]
pub fn line(row: &RunRow) -> String {
    let mut f = vec![row.point.id(), row.point.index.to_string()];
    f.extend(row.point.values.iter().map(|(_, v)| csv_field(&v.render())));
    f.extend(
        row.metrics
            .iter()
            .map(|m| m.map(|v| format!("{v:?}")).unwrap_or_default()),
    );
    f.push(row.status.as_str().to_owned());
    f.push(row.steps.to_string());
    let mut w = String::new();
    let _ = write!(w, "{:.6}", row.wall_s);
    f.push(w);
    f.push(csv_field(&row.error));
    f.join(",")
}

/// Read a summary table back: the header and each row's fields.
pub fn read_summary(path: &Path) -> Result<(Vec<String>, Vec<Vec<String>>), SweepError> {
    let shown = path.display().to_string();
    let text = fs::read_to_string(path).map_err(|e| err(&shown, e.to_string()))?;
    let mut lines = text.lines();
    let head = lines
        .next()
        .map(csv_split)
        .ok_or_else(|| err(&shown, "empty"))?;
    Ok((head, lines.map(csv_split).collect()))
}
