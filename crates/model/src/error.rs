//! [`ModelError`]: every problem in a model file, with the file, line and column, the element
//! concerned and a hint.

use std::fmt;
use std::sync::Arc;

/// What kind of problem a [`ModelError`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file cannot be read.
    Io,
    /// The TOML does not parse, or has the wrong shape.
    Syntax,
    /// A `--set` override cannot be applied.
    Override,
    /// An element kind nobody registered.
    UnknownKind,
    /// A bond or event names an element that does not exist.
    UnknownElement,
    /// A required parameter is missing.
    MissingParameter,
    /// A parameter the element does not take.
    ExtraParameter,
    /// A parameter value is invalid (negative mass, non-finite number, bad expression, …).
    BadParameter,
    /// The graph's structure is wrong (ports, dimensions, signals).
    Graph,
    /// Causality assignment or equation ordering failed.
    Causality,
    /// Simulation settings, events or outputs are wrong.
    Settings,
    /// A `[scene]` switch is wrong.
    Scene,
    /// A `[[plot]]` table is wrong, or names a column the results do not have.
    Plot,
    /// A data file (inputs, tables) is wrong: a cell, a row, its times, its coverage.
    Data,
    /// An `[inputs]` entry, or a data column given to an input, is wrong.
    Input,
    /// A `[tables]` entry is wrong.
    Table,
}

/// A problem in a model file.
#[derive(Clone, Debug)]
pub struct ModelError {
    /// What kind of problem.
    pub kind: ErrorKind,
    /// The model file.
    pub file: String,
    /// 1-based line, where the TOML gives one.
    pub line: Option<usize>,
    /// 1-based column.
    pub col: Option<usize>,
    /// The element concerned, if any.
    pub element: Option<String>,
    /// What is wrong.
    pub message: String,
    /// What to do about it.
    pub hint: Option<String>,
    /// The error underneath (an element's [`bondgraph::BuildError`], a core
    /// [`bondgraph::Error`]), for [`std::error::Error::source`].
    pub source: Option<Arc<dyn std::error::Error + Send + Sync>>,
}

impl PartialEq for ModelError {
    /// Equal when everything but the source is.
    fn eq(&self, o: &Self) -> bool {
        (
            self.kind,
            &self.file,
            self.line,
            self.col,
            &self.element,
            &self.message,
            &self.hint,
        ) == (
            o.kind, &o.file, o.line, o.col, &o.element, &o.message, &o.hint,
        )
    }
}

impl Eq for ModelError {}

impl ModelError {
    pub(crate) fn new(kind: ErrorKind, file: &str, message: impl Into<String>) -> Self {
        Self {
            kind,
            file: file.to_owned(),
            line: None,
            col: None,
            element: None,
            message: clip_to(&message.into(), MAX_MESSAGE),
            hint: None,
            source: None,
        }
    }
    pub(crate) fn at(mut self, pos: Option<(usize, usize)>) -> Self {
        if let Some((l, c)) = pos {
            self.line = Some(l);
            self.col = Some(c);
        }
        self
    }
    pub(crate) fn element(mut self, name: &str) -> Self {
        self.element = Some(name.to_owned());
        self
    }
    /// With a hint.
    #[must_use]
    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(clip_to(&hint.into(), MAX_MESSAGE));
        self
    }
    /// With `hint` if there is one, else as it is.
    #[must_use]
    pub(crate) fn or_hint(self, hint: Option<String>) -> Self {
        match hint {
            Some(h) => self.hint(h),
            None => self,
        }
    }
    /// With the error underneath.
    #[must_use]
    pub fn with_source(mut self, source: impl std::error::Error + Send + Sync + 'static) -> Self {
        self.source = Some(Arc::new(source));
        self
    }
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.col {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(e) = &self.element {
            // an input or a table is not an element; its messages may name it already
            let word = match self.kind {
                ErrorKind::Input => "input",
                ErrorKind::Table => "table",
                _ => "element",
            };
            let named = format!("{word} `{e}`");
            if !self.message.starts_with(&named) {
                write!(f, "{named}: ")?;
            }
        }
        write!(f, "{}", self.message)?;
        if let Some(h) = &self.hint {
            write!(f, "\n  hint: {h}")?;
        }
        Ok(())
    }
}

