//! What the loader keeps of a model file once parsed: its text (to place errors), its
//! entries with their raw parameters (to rebuild an element for an event) and its events.

use std::collections::HashSet;
use std::ops::Range;

use indexmap::IndexMap;

use crate::error::{line_col, ErrorKind, ModelError};
use crate::reader::RawValue;
use crate::registry::Registry;

/// One `[elements]` entry as written.
#[derive(Clone, Debug)]
pub(super) struct ElementDef {
    pub(super) name: String,
    pub(super) kind: String,
    pub(super) params: IndexMap<String, RawValue>,
    pub(super) name_span: Range<usize>,
    /// The `[parameters]` its values use (filled when it is built).
    pub(super) used: HashSet<String>,
    /// Global names of the elements this entry became (itself, or a composite's members).
    pub(super) members: Vec<String>,
    /// A composite's exposed ports: name → `member` or `member.port` (global names).
    pub(super) ports: Vec<(String, String)>,
}

/// One `[[events]]` table as written.
#[derive(Clone, Debug)]
pub(super) struct EventDef {
    pub(super) t: f64,
    pub(super) set: IndexMap<String, RawValue>,
    pub(super) span: Range<usize>,
}

/// The model file as the later stages and the events need it.
#[derive(Clone, Debug)]
pub(super) struct Source {
    pub(super) file: String,
    pub(super) text: String,
    pub(super) registry: Registry,
    pub(super) param_exprs: IndexMap<String, RawValue>,
    /// The `[parameters]` written with a unit (`p = "300 bar"`), for the checks of the
    /// element parameters that use them by name.
    pub(super) param_units: std::sync::Arc<crate::reader::ParamUnits>,
    pub(super) elements: Vec<ElementDef>,
    pub(super) events: Vec<EventDef>,
    /// Lines (1-based) that `--set` wrote or changed: errors there say so.
    pub(super) changed_lines: Vec<usize>,
    /// The `[[plot]]` tables (`crate::plots`).
    pub(super) plots: Vec<crate::plots::Plot>,
    /// The `[inputs]` entries (`super::inputs`).
    pub(super) inputs: Vec<super::inputs::InputDef>,
    /// The `[tables]` (`super::tables`), shared by every expression that calls one.
    pub(super) tables: std::sync::Arc<crate::tables::Tables>,
    /// Byte offset of each line's start in `text`: an error's line by binary search, so
    /// that refusing N mistakes is linear in N (issue 24, item 7), not N scans of the text.
    pub(super) line_starts: Vec<usize>,
    /// Entry index by entry name and by member name, built on the first look-up (after the
    /// entries are built): finding a name is O(1), so loading is linear in the model's size
    /// (issue 37, item 8). A name it misses is looked for by a scan.
    pub(super) index: std::sync::OnceLock<std::collections::HashMap<String, usize>>,
}

/// Byte offsets of the starts of the lines of `text`.
pub(super) fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect()
}

impl Source {
    /// An error at `span` of the file.
    pub(super) fn err(
        &self,
        kind: ErrorKind,
        span: Option<&Range<usize>>,
        message: impl Into<String>,
    ) -> ModelError {
        let pos = span.map(|s| self.line_col(s.start));
        let e = ModelError::new(kind, &self.file, message).at(pos);
        mark_set_line(e, &self.changed_lines)
    }

    /// Line and column of the entry that defines element `name` (or a member of it, or
    /// the `[inputs]` entry of that name).
    pub(super) fn element_pos(&self, name: &str) -> Option<(usize, usize)> {
        self.entry_of(name)
            .map(|e| self.line_col(e.name_span.start))
            .or_else(|| {
                self.inputs
                    .iter()
                    .find(|d| d.spec.name == name)
                    .map(|d| self.line_col(d.span.start))
            })
    }

    /// An error reading the data file `shown` that `what` (`table \`tb\``, `input \`F\``,
    /// written at `span`) names: one without a line of the data file (missing, empty, a
    /// directory) is placed at `span` in the model, naming the data file; one inside it
    /// (a bad cell) stays at its line there, saying whose data it is. `columns` is the
    /// header to suggest for an empty file.
    pub(super) fn data_err(
        &self,
        kind: ErrorKind,
        span: &Range<usize>,
        what: &str,
        shown: &str,
        e: ModelError,
        columns: &str,
    ) -> ModelError {
        if e.line.is_some() {
            let mut e = e;
            e.message = format!("{what}: {}", e.message);
            return e;
        }
        let message = match e.message.strip_prefix("cannot read the data file") {
            Some(rest) => format!("{what}: cannot read the data file `{shown}`{rest}"),
            None => format!("{what}: the data file `{shown}` {}", e.message),
        };
        let hint = if e.message.contains("no header") {
            Some(format!("the first line names the columns: `{columns}`"))
        } else {
            e.hint
        };
        self.err(kind, Some(span), message).or_hint(hint)
    }

    /// The entry called `name`, or whose member is called `name`.
    pub(super) fn entry_of(&self, name: &str) -> Option<&ElementDef> {
        let index = self.index.get_or_init(|| {
            let mut m = std::collections::HashMap::with_capacity(self.elements.len());
            for (i, e) in self.elements.iter().enumerate() {
                m.entry(e.name.clone()).or_insert(i);
                for n in &e.members {
                    m.entry(n.clone()).or_insert(i);
                }
            }
            m
        });
        index
            .get(name)
            .and_then(|&i| self.elements.get(i))
            .or_else(|| {
                self.elements
                    .iter()
                    .find(|e| e.name == name || e.members.iter().any(|m| m == name))
            })
    }

    /// The names of the `[inputs]`.
    pub(super) fn input_names(&self) -> Vec<String> {
        self.inputs.iter().map(|d| d.spec.name.clone()).collect()
    }

    /// Line and column (1-based) of byte `offset`, as [`line_col`] gives them, in
    /// O(log lines + line length).
    fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let line = self.line_starts.partition_point(|&s| s <= offset).max(1);
        let start = self.line_starts.get(line - 1).copied().unwrap_or(0);
        match self.text.get(start..offset) {
            Some(before) => (line, before.chars().count() + 1),
            None => line_col(&self.text, offset),
        }
    }
}

/// Say so when an error points at a line that `--set` wrote or changed.
pub(super) fn mark_set_line(mut e: ModelError, changed: &[usize]) -> ModelError {
    if e.line.is_some_and(|l| changed.contains(&l)) {
        e.message
            .push_str(" (at a line written by --set: the file as changed by the overrides)");
    }
    e
}
