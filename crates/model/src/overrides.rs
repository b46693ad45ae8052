//! `--set key=value`: change any value of a model file before it is read.
//!
//! The key is a dotted TOML path (`parameters.k`, `simulation.t_end`, `elements.mass.m`);
//! the value is read as TOML (`2.5`, `"bdf"`, `[1, 2]`, `true`) or, failing that, taken as a
//! string (so `--set elements.spring.c=1/k` sets an expression). The document keeps its
//! layout, so errors still point at the right lines.

use toml_edit::{DocumentMut, Item, Value};

use crate::error::{ErrorKind, ModelError};

/// Apply `overrides` (`key=value` strings) to the TOML `text`.
pub fn apply(file: &str, text: &str, overrides: &[String]) -> Result<String, ModelError> {
    if overrides.is_empty() {
        return Ok(text.to_owned());
    }
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| {
        ModelError::new(ErrorKind::Syntax, file, e.message().to_owned())
    })?;
    for o in overrides {
        let err = |m: String| ModelError::new(ErrorKind::Override, file, format!("--set {o}: {m}"));
        let (key, value) = o
            .split_once('=')
            .ok_or_else(|| err("expected key=value".into()))?;
        let path: Vec<&str> = key.trim().split('.').collect();
        if path.iter().any(|p| p.is_empty()) {
            return Err(err("empty key segment".into()));
        }
        let value = parse_value(value.trim());
        set_path(doc.as_item_mut(), &path, 0, value).map_err(|(m, hint)| {
            let e = err(m);
            match hint {
                Some(h) => e.hint(h),
                None => e,
            }
        })?;
    }
    Ok(doc.to_string())
}

type SetError = (String, Option<String>);

fn set_path(item: &mut Item, path: &[&str], i: usize, value: Value) -> Result<(), SetError> {
    let seg = path[i];
    let table = item
        .as_table_like_mut()
        .ok_or_else(|| (format!("`{}` is not a table", path[..i].join(".")), None))?;
    let exists = table.get(seg).is_some();
    if i + 1 == path.len() {
        // New keys are allowed only where the file format has optional keys.
        if !exists && path[0] == "parameters" {
            let known: Vec<String> = table.iter().map(|(k, _)| k.to_owned()).collect();
            return Err((
                format!("the model has no parameter `{seg}`"),
                Some(format!("parameters are: {}", known.join(", "))),
            ));
        }
        if !exists && path[0] == "elements" && path.len() == 2 {
            return Err((
                format!("the model has no element `{seg}`"),
                Some(known_keys(table)),
            ));
        }
        let mut value = value;
        if let Some(old) = table.get(seg).and_then(Item::as_value) {
            // keep the comment and spacing around the old value
            *value.decor_mut() = old.decor().clone();
        }
        table.insert(seg, Item::Value(value));
        return Ok(());
    }
    if !exists {
        if path[0] == "elements" && i == 1 {
            return Err((
                format!("the model has no element `{seg}`"),
                Some(known_keys(table)),
            ));
        }
        table.insert(seg, Item::Table(toml_edit::Table::new()));
    }
    let next = table
        .get_mut(seg)
        .ok_or_else(|| (format!("no `{seg}`"), None))?;
    set_path(next, path, i + 1, value)
}

fn known_keys(table: &dyn toml_edit::TableLike) -> String {
    let keys: Vec<&str> = table.iter().map(|(k, _)| k).collect();
    format!("it has: {}", keys.join(", "))
}

fn parse_value(s: &str) -> Value {
    s.parse::<Value>().unwrap_or_else(|_| Value::from(s))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const MODEL: &str = "[parameters]\nk = 100.0 # stiffness\n\n[elements]\nmass = { kind = \"I\", m = 1.0 }\n\n[simulation]\nt_end = 1.0\n";

    #[test]
    fn changes_values_and_keeps_lines() {
        let out = apply(
            "m.toml",
            MODEL,
            &[
                "parameters.k=5".into(),
                "elements.mass.m=1/k".into(),
                "simulation.solver=esdirk34".into(),
            ],
        )
        .unwrap();
        assert!(out.contains("k = 5 # stiffness"), "{out}");
        assert!(out.contains("m = \"1/k\""), "{out}");
        assert!(out.contains("solver = \"esdirk34\""), "{out}");
        assert_eq!(
            out.lines().position(|l| l.starts_with("mass")),
            MODEL.lines().position(|l| l.starts_with("mass"))
        );
    }

    #[test]
    fn refuses_unknown_parameters_and_elements() {
        let e = apply("m.toml", MODEL, &["parameters.kk=5".into()]).unwrap_err();
        assert!(e.to_string().contains("no parameter `kk`"), "{e}");
        assert!(e.to_string().contains("parameters are: k"), "{e}");
        assert!(apply("m.toml", MODEL, &["elements.spring.c=1".into()]).is_err());
        assert!(apply("m.toml", MODEL, &["nokey".into()]).is_err());
    }
}