impl ErrorKind {
    /// The kind's name in JSON (`bad_parameter`, `unknown_kind`, …).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Io => "io",
            Self::Syntax => "syntax",
            Self::Override => "override",
            Self::UnknownKind => "unknown_kind",
            Self::UnknownElement => "unknown_element",
            Self::MissingParameter => "missing_parameter",
            Self::ExtraParameter => "extra_parameter",
            Self::BadParameter => "bad_parameter",
            Self::Graph => "graph",
            Self::Causality => "causality",
            Self::Settings => "settings",
            Self::Scene => "scene",
            Self::Plot => "plot",
            Self::Data => "data",
            Self::Input => "input",
            Self::Table => "table",
        }
    }
}

impl serde::Serialize for ErrorKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// As JSON: `{"file", "line", "column", "element", "kind", "message", "hint"}` (`null`
/// where there is none); the source is not written (its message is the message).
impl serde::Serialize for ModelError {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut m = s.serialize_struct("ModelError", 7)?;
        m.serialize_field("file", &self.file)?;
        m.serialize_field("line", &self.line)?;
        m.serialize_field("column", &self.col)?;
        m.serialize_field("element", &self.element)?;
        m.serialize_field("kind", &self.kind)?;
        m.serialize_field("message", &self.message)?;
        m.serialize_field("hint", &self.hint)?;
        m.end()
    }
}

impl std::error::Error for ModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

/// Longest piece of user input an error message repeats, in characters.
pub const MAX_ECHO: usize = 80;

/// Longest message or hint, in characters: the rest is cut (a 10 MB value must not come
/// back on stderr).
pub const MAX_MESSAGE: usize = 2_000;

/// `s` cut to [`MAX_ECHO`] characters, saying how much was left out.
#[must_use]
pub fn clip(s: &str) -> String {
    clip_to(s, MAX_ECHO)
}

fn clip_to(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        None => s.to_owned(),
        Some((i, _)) => format!("{}… ({} more characters)", &s[..i], s[i..].chars().count()),
    }
}

/// The line breaks in `b`, counted in blocks of 64 bytes into a byte-wide count the compiler
/// vectorises: bytes, not chars, as a UTF-8 continuation byte is never `\n` (`matches('\n')`
/// took 8 M instructions of the crane's start-up for its 87 look-ups).
fn count_newlines(b: &[u8]) -> usize {
    b.chunks(64)
        .map(|c| usize::from(c.iter().fold(0u8, |n, &x| n + u8::from(x == b'\n'))))
        .sum()
}

/// Line and column (1-based) of byte `offset` in `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = count_newlines(before.as_bytes()) + 1;
    let col = before
        .rfind('\n')
        .map_or(before.chars().count(), |i| before[i + 1..].chars().count())
        + 1;
    (line, col)
}

/// Byte offset of the first value `= 123…` whose digits do not fit an i64 (TOML integers).
pub(crate) fn too_large_integer(text: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        if let Some(eq) = line.find('=') {
            let value = &line[eq + 1..];
            let lead = value.len() - value.trim_start().len();
            let v = value.trim_start();
            let digits: String = v
                .chars()
                .take_while(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '_'))
                .filter(|c| *c != '_')
                .collect();
            let rest = &v[v
                .char_indices()
                .find(|(_, c)| !(c.is_ascii_digit() || matches!(c, '+' | '-' | '_')))
                .map_or(v.len(), |(i, _)| i)..];
            let float = rest.starts_with(['.', 'e', 'E']);
            if !float
                && digits.chars().any(|c| c.is_ascii_digit())
                && digits.parse::<i64>().is_err()
            {
                return Some(offset + eq + 1 + lead);
            }
        }
        offset += line.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::line_col;

    /// Lines and columns as the characters give them, over blocks of 64 bytes and
    /// multi-byte characters.
    #[test]
    fn line_col_counts_lines_and_characters() {
        let text = "é\nab\n".repeat(40) + "x→y\nz";
        for offset in (0..=text.len()).filter(|&o| text.is_char_boundary(o)) {
            let before = &text[..offset];
            let line = before.chars().filter(|&c| c == '\n').count() + 1;
            let col = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
            assert_eq!(line_col(&text, offset), (line, col), "offset {offset}");
        }
        assert_eq!(line_col(&text, usize::MAX).0, 82);
    }
}
