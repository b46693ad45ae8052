//! The `[tables]` section: lookup tables ([`crate::tables`]) read and checked, each problem
//! naming the table and the entry (non-monotone x, sizes that disagree, NaN entries).

use std::ops::Range;

use super::inputs::relative;
use super::parse::{valid_name, SpannedMap};
use super::source::Source;
use crate::data::DataFile;
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::{FUNCTIONS, RESERVED};
use crate::tables::{Table, TableExtrapolate, TableInterp, Tables};

const KEYS: &[&str] = &[
    "x",
    "y",
    "z",
    "file",
    "interp",
    "extrapolate",
    "description",
];

/// Read every `[tables]` entry; problems go to `problems`.
pub(super) fn read(
    table: &SpannedMap<toml::Value>,
    source: &Source,
    problems: &mut Vec<ModelError>,
) -> Tables {
    let mut out = Tables::default();
    for (name, value) in table {
        match entry(name.get_ref(), &name.span(), value.get_ref(), source) {
            Ok(t) => out.list.push(t),
            Err(e) => problems.push(e),
        }
    }
    out
}

fn numbers(v: &toml::Value) -> Option<Vec<f64>> {
    v.as_array()?
        .iter()
        .map(|x| match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            toml::Value::String(s) if s.eq_ignore_ascii_case("nan") => Some(f64::NAN),
            _ => None,
        })
        .collect()
}

fn entry(
    name: &str,
    span: &Range<usize>,
    value: &toml::Value,
    source: &Source,
) -> Result<Table, ModelError> {
    let err = |m: String| {
        source
            .err(
                ErrorKind::Table,
                Some(span),
                format!("table `{}`: {m}", clip(name)),
            )
            .element(name)
    };
    if !valid_name(name) || RESERVED.contains(&name) || FUNCTIONS.iter().any(|(f, _)| *f == name) {
        return Err(err("cannot be a table name".into())
            .hint("table names are letters, digits and _, and not a built-in function (sqrt, exp, min, …)"));
    }
    if source.param_exprs.contains_key(name) || source.inputs.iter().any(|d| d.spec.name == name) {
        return Err(err("is also a parameter or an input".into()).hint("rename one of them"));
    }
    let toml::Value::Table(t) = value else {
        return Err(err("must be a table".into()).hint("write `name = { x = [...], y = [...] }`"));
    };
    for k in t.keys() {
        if !KEYS.contains(&k.as_str()) {
            let close = bondgraph::kind::suggest(k, KEYS.iter().copied());
            return Err(err(format!("has no key `{}`", clip(k))).hint(match close {
                Some(c) => format!("did you mean `{c}`? keys: {}", KEYS.join(", ")),
                None => format!("keys: {}", KEYS.join(", ")),
            }));
        }
    }
    let word = |k: &str| t.get(k).and_then(toml::Value::as_str);
    let interp = match word("interp") {
        None | Some("linear") => TableInterp::Linear,
        Some("cubic") => TableInterp::Cubic,
        Some(o) => {
            return Err(err(format!("`interp` = `{}`", clip(o)))
                .hint("`interp` is \"linear\" or \"cubic\""))
        }
    };
    let extrapolate = match word("extrapolate") {
        None | Some("hold") => TableExtrapolate::Hold,
        Some("linear") => TableExtrapolate::Linear,
        Some("error") => TableExtrapolate::Error,
        Some(o) => {
            return Err(err(format!("`extrapolate` = `{}`", clip(o)))
                .hint("`extrapolate` is \"hold\" (the default), \"linear\" or \"error\""))
        }
    };
    let (x, y, z) = if let Some(file) = word("file") {
        if t.contains_key("x") || t.contains_key("y") || t.contains_key("z") {
            return Err(err("gives both `file` and values".into())
                .hint("give either `file` or `x`, `y` (and `z`)"));
        }
        from_file(name, file, source, span)?
    } else {
        let axis = |k: &str| -> Result<Option<Vec<f64>>, ModelError> {
            t.get(k)
                .map(|v| numbers(v).ok_or_else(|| err(format!("`{k}` must be a list of numbers"))))
                .transpose()
        };
        let x = axis("x")?.ok_or_else(|| err("has no `x`".into()).hint("write `x = [...]`"))?;
        let y = axis("y")?.ok_or_else(|| err("has no `y`".into()).hint("write `y = [...]`"))?;
        let z = match t.get("z") {
            None => None,
            Some(v) => Some(
                v.as_array()
                    .and_then(|rows| rows.iter().map(numbers).collect::<Option<Vec<_>>>())
                    .ok_or_else(|| {
                        err("`z` must be a list of rows of numbers, one row per x".into())
                    })?,
            ),
        };
        (x, y, z)
    };
    check_axis(name, "x", &x).map_err(err)?;
    match z {
        None => {
            if y.len() != x.len() {
                return Err(err(format!(
                    "`x` has {} entries and `y` {}: they must be as many",
                    x.len(),
                    y.len()
                )));
            }
            if let Some(k) = y.iter().position(|v| !v.is_finite()) {
                return Err(err(format!("y[{k}] = {} is not finite", y[k]))
                    .hint("fill every entry with a number"));
            }
            Ok(Table::one(name, x, y, interp, extrapolate))
        }
        Some(z) => {
            check_axis(name, "y", &y).map_err(err)?;
            if z.len() != x.len() {
                return Err(err(format!(
                    "`z` has {} rows and `x` {} entries: one row per x",
                    z.len(),
                    x.len()
                )));
            }
            for (i, row) in z.iter().enumerate() {
                if row.len() != y.len() {
                    return Err(err(format!(
                        "row z[{i}] has {} entries and `y` {}: one per y",
                        row.len(),
                        y.len()
                    )));
                }
                if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                    return Err(err(format!("z[{i}][{j}] = {} is not finite", row[j]))
                        .hint("fill every entry with a number"));
                }
            }
            Ok(Table::two(name, x, y, z, interp, extrapolate))
        }
    }
}

