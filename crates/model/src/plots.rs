//! `[[plot]]`: the figures a model draws of its own results (`bg-sim plot --model`,
//! `bg-sim run --plots`), declared in the model file beside the outputs they show.
//!
//! ```toml
//! [[plot]]
//! file = "joint-angles"            # output file stem: joint-angles.png / .svg
//! title = "Joint angles"
//! [[plot.panel]]                   # one panel (axes) per table, top to bottom
//! y_label = "angle"
//! convert = "rad->deg"             # for every series of the panel; the unit follows
//! series = [
//!   { column = "q1", label = "joint 1" },
//!   { column = "q2", label = "joint 2", dashed = true },
//! ]
//! ```
//!
//! A plot of one panel may give `y_label`, `unit`, `convert` and `series` directly in the
//! `[[plot]]` table. A series is a column of the results (an output, or `t`), its legend in
//! words, an optional conversion (a named one from [`CONVERSIONS`], or `scale` and `offset`:
//! shown = scale · value + offset) and whether it is dashed (a reference or a command drawn
//! on top of the solid curves). Everything that can be checked without the results is
//! checked when the model loads ([`read`]); whether the columns exist is checked when the
//! plot is drawn ([`Plot::check_columns`]), against the columns of the results at hand.

use std::ops::Range;

use serde::Deserialize;
use toml::Spanned;

use crate::error::{clip, line_col, ErrorKind, ModelError};

/// The named unit conversions: (name, scale, offset, unit shown); shown = scale · value +
/// offset.
pub const CONVERSIONS: &[(&str, f64, f64, &str)] = &[
    ("rad->deg", 180.0 / std::f64::consts::PI, 0.0, "deg"),
    ("deg->rad", std::f64::consts::PI / 180.0, 0.0, "rad"),
    ("rad/s->rpm", 30.0 / std::f64::consts::PI, 0.0, "rpm"),
    ("rad/s->deg/s", 180.0 / std::f64::consts::PI, 0.0, "deg/s"),
    ("Pa->kPa", 1e-3, 0.0, "kPa"),
    ("Pa->bar", 1e-5, 0.0, "bar"),
    ("Pa->MPa", 1e-6, 0.0, "MPa"),
    ("m^3/s->L/s", 1e3, 0.0, "L/s"),
    ("m^3/s->L/min", 6e4, 0.0, "L/min"),
    ("m^3->L", 1e3, 0.0, "L"),
    ("m->mm", 1e3, 0.0, "mm"),
    ("m->cm", 1e2, 0.0, "cm"),
    ("m/s->mm/s", 1e3, 0.0, "mm/s"),
    ("N->kN", 1e-3, 0.0, "kN"),
    ("N*m->kN*m", 1e-3, 0.0, "kN·m"),
    ("W->kW", 1e-3, 0.0, "kW"),
    ("J->kJ", 1e-3, 0.0, "kJ"),
    ("A->mA", 1e3, 0.0, "mA"),
    ("V->mV", 1e3, 0.0, "mV"),
    ("K->degC", 1.0, -273.15, "°C"),
    ("1->%", 100.0, 0.0, "%"),
];

/// The named conversion `name`: (scale, offset, unit shown).
#[must_use]
pub fn conversion(name: &str) -> Option<(f64, f64, &'static str)> {
    CONVERSIONS
        .iter()
        .find(|c| c.0 == name)
        .map(|c| (c.1, c.2, c.3))
}

/// One figure of a model: a title and panels stacked top to bottom over a common x column.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// Output file stem (`joint-angles` → `joint-angles.png`).
    pub file: String,
    /// Title, in words.
    pub title: String,
    /// The x column (`t` unless given).
    pub x: String,
    /// The x axis label, with its unit (`time [s]` for `t`).
    pub x_label: String,
    /// The panels, top to bottom.
    pub panels: Vec<Panel>,
    /// 1-based line of the `[[plot]]` table.
    pub line: usize,
}

