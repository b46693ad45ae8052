//! Reading the `[[plot]]` tables: everything that can be checked without the results.

use std::ops::Range;

use serde::Deserialize;
use toml::Spanned;

use super::{conversion, Panel, Plot, Series, CONVERSIONS};
use crate::error::{clip, line_col, ModelError};

/// The `[[plot]]` tables as written (the rest of the file is read by the loader).
#[derive(Deserialize)]
struct PlotsFile<T> {
    #[serde(default = "Vec::new")]
    plot: Vec<Spanned<T>>,
}

type Text = Option<Spanned<String>>;
type SeriesList = Option<Spanned<Vec<Spanned<SeriesSpec>>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlotSpec {
    file: Text,
    title: Text,
    x: Text,
    x_label: Text,
    x_unit: Text,
    panel: Option<Vec<Spanned<PanelSpec>>>,
    // a plot of one panel: the panel's keys in the plot's table
    y_label: Text,
    unit: Text,
    convert: Text,
    x_range: Option<Spanned<Vec<f64>>>,
    series: SeriesList,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PanelSpec {
    y_label: Text,
    unit: Text,
    convert: Text,
    x_range: Option<Spanned<Vec<f64>>>,
    series: SeriesList,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SeriesSpec {
    column: Spanned<String>,
    label: Text,
    convert: Text,
    scale: Option<Spanned<f64>>,
    offset: Option<Spanned<f64>>,
    dashed: Option<bool>,
}

const SHAPE: &str = "a [[plot]] has `file`, `title`, optional `x`, `x_label`, `x_unit`, then its panels as [[plot.panel]] tables of `y_label`, `unit`, `convert`, `x_range` and `series` (one panel may sit in the [[plot]] table itself); a series is { column = \"q1\", label = \"joint 1\", convert = \"rad->deg\" or scale = …, offset = …, dashed = true }; docs/model-format.md, section Plots";

/// Whether `s` can be a file stem: 1 to 64 letters, digits, `-` and `_`.
fn valid_stem(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// Makes an error at a byte span of the file.
type ErrAt<'a> = &'a dyn Fn(Option<&Range<usize>>, String) -> ModelError;

/// Read and check the `[[plot]]` tables of a model file's text (after `--set`). `err` makes
/// an error at a byte span of `text`.
pub(crate) fn read(text: &str, err: ErrAt<'_>) -> Result<Vec<Plot>, ModelError> {
    let specs = match toml::from_str::<PlotsFile<PlotSpec>>(text) {
        Ok(f) => f.plot,
        Err(e) => {
            // name the plot: the last `[[plot]]` header before the error
            let at = e.span();
            let name = toml::from_str::<PlotsFile<toml::Value>>(text)
                .ok()
                .and_then(|f| {
                    f.plot
                        .iter()
                        .enumerate()
                        .rfind(|(_, p)| at.as_ref().is_none_or(|a| p.span().start <= a.start))
                        .map(|(i, p)| {
                            plot_name(i, p.get_ref().get("file").and_then(toml::Value::as_str))
                        })
                })
                .unwrap_or_default();
            return Err(err(
                at.as_ref(),
                format!("[[plot]] {name}: {}", e.message().trim()),
            )
            .hint(SHAPE));
        }
    };
    let mut plots: Vec<Plot> = Vec::new();
    for (i, spec) in specs.into_iter().enumerate() {
        let span = spec.span();
        let spec = spec.into_inner();
        let name = plot_name(i, spec.file.as_ref().map(|f| f.get_ref().as_str()));
        let at = |s: &Range<usize>, m: String| err(Some(s), format!("[[plot]] {name}: {m}"));
        let p = plot(text, spec, &span, &at)?;
        if let Some(prev) = plots.iter().find(|q| q.file == p.file) {
            return Err(at(
                &span,
                format!(
                    "the file `{}` is also that of the plot at line {}",
                    p.file, prev.line
                ),
            )
            .hint("give each [[plot]] its own `file`"));
        }
        plots.push(p);
    }
    Ok(plots)
}

fn plot_name(i: usize, file: Option<&str>) -> String {
    file.map_or_else(|| format!("number {}", i + 1), |f| format!("`{}`", clip(f)))
}

fn plot(
    text: &str,
    spec: PlotSpec,
    span: &Range<usize>,
    at: &dyn Fn(&Range<usize>, String) -> ModelError,
) -> Result<Plot, ModelError> {
    let line = |s: &Range<usize>| line_col(text, s.start).0;
    let file = spec.file.ok_or_else(|| {
        at(span, "has no `file`".to_owned())
            .hint("name the output: `file = \"pressures\"` writes pressures.png and pressures.svg")
    })?;
    if !valid_stem(file.get_ref()) {
        return Err(at(&file.span(), format!("`{}` cannot be a file name", clip(file.get_ref())))
            .hint("a plot's `file` is 1 to 64 letters, digits, `-` and `_`, without an extension: `joint-angles`"));
    }
    let title = spec.title.ok_or_else(|| {
        at(span, "has no `title`".to_owned())
            .hint("say what the figure shows: `title = \"Chamber pressures\"`")
    })?;
    let x = spec.x.map_or_else(|| "t".to_owned(), Spanned::into_inner);
    let x_unit = spec
        .x_unit
        .map(Spanned::into_inner)
        .or_else(|| (x == "t").then(|| "s".to_owned()));
    let x_word = spec.x_label.map(Spanned::into_inner).unwrap_or_else(|| {
        if x == "t" {
            "time".to_owned()
        } else {
            x.clone()
        }
    });
    let x_label = match x_unit {
        Some(u) if !u.is_empty() => format!("{x_word} [{u}]"),
        _ => x_word,
    };
    let single = PanelSpec {
        y_label: spec.y_label,
        unit: spec.unit,
        convert: spec.convert,
        x_range: spec.x_range,
        series: spec.series,
    };
    let has_single = single.y_label.is_some()
        || single.unit.is_some()
        || single.convert.is_some()
        || single.x_range.is_some()
        || single.series.is_some();
    let mut panels = Vec::new();
    match spec.panel {
        Some(list) => {
            if has_single {
                return Err(at(span, "has [[plot.panel]] tables and also panel keys (`y_label`, `unit`, `convert`, `x_range`, `series`) of its own".to_owned())
                    .hint("move those keys into a [[plot.panel]] table"));
            }
            if list.is_empty() {
                return Err(at(span, "has no panels".to_owned()).hint(SHAPE));
            }
            for p in list {
                let s = p.span();
                panels.push(panel(text, p.into_inner(), &s, at)?);
            }
        }
        None => {
            if single.series.is_none() {
                return Err(at(span, "has no series".to_owned()).hint(SHAPE));
            }
            panels.push(panel(text, single, span, at)?);
        }
    }
    Ok(Plot {
        file: file.into_inner(),
        title: title.into_inner(),
        x,
        x_label,
        panels,
        line: line(span),
    })
}

fn panel(
    text: &str,
    spec: PanelSpec,
    span: &Range<usize>,
    at: &dyn Fn(&Range<usize>, String) -> ModelError,
) -> Result<Panel, ModelError> {
    let line = |s: &Range<usize>| line_col(text, s.start).0;
    let series_list = spec.series.ok_or_else(|| {
        at(span, "a panel has no `series`".to_owned())
            .hint("list its curves: `series = [ { column = \"p\", label = \"pressure\" } ]`")
    })?;
    if series_list.get_ref().is_empty() {
        return Err(at(&series_list.span(), "`series` is empty".to_owned())
            .hint("a panel draws at least one column: `series = [ { column = \"p\", label = \"pressure\" } ]`"));
    }
    let y_label = spec.y_label.ok_or_else(|| {
        at(span, "a panel has no `y_label`".to_owned()).hint("name the quantity on the y axis in words: `y_label = \"pressure\"` (the unit goes in `unit`)")
    })?;
    let x_range = match spec.x_range {
        None => None,
        Some(r) => match r.get_ref()[..] {
            [a, b] if a.is_finite() && b.is_finite() && a < b => Some((a, b)),
            _ => {
                return Err(at(
                    &r.span(),
                    "`x_range` must be two finite numbers, the first the smaller".to_owned(),
                )
                .hint("a close-up of the first two seconds: `x_range = [0.0, 2.0]`"))
            }
        },
    };
    let panel_convert = match &spec.convert {
        Some(c) => Some(named(c, at)?),
        None => None,
    };
    let mut series = Vec::new();
    let mut shown_units: Vec<&'static str> = Vec::new();
    for s in series_list.into_inner() {
        let s_span = s.span();
        let s = s.into_inner();
        let column = s.column.get_ref();
        if column.trim().is_empty() {
            return Err(at(
                &s.column.span(),
                "a series has an empty `column`".to_owned(),
            )
            .hint("name a column of the results (an output of [outputs], or `t`)"));
        }
        let (scale, offset, unit) = match (&s.convert, &s.scale, &s.offset) {
            (Some(c), None, None) => named(c, at).map(|(a, b, u)| (a, b, Some(u)))?,
            (Some(c), _, _) => {
                return Err(at(
                    &c.span(),
                    format!(
                        "series `{}` has both `convert` and `scale`/`offset`",
                        clip(column)
                    ),
                )
                .hint("use a named conversion, or scale and offset, not both"))
            }
            (None, None, None) => {
                panel_convert.map_or((1.0, 0.0, None), |(a, b, u)| (a, b, Some(u)))
            }
            (None, sc, of) => {
                let scale = sc.as_ref().map_or(1.0, |v| *v.get_ref());
                let offset = of.as_ref().map_or(0.0, |v| *v.get_ref());
                if !scale.is_finite() || scale == 0.0 || !offset.is_finite() {
                    let s = sc
                        .as_ref()
                        .or(of.as_ref())
                        .map_or(s_span.clone(), Spanned::span);
                    return Err(at(
                        &s,
                        format!(
                            "series `{}`: `scale` must be finite and non-zero, `offset` finite",
                            clip(column)
                        ),
                    )
                    .hint("shown = scale · value + offset, e.g. `scale = 1e-3` for N → kN"));
                }
                (scale, offset, None)
            }
        };
        if let Some(u) = unit {
            if !shown_units.contains(&u) {
                shown_units.push(u);
            }
        }
        series.push(Series {
            column: column.clone(),
            label: s.label.map_or_else(|| column.clone(), Spanned::into_inner),
            scale,
            offset,
            dashed: s.dashed.unwrap_or(false),
            line: line(&s_span),
        });
    }
    let unit = match (spec.unit, shown_units.as_slice()) {
        (Some(u), conv) => {
            if let Some(other) = conv.iter().find(|c| **c != u.get_ref()) {
                return Err(at(
                    &u.span(),
                    format!(
                        "the panel's unit is `{}` but a series is converted to `{other}`",
                        clip(u.get_ref())
                    ),
                )
                .hint(
                    "leave `unit` out (a conversion gives it) or make it the conversion's unit",
                ));
            }
            Some(u.into_inner())
        }
        (None, [one]) => Some((*one).to_owned()),
        (None, []) => None,
        (None, _) => {
            return Err(at(
                span,
                format!(
                    "the panel's series are converted to different units ({})",
                    shown_units.join(", ")
                ),
            )
            .hint("draw quantities of different units in different panels"))
        }
    };
    Ok(Panel {
        y_label: y_label.into_inner(),
        unit,
        x_range,
        series,
        line: line(span),
    })
}

/// A named conversion, or an error listing the known ones.
fn named(
    c: &Spanned<String>,
    at: &dyn Fn(&Range<usize>, String) -> ModelError,
) -> Result<(f64, f64, &'static str), ModelError> {
    conversion(c.get_ref()).ok_or_else(|| {
        let names: Vec<&str> = CONVERSIONS.iter().map(|c| c.0).collect();
        at(&c.span(), format!("unknown conversion `{}`", clip(c.get_ref()))).hint(format!(
            "the named conversions are {}; for another, give `scale` and `offset` on the series (shown = scale · value + offset)",
            names.join(", ")
        ))
    })
}