fn check_axis(_name: &str, key: &str, v: &[f64]) -> Result<(), String> {
    if v.len() < 2 {
        return Err(format!("`{key}` needs at least 2 entries, has {}", v.len()));
    }
    if let Some(k) = v.iter().position(|a| !a.is_finite()) {
        return Err(format!("{key}[{k}] = {} is not finite", v[k]));
    }
    if let Some(k) = (1..v.len()).find(|&k| v[k] <= v[k - 1]) {
        return Err(format!(
            "`{key}` must increase strictly: {key}[{k}] = {} is not after {key}[{}] = {}",
            v[k],
            k - 1,
            v[k - 1]
        ));
    }
    Ok(())
}

/// A table from a CSV, relative to the model: a header `x,y` (in either order: columns are
/// read by name) then rows of numbers (1-D), or a grid whose header holds the y values after
/// a first cell that is not a number (`x\y`), and each row an x value then its z values.
type Grid = (Vec<f64>, Vec<f64>, Option<Vec<Vec<f64>>>);

fn from_file(
    name: &str,
    file: &str,
    source: &Source,
    span: &Range<usize>,
) -> Result<Grid, ModelError> {
    let path = relative(&source.file, file);
    let shown = path.display().to_string();
    let what = format!("table `{}`", clip(name));
    let data = DataFile::read(&path, &shown)
        .map_err(|e| source.data_err(ErrorKind::Table, span, &what, &shown, e, "x,y"))?;
    let refuse = |m: String, hint: &str| {
        source
            .err(
                ErrorKind::Table,
                Some(span),
                format!("{what}: `{shown}` {m}"),
            )
            .hint(hint.to_owned())
    };
    const HINTS: &str = "a 1-D table file starts with the header `x,y`; a 2-D one with `x\\y, y1, y2, …` (numbers after the first cell)";
    let number = |c: &String| c.parse::<f64>().is_ok();
    let names = &data.names;
    if names.iter().all(number) {
        return Err(refuse(
            format!(
                "has no header: its first line `{}` is numbers",
                clip(&names.join(","))
            ),
            HINTS,
        ));
    }
    if names.len() > 2 && names[1..].iter().all(number) {
        // 2-D: the header's cells after the first are the y values
        let y: Vec<f64> = names[1..].iter().filter_map(|c| c.parse().ok()).collect();
        let x = data.columns[0].clone();
        let z: Vec<Vec<f64>> = (0..x.len())
            .map(|i| (1..names.len()).map(|k| data.columns[k][i]).collect())
            .collect();
        return Ok((x, y, Some(z)));
    }
    let (Some(kx), Some(ky), 2) = (data.column("x"), data.column("y"), names.len()) else {
        return Err(refuse(
            format!(
                "has the columns {}: a 1-D table file has the two columns `x` and `y`",
                clip(
                    &names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            ),
            HINTS,
        ));
    };
    Ok((data.columns[kx].clone(), data.columns[ky].clone(), None))
}
