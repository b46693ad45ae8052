//! Edits of the model file's text: the candidates a model's entries offer, and applying
//! the chosen ones (set a key, remove one, set a key in every entry of a list).

use bg_model::Registry;
use bondgraph::kind::{Change, Default, KindDecl};
use toml_edit::{DocumentMut, Item, TableLike, Value};

use super::{Candidate, ElementActivity};

fn entry_mut<'a>(doc: &'a mut DocumentMut, name: &str) -> Option<&'a mut dyn TableLike> {
    doc.get_mut("elements")?
        .as_table_like_mut()?
        .get_mut(name)?
        .as_table_like_mut()
}

/// `list[*].key` → (`list`, `key`).
fn split_star(key: &str) -> Option<(&str, &str)> {
    key.split_once("[*].")
}

/// The entries of a list of tables (inline or not).
fn list_entries(item: &Item) -> Vec<&dyn TableLike> {
    if let Some(a) = item.as_array() {
        a.iter()
            .filter_map(|v| v.as_inline_table().map(|t| t as &dyn TableLike))
            .collect()
    } else if let Some(a) = item.as_array_of_tables() {
        a.iter().map(|t| t as &dyn TableLike).collect()
    } else {
        Vec::new()
    }
}

/// The value written as TOML text, for comparisons.
fn written(v: &Value) -> String {
    let mut v = v.clone();
    v.decor_mut().clear();
    v.to_string()
}

/// Whether `value` (TOML text) equals what `decl` gives when the key is absent.
fn equals_default(kind: &KindDecl, key: &str, value: &str) -> bool {
    let Some(d) = kind.param(key) else {
        return false;
    };
    let Ok(v) = value.parse::<Value>() else {
        return false;
    };
    match d.default {
        Default::Value(x) => v
            .as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .is_some_and(|y| y.total_cmp(&x).is_eq()), // the number written, not computed
        Default::Word(w) => v.as_str() == Some(w),
        Default::Flag(b) => v.as_bool() == Some(b),
        _ => false,
    }
}

/// Whether `change` changes entry `t` (of kind `kind`).
fn changes(t: &dyn TableLike, kind: &KindDecl, change: &Change) -> bool {
    match *change {
        Change::Unset(key) => t.contains_key(key),
        Change::Set(key, value) => {
            let target = value.parse::<Value>().map(|v| written(&v)).ok();
            if let Some((list, key)) = split_star(key) {
                return t.get(list).is_some_and(|l| {
                    list_entries(l).iter().any(|e| {
                        e.get(key)
                            .and_then(Item::as_value)
                            .is_some_and(|v| Some(written(v)) != target)
                    })
                });
            }
            match t.get(key).and_then(Item::as_value) {
                Some(v) => Some(written(v)) != target,
                None => !equals_default(kind, key, value),
            }
        }
    }
}

/// Every simplification of every entry of the model file `text` that changes it, with its
/// activity share from `ranking`, lowest share first (file order among equals).
///
/// # Errors
/// The text is not TOML.
pub fn candidates(
    text: &str,
    registry: &Registry,
    ranking: &[ElementActivity],
) -> Result<Vec<Candidate>, String> {
    let doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| e.to_string())?;
    let mut out = Vec::new();
    let Some(elements) = doc.get("elements").and_then(Item::as_table_like) else {
        return Ok(out);
    };
    for (name, item) in elements.iter() {
        let Some(t) = item.as_table_like() else {
            continue;
        };
        let Some(kind) = t
            .get("kind")
            .and_then(Item::as_str)
            .and_then(|k| registry.get(k))
        else {
            continue;
        };
        for s in kind.simplifications {
            if !s.changes.iter().any(|c| changes(t, kind, c)) {
                continue;
            }
            let share = ranking
                .iter()
                .filter(|a| {
                    a.composite == name
                        && (s.members.is_empty()
                            || s.members
                                .iter()
                                .any(|m| a.name == bondgraph::kind::member_name(name, m)))
                })
                .map(|a| a.share)
                .sum();
            out.push(Candidate {
                instance: name.to_owned(),
                kind: kind.name.to_owned(),
                simplification: *s,
                share,
            });
        }
    }
    out.sort_by(|a, b| a.share.total_cmp(&b.share));
    Ok(out)
}

/// The model file `text` with `picks` applied, in order.
///
/// # Errors
/// The text is not TOML, an entry is missing, or a value is not TOML.
pub fn apply(text: &str, picks: &[&Candidate]) -> Result<String, String> {
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| e.to_string())?;
    for c in picks {
        let t = entry_mut(&mut doc, &c.instance)
            .ok_or_else(|| format!("the model has no element `{}`", c.instance))?;
        for ch in c.simplification.changes {
            match *ch {
                Change::Unset(key) => {
                    t.remove(key);
                }
                Change::Set(key, value) => {
                    let v: Value = value.parse().map_err(|e: toml_edit::TomlError| {
                        format!("{}: `{value}` is not a TOML value: {e}", c.label())
                    })?;
                    if let Some((list, key)) = split_star(key) {
                        let Some(l) = t.get_mut(list) else { continue };
                        if let Some(a) = l.as_array_mut() {
                            for e in a.iter_mut().filter_map(Value::as_inline_table_mut) {
                                if e.contains_key(key) {
                                    e.insert(key, v.clone());
                                }
                            }
                        } else if let Some(a) = l.as_array_of_tables_mut() {
                            for e in a.iter_mut() {
                                if e.contains_key(key) {
                                    e.insert(key, Item::Value(v.clone()));
                                }
                            }
                        }
                    } else {
                        t.insert(key, Item::Value(v));
                    }
                }
            }
        }
    }
    Ok(doc.to_string())
}

/// The model file `text` with only the output columns `columns` (and `t`), and without its
/// `[[check]]`s and `[[plot]]`s: what the reducer runs when the user names the columns to
/// score, so that an output or a check reading a variable a simplification removes (a
/// line's `p[2]`) does not stop the reduced model from loading. The full model is run the
/// same way, so that their times compare.
///
/// # Errors
/// The text is not TOML.
pub fn keep_only(text: &str, columns: &[String]) -> Result<String, String> {
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| e.to_string())?;
    if let Some(outputs) = doc.get_mut("outputs").and_then(Item::as_table_like_mut) {
        let drop: Vec<String> = outputs
            .iter()
            .map(|(k, _)| k.to_owned())
            .filter(|k| !columns.contains(k))
            .collect();
        for k in drop {
            outputs.remove(&k);
        }
    }
    doc.remove("check");
    doc.remove("plot");
    Ok(doc.to_string())
}
