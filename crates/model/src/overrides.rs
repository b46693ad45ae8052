//! `--set key=value`: change any value of a model file before it is read.
//!
//! The key is a dotted TOML path (`parameters.k`, `simulation.t_end`, `elements.mass.m`);
//! the value is read as TOML (`2.5`, `"bdf"`, `[1, 2]`, `true`) or, failing that, taken as a
//! string (so `--set elements.spring.c=1/k` sets an expression). The document keeps its
//! layout, so errors still point at the right lines. A segment may be quoted
//! (`initial."spring.q"`), a key with dots written in quotes in the file is found as one key
//! (`initial.spring.q` sets `"spring.q"`), and `name[k]` addresses entry k of a list
//! (`events[0].t`, `check[1].tol`). Sections and `[simulation]` keys the format does not
//! have are refused here, not later at a line the user never wrote.

use toml_edit::{DocumentMut, Item, Value};

use crate::error::{clip, ErrorKind, ModelError};

/// The sections of a model file, and the keys of those with fixed keys.
const SECTIONS: &[&str] = &[
    "title",
    "description",
    "parameters",
    "elements",
    "bonds",
    "simulation",
    "initial",
    "events",
    "outputs",
    "check",
    "scene",
];
const SIMULATION_KEYS: &[&str] = &[
    "t_start",
    "t_end",
    "dt_out",
    "solver",
    "rtol",
    "atol",
    "linear_algebra",
];
const EVENT_KEYS: &[&str] = &["t", "set"];
const CHECK_KEYS: &[&str] = &["value", "expected", "tol"];

/// Apply `overrides` (`key=value` strings) to the TOML `text`.
pub fn apply(file: &str, text: &str, overrides: &[String]) -> Result<String, ModelError> {
    if overrides.is_empty() {
        return Ok(text.to_owned());
    }
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| {
        ModelError::new(ErrorKind::Syntax, file, e.message().to_owned())
    })?;
    for o in overrides {
        let err = |m: String| {
            ModelError::new(ErrorKind::Override, file, format!("--set {}: {m}", clip(o)))
        };
        let (key, value) = o
            .split_once('=')
            .ok_or_else(|| err("expected key=value".into()))?;
        let path = split_key(key.trim()).map_err(err)?;
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

/// Whether `apply` would accept the one override `o` on the parsed file `doc`, without
/// writing the file out again: the override is tried on a copy of the one section it
/// names (what `set_path` reads is that section alone), so checking many overrides
/// (every choice of every `[scene]` switch) parses the file once.
pub(crate) fn check(file: &str, doc: &DocumentMut, o: &str) -> Result<(), ModelError> {
    let err =
        |m: String| ModelError::new(ErrorKind::Override, file, format!("--set {}: {m}", clip(o)));
    let (key, value) = o
        .split_once('=')
        .ok_or_else(|| err("expected key=value".into()))?;
    let path = split_key(key.trim()).map_err(err)?;
    let value = parse_value(value.trim());
    let mut root = toml_edit::Table::new();
    if let Some(first) = path.first() {
        // `events[0]` reads the section `events`; a key written `name[k]` is itself a key
        let (key, literal) = (first.key.clone(), first.literal());
        // (the two are one key unless it is written `name[k]`: the section is cloned once)
        let keys = if literal == key {
            vec![key]
        } else {
            vec![key, literal]
        };
        for k in keys {
            if let Some(item) = doc.as_table().get(&k) {
                root.insert(&k, item.clone());
            }
        }
    }
    set_path(&mut Item::Table(root), &path, 0, value).map_err(|(m, hint)| {
        let e = err(m);
        match hint {
            Some(h) => e.hint(h),
            None => e,
        }
    })
}

/// One segment of a `--set` key: a key, with an array index if written `name[k]`.
#[derive(Clone, Debug, PartialEq)]
struct Segment {
    key: String,
    /// `name[k]`: entry k of the array `name` (if `name` is an array; else the key is
    /// `name[k]` itself, as in `[initial] "arm.q[1]"`).
    index: Option<usize>,
    /// The segment was quoted: never an array index, never split.
    quoted: bool,
}

impl Segment {
    /// The segment as written, for messages and literal keys.
    fn literal(&self) -> String {
        match self.index {
            Some(k) if !self.quoted => format!("{}[{k}]", self.key),
            _ => self.key.clone(),
        }
    }
}

/// Split a dotted key: `a.b`, `initial."spring.q"`, `events[0].t`.
fn split_key(key: &str) -> Result<Vec<Segment>, String> {
    let mut out = Vec::new();
    let mut chars = key.chars().peekable();
    loop {
        let mut seg = String::new();
        let mut quoted = false;
        if let Some(&q @ ('"' | '\'')) = chars.peek() {
            chars.next();
            quoted = true;
            loop {
                match chars.next() {
                    Some(c) if c == q => break,
                    Some(c) => seg.push(c),
                    None => return Err(format!("unclosed {q} in the key")),
                }
            }
        } else {
            while let Some(&c) = chars.peek() {
                if c == '.' {
                    break;
                }
                seg.push(c);
                chars.next();
            }
        }
        let seg = seg.trim().to_owned();
        if seg.is_empty() {
            return Err("empty key segment".into());
        }
        let index = if quoted {
            None
        } else {
            seg.strip_suffix(']')
                .and_then(|s| s.rsplit_once('['))
                .and_then(|(_, k)| k.parse::<usize>().ok())
        };
        let key = match index {
            Some(_) => seg[..seg.rfind('[').unwrap_or(seg.len())].to_owned(),
            None => seg,
        };
        out.push(Segment { key, index, quoted });
        match chars.next() {
            None => return Ok(out),
            Some('.') => {}
            Some(c) => return Err(format!("unexpected `{c}` after a quoted key segment")),
        }
    }
}

type SetError = (String, Option<String>);

/// The keys `path` may create where the format has fixed keys (`None`: any key).
fn allowed_keys(path: &[Segment], i: usize) -> Option<&'static [&'static str]> {
    match (i, path.first().map(|s| s.key.as_str())) {
        (0, _) => Some(SECTIONS),
        (1, Some("simulation")) => Some(SIMULATION_KEYS),
        (1, Some("events")) => Some(EVENT_KEYS),
        (1, Some("check")) => Some(CHECK_KEYS),
        _ => None,
    }
}

