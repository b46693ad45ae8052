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

use crate::error::{clip, ErrorKind, ModelError};

mod conversions;
mod read;

pub use conversions::{conversion, CONVERSIONS};
pub(crate) use read::read;

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