/// One panel (a pair of axes) of a [`Plot`].
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// The quantity on the y axis, in words (`angle`).
    pub y_label: String,
    /// The unit shown (`deg`), if any: given, or the target of the series' conversion.
    pub unit: Option<String>,
    /// Only this x window (a close-up), or all of it.
    pub x_range: Option<(f64, f64)>,
    /// The curves.
    pub series: Vec<Series>,
    /// 1-based line of the panel.
    pub line: usize,
}

/// One curve of a [`Panel`].
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The column of the results.
    pub column: String,
    /// Legend text, in words.
    pub label: String,
    /// Shown = `scale` · value + `offset`.
    pub scale: f64,
    /// See `scale`.
    pub offset: f64,
    /// Dashed: a reference, a command or a variant, drawn on top of the solid curves.
    pub dashed: bool,
    /// 1-based line of the series.
    pub line: usize,
}

impl Panel {
    /// The y axis label with its unit: `angle [deg]`.
    #[must_use]
    pub fn axis_label(&self) -> String {
        match &self.unit {
            Some(u) if !u.is_empty() => format!("{} [{u}]", self.y_label),
            _ => self.y_label.clone(),
        }
    }
}

impl Series {
    /// The value shown for a column value.
    #[must_use]
    pub fn show(&self, v: f64) -> f64 {
        self.scale * v + self.offset
    }
}

impl Plot {
    /// Every column the plot reads: x first, then the series in order (repeats kept).
    pub fn columns(&self) -> impl Iterator<Item = &str> {
        std::iter::once(self.x.as_str()).chain(
            self.panels
                .iter()
                .flat_map(|p| p.series.iter().map(|s| s.column.as_str())),
        )
    }

    /// Check that every column the plot reads is among `columns` (those of the results at
    /// hand); the error names the first that is not, at its line in `file`, with the
    /// similar names there are.
    pub fn check_columns(&self, file: &str, columns: &[String]) -> Result<(), ModelError> {
        let has = |c: &str| columns.iter().any(|n| n == c);
        let missing = if has(&self.x) {
            self.panels
                .iter()
                .flat_map(|p| p.series.iter())
                .find(|s| !has(&s.column))
                .map(|s| (s.column.as_str(), s.line))
        } else {
            Some((self.x.as_str(), self.line))
        };
        let Some((column, line)) = missing else {
            return Ok(());
        };
        let hint = column_hint(column, columns);
        Err(ModelError::new(
            ErrorKind::Plot,
            file,
            format!(
                "[[plot]] `{}`: the results have no column `{}`",
                self.file,
                clip(column)
            ),
        )
        .at(Some((line, 1)))
        .hint(hint))
    }
}