fn set_path(item: &mut Item, path: &[Segment], i: usize, value: Value) -> Result<(), SetError> {
    let written = |upto: usize| {
        path[..upto]
            .iter()
            .map(Segment::literal)
            .collect::<Vec<_>>()
            .join(".")
    };
    let table = item
        .as_table_like_mut()
        .ok_or_else(|| (format!("`{}` is not a table", written(i)), None))?;
    // A key with dots, quoted in the file (`[initial] "spring.q" = 0.1`), is set as one key.
    if path.len() > i + 1 && path[i..].iter().all(|s| s.index.is_none()) {
        let joined = path[i..]
            .iter()
            .map(|s| s.key.as_str())
            .collect::<Vec<_>>()
            .join(".");
        if let Some(old) = table.get(&joined).and_then(Item::as_value) {
            let mut value = value;
            *value.decor_mut() = old.decor().clone();
            table.insert(&joined, Item::Value(value));
            return Ok(());
        }
    }
    let seg = &path[i];
    // `name[k]`: an entry of an array (events[0], check[1]), if `name` is one
    let is_array = table
        .get(&seg.key)
        .is_some_and(|it| it.is_array_of_tables() || it.is_array());
    if let (Some(k), true) = (seg.index, is_array) {
        let Some(arr) = table.get_mut(&seg.key) else {
            return Err((format!("no `{}`", seg.key), None));
        };
        let len = arr
            .as_array_of_tables()
            .map(toml_edit::ArrayOfTables::len)
            .or_else(|| arr.as_array().map(toml_edit::Array::len))
            .unwrap_or(0);
        if k >= len {
            return Err((
                format!(
                    "`{}` has {len} entries, so there is no `{}`",
                    seg.key,
                    seg.literal()
                ),
                Some(format!(
                    "entries are numbered from 0: {}[0] to {}[{}]",
                    seg.key,
                    seg.key,
                    len.saturating_sub(1)
                )),
            ));
        }
        if i + 1 == path.len() {
            if let Some(a) = arr.as_array_mut() {
                a.replace(k, value);
                return Ok(());
            }
            return Err((
                format!("`{}` is a table: set one of its keys", seg.literal()),
                None,
            ));
        }
        if let Some(t) = arr.as_array_of_tables_mut().and_then(|a| a.get_mut(k)) {
            let mut item = Item::Table(std::mem::take(t));
            let r = set_path(&mut item, path, i + 1, value);
            if let Item::Table(back) = item {
                *t = back;
            }
            return r;
        }
        return Err((format!("`{}` is not a table", seg.literal()), None));
    }
    if is_array && !seg.quoted {
        let len = table
            .get(&seg.key)
            .and_then(|it| it.as_array_of_tables().map(toml_edit::ArrayOfTables::len))
            .unwrap_or(0);
        if len > 0 && i + 1 < path.len() {
            return Err((
                format!("`{}` is a list of {len}: name the entry", written(i + 1)),
                Some(format!(
                    "write `{}[0].{}`",
                    written(i + 1),
                    path[i + 1..]
                        .iter()
                        .map(Segment::literal)
                        .collect::<Vec<_>>()
                        .join(".")
                )),
            ));
        }
    }
    let key = seg.literal();
    let exists = table.get(&key).is_some();
    if !exists {
        if let Some(allowed) = allowed_keys(path, i).filter(|a| !a.contains(&key.as_str())) {
            let what = if i == 0 {
                "the model file format has no section".to_owned()
            } else {
                format!("`{}` has no key", written(i))
            };
            return Err((
                format!("{what} `{key}`"),
                Some(format!("the keys are: {}", allowed.join(", "))),
            ));
        }
    }
    if i + 1 == path.len() {
        // New keys are allowed only where the file format has optional keys.
        if !exists && path[0].key == "parameters" {
            let known: Vec<String> = table.iter().map(|(k, _)| k.to_owned()).collect();
            return Err((
                format!("the model has no parameter `{key}`"),
                Some(format!("parameters are: {}", known.join(", "))),
            ));
        }
        if !exists && path[0].key == "elements" && path.len() == 2 {
            return Err((
                format!("the model has no element `{key}`"),
                Some(known_keys(table)),
            ));
        }
        let mut value = value;
        if let Some(old) = table.get(&key).and_then(Item::as_value) {
            // keep the comment and spacing around the old value
            *value.decor_mut() = old.decor().clone();
        }
        table.insert(&key, Item::Value(value));
        return Ok(());
    }
    if !exists {
        if path[0].key == "elements" && i == 1 {
            return Err((
                format!("the model has no element `{key}`"),
                Some(known_keys(table)),
            ));
        }
        table.insert(&key, Item::Table(toml_edit::Table::new()));
    }
    let next = table
        .get_mut(&key)
        .ok_or_else(|| (format!("no `{key}`"), None))?;
    set_path(next, path, i + 1, value)
}

