//! `--format json` of `check` and `run`: the problems of a model file as JSON objects, one
//! shape for every command, so that an editor or a script reads them without parsing text.

use bg_model::ModelError;
use serde_json::{json, Value};

/// How `check` and `run` report on stdout.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    // lines for a person (the default)
    #[default]
    Text,
    // one JSON document; the text report, if any, goes to stderr
    Json,
}

/// Problems (or notes) as a JSON array of objects
/// `{file, line, column, element, kind, message, hint}`; what a problem lacks (a line, an
/// element, a hint) is `null`. `kind` is the [`bg_model::ErrorKind`] in snake case
/// (`unknown_kind`, `bad_parameter`, `causality`, …).
pub fn problems(errors: &[ModelError]) -> Value {
    Value::Array(
        errors
            .iter()
            .map(|e| {
                json!({
                    "file": e.file,
                    "line": e.line,
                    "column": e.col,
                    "element": e.element,
                    "kind": snake_case(&format!("{:?}", e.kind)),
                    "message": e.message,
                    "hint": e.hint,
                })
            })
            .collect(),
    )
}

/// `UnknownKind` → `unknown_kind`.
fn snake_case(name: &str) -> String {
    let mut s = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                s.push('_');
            }
            s.push(c.to_ascii_lowercase());
        } else {
            s.push(c);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_are_snake_case() {
        assert_eq!(snake_case("UnknownKind"), "unknown_kind");
        assert_eq!(snake_case("Io"), "io");
    }
}
