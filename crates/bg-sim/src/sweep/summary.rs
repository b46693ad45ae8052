//! The summary table: one CSV line per run ([`header`], [`line`]), read back by
//! [`read_summary`].

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

use super::run::RunRow;
use super::spec::Spec;
use super::{err, SweepError};

/// RFC 4180 quoting where needed; line breaks become ` / ` so one run is one line.
pub(super) fn csv_field(s: &str) -> String {
    let s = s.replace("\r\n", " / ").replace(['\n', '\r'], " / ");
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}

/// Split one CSV line written by [`csv_field`] into fields.
pub(super) fn csv_split(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', q) => quoted = !q,
            (',', false) => out.push(std::mem::take(&mut cur)),
            (c, _) => cur.push(c),
        }
    }
    out.push(cur);
    out
}

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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn csv_fields_round_trip() {
        let f = ["a", "b,c", "say \"hi\"", "two\nlines"];
        let l: Vec<String> = f.iter().map(|s| csv_field(s)).collect();
        let back = csv_split(&l.join(","));
        assert_eq!(back, ["a", "b,c", "say \"hi\"", "two / lines"]);
    }
}