fn known_keys(table: &dyn toml_edit::TableLike) -> String {
    let keys: Vec<&str> = table.iter().map(|(k, _)| k).collect();
    format!("it has: {}", clip(&keys.join(", ")))
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
    fn check_agrees_with_apply_on_every_kind_of_key() {
        let model = format!(
            "{MODEL}\n[initial]\n\"arm.q[1]\" = 0.5\n\n[[events]]\nt = 0.5\nset = {{ k = 1.0 }}\n\n[[check]]\nvalue = \"k\"\nexpected = 1\ntol = 1\n"
        );
        let doc: DocumentMut = model.parse().unwrap();
        for o in [
            "parameters.k=5",
            "parameters.kk=5",
            "elements.mass.m=2",
            "elements.spring.c=1",
            "elements.mass=3",
            "simulation.solver=bdf",
            "simulation.tend=1",
            "nosection.x=1",
            "events[0].t=0.2",
            "events[3].t=0.2",
            "events.t=0.2",
            "events[0].set.k=2",
            "check[0].tol=2",
            "initial.\"arm.q[1]\"=0.1",
            "initial.x=1",
            "nokey",
            "parameters..k=1",
        ] {
            let a = apply("m.toml", &model, &[o.to_owned()]).map(drop);
            let c = check("m.toml", &doc, o);
            assert_eq!(
                a.as_ref().map_err(ToString::to_string),
                c.as_ref().map_err(ToString::to_string),
                "{o}"
            );
        }
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