/// What to say of a column that is not among `columns`: the names that differ only in case
/// (else those a misspelling away), or the columns there are.
#[must_use]
pub fn column_hint(column: &str, columns: &[String]) -> String {
    let mut close: Vec<&str> = columns
        .iter()
        .map(String::as_str)
        .filter(|n| n.eq_ignore_ascii_case(column))
        .collect();
    if close.is_empty() {
        close = columns
            .iter()
            .map(String::as_str)
            .filter(|n| bondgraph::kind::similar(column, n) || bondgraph::kind::similar(n, column))
            .take(8)
            .collect();
    }
    if close.is_empty() {
        let shown: Vec<&str> = columns.iter().map(String::as_str).take(12).collect();
        let more = columns.len().saturating_sub(shown.len());
        format!(
            "the results have the columns {}{}: name one of them, or add the column to [outputs]",
            shown.join(", "),
            if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            }
        )
    } else {
        let quoted: Vec<String> = close.iter().map(|c| format!("`{c}`")).collect();
        format!("did you mean {}?", quoted.join(" or "))
    }
}

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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::{Model, Registry};

    const BASE: &str = "[elements]\nm = { kind = \"I\", m = 1.0 }\ns = { kind = \"C\", k = 1.0, q0 = 1.0 }\nj = { kind = \"1\" }\n[bonds]\nb1 = \"j -> m\"\nb2 = \"j -> s\"\n[outputs]\nx = \"s.q\"\nv = \"m.f\"\n";

    fn load(plots: &str) -> Result<Model, ModelError> {
        Model::from_text(
            "m.toml",
            &format!("{BASE}{plots}"),
            &Registry::with_core(),
            &[],
        )
    }

    fn refused(plots: &str, line: usize, words: &[&str]) {
        let e = load(plots).unwrap_err();
        let text = e.to_string();
        assert_eq!(e.kind, ErrorKind::Plot, "{text}");
        assert_eq!(e.line, Some(line), "{text}");
        assert!(e.hint.is_some(), "{text}");
        for w in words {
            assert!(text.contains(w), "`{w}` missing from: {text}");
        }
    }

    /// Line of the first `[[plot]]` in a model: BASE has 10 lines.
    const L: usize = 11;

    #[test]
    fn reads_panels_series_conversions_and_defaults() {
        let m = load(
            "[[plot]]\nfile = \"one\"\ntitle = \"One panel\"\ny_label = \"position\"\nunit = \"m\"\nseries = [ { column = \"x\", label = \"spring stretch\" } ]\n\
             [[plot]]\nfile = \"two\"\ntitle = \"Two panels\"\nx = \"x\"\nx_label = \"stretch\"\nx_unit = \"m\"\n\
             [[plot.panel]]\ny_label = \"speed\"\nconvert = \"m->mm\"\nx_range = [0.0, 0.5]\nseries = [\n  { column = \"v\", label = \"mass\" },\n  { column = \"v\", label = \"scaled\", convert = \"m->mm\", dashed = true },\n]\n\
             [[plot.panel]]\ny_label = \"angle\"\nseries = [ { column = \"x\", label = \"as angle\", scale = 2.0, offset = 1.0 } ]\n",
        )
        .unwrap();
        let p = m.plots();
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].file.as_str(), p[0].line), ("one", L));
        assert_eq!(p[0].x, "t");
        assert_eq!(p[0].x_label, "time [s]");
        assert_eq!(p[0].panels[0].axis_label(), "position [m]");
        assert_eq!(p[1].x_label, "stretch [m]");
        let a = &p[1].panels[0];
        assert_eq!(a.axis_label(), "speed [mm]");
        assert_eq!(a.x_range, Some((0.0, 0.5)));
        assert_eq!(a.series.len(), 2);
        assert!(!a.series[0].dashed && a.series[1].dashed);
        assert!((a.series[0].show(0.25) - 250.0).abs() < 1e-12);
        assert_eq!(a.series[1].line, L + 18);
        let b = &p[1].panels[1];
        assert_eq!(b.axis_label(), "angle");
        assert!((b.series[0].show(3.0) - 7.0).abs() < 1e-12);
        let cols: Vec<&str> = p[1].columns().collect();
        assert_eq!(cols, ["x", "v", "v", "x"]);
    }

    #[test]
    fn named_conversions_are_right() {
        let c = |n: &str, v: f64| {
            let (a, b, _) = conversion(n).unwrap();
            a * v + b
        };
        assert!((c("rad->deg", std::f64::consts::PI) - 180.0).abs() < 1e-12);
        assert!((c("Pa->bar", 2e5) - 2.0).abs() < 1e-12);
        assert!((c("m^3/s->L/min", 1e-3) - 60.0).abs() < 1e-9);
        assert!((c("K->degC", 273.15)).abs() < 1e-12);
        assert!((c("rad/s->rpm", 2.0 * std::f64::consts::PI) - 60.0).abs() < 1e-9);
        assert!(conversion("furlong->m").is_none());
    }

    #[test]
    fn bad_tables_are_refused_with_line_plot_and_hint() {
        let head = "[[plot]]\nfile = \"p\"\ntitle = \"P\"\n";
        // unknown key in a series, at its line
        refused(
            &format!(
                "{head}y_label = \"a\"\nseries = [\n  {{ column = \"x\", colour = \"red\" }},\n]\n"
            ),
            L + 5,
            &["`p`", "colour"],
        );
        // unknown key in the plot
        refused(&format!("{head}legend = 1\n"), L + 3, &["`p`", "legend"]);
        // empty series
        refused(
            &format!("{head}y_label = \"a\"\nseries = []\n"),
            L + 4,
            &["`p`", "empty"],
        );
        // no series at all
        refused(head, L, &["`p`", "no series"]);
        // bad conversion, with the list of known ones in the hint
        refused(
            &format!("{head}y_label = \"a\"\nseries = [ {{ column = \"x\", convert = \"rad->degree\" }} ]\n"),
            L + 4,
            &["rad->degree", "rad->deg,"],
        );
        // a panel's unit against its conversion
        refused(
            &format!("{head}y_label = \"a\"\nunit = \"bar\"\nconvert = \"Pa->MPa\"\nseries = [ {{ column = \"x\" }} ]\n"),
            L + 4,
            &["bar", "MPa"],
        );
        // both panels and panel keys
        refused(
            &format!("{head}series = [ {{ column = \"x\" }} ]\n[[plot.panel]]\ny_label = \"a\"\nseries = [ {{ column = \"x\" }} ]\n"),
            L,
            &["[[plot.panel]]"],
        );
        // a panel without y_label, at the panel's line
        refused(
            &format!("{head}[[plot.panel]]\nseries = [ {{ column = \"x\" }} ]\n"),
            L + 3,
            &["y_label"],
        );
        // no file, no title, a bad file name, twice the same file
        refused("[[plot]]\ntitle = \"P\"\n", L, &["number 1", "`file`"]);
        refused("[[plot]]\nfile = \"p\"\n", L, &["`title`"]);
        refused(
            "[[plot]]\nfile = \"a/b.png\"\ntitle = \"P\"\n",
            L + 1,
            &["file name"],
        );
        refused(
            &format!("{head}y_label = \"a\"\nseries = [ {{ column = \"x\" }} ]\n{head}y_label = \"a\"\nseries = [ {{ column = \"x\" }} ]\n"),
            L + 5,
            &["line 11"],
        );
        // a bad x_range, a wrong type
        refused(
            &format!(
                "{head}y_label = \"a\"\nx_range = [2.0, 1.0]\nseries = [ {{ column = \"x\" }} ]\n"
            ),
            L + 4,
            &["x_range"],
        );
        refused(&format!("{head}y_label = 3\n"), L + 3, &["`p`", "string"]);
    }

    #[test]
    fn a_missing_column_is_named_with_similar_ones() {
        let m = load("[[plot]]\nfile = \"p\"\ntitle = \"P\"\ny_label = \"a\"\nseries = [\n  { column = \"x\" },\n  { column = \"V\" },\n]\n").unwrap();
        let cols: Vec<String> = ["t", "x", "v"].iter().map(|s| (*s).to_owned()).collect();
        let e = m.plots()[0].check_columns("m.toml", &cols).unwrap_err();
        assert_eq!(e.line, Some(L + 6));
        assert!(
            e.message.contains("`V`") && e.message.contains("`p`"),
            "{e}"
        );
        assert!(e.hint.as_deref().unwrap().contains("`v`"), "{e}");
        // nothing alike: the hint lists the columns there are
        let far = load("[[plot]]\nfile = \"p\"\ntitle = \"P\"\ny_label = \"a\"\nseries = [ { column = \"force\" } ]\n").unwrap();
        let e = far.plots()[0].check_columns("m.toml", &cols).unwrap_err();
        assert!(e.hint.as_deref().unwrap().contains("t, x, v"), "{e}");
        let all: Vec<String> = ["t", "x", "V"].iter().map(|s| (*s).to_owned()).collect();
        m.plots()[0].check_columns("m.toml", &all).unwrap();
    }
}
