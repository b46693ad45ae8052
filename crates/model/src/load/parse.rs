//! Stage 1, parse: the model file (after `--set`, [`crate::overrides`]) as TOML with spans,
//! into the typed sections below and a [`Source`]. Only a file that is not TOML, too large
//! or without elements stops here; a bad name or a missing `kind` is a problem of that entry
//! alone, collected in [`Parsed::problems`] with the others.

use std::collections::HashSet;
use std::path::Path;

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

use super::source::{mark_set_line, ElementDef, EventDef, Source};
use crate::error::{clip, line_col, ErrorKind, ModelError};
use crate::expr::RESERVED;
use crate::reader::RawValue;
use crate::registry::Registry;
use crate::scene::Scene;

pub(super) type SpannedMap<V> = IndexMap<Spanned<String>, Spanned<V>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileSpec {
    pub(super) title: Option<String>,
    pub(super) description: Option<String>,
    #[serde(default)]
    pub(super) parameters: SpannedMap<toml::Value>,
    #[serde(default)]
    pub(super) elements: SpannedMap<SpannedMap<toml::Value>>,
    #[serde(default)]
    pub(super) bonds: SpannedMap<String>,
    pub(super) simulation: Option<SimulationSpec>,
    #[serde(default)]
    pub(super) initial: SpannedMap<toml::Value>,
    #[serde(default)]
    pub(super) events: Vec<Spanned<EventSpec>>,
    #[serde(default)]
    pub(super) outputs: SpannedMap<String>,
    #[serde(default)]
    pub(super) check: Vec<Spanned<CheckSpec>>,
    #[serde(default)]
    pub(super) scene: SpannedMap<toml::Value>,
    /// `[inputs]`: read by `super::inputs`.
    #[serde(default)]
    pub(super) inputs: SpannedMap<toml::Value>,
    /// `[tables]`: read by `super::tables`.
    #[serde(default)]
    pub(super) tables: SpannedMap<toml::Value>,
    /// `[[plot]]`: read by `crate::plots`.
    #[serde(default, rename = "plot")]
    pub(super) _plot: serde::de::IgnoredAny,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct SimulationSpec {
    pub(super) t_start: Option<Spanned<f64>>,
    pub(super) t_end: Option<Spanned<f64>>,
    pub(super) dt_out: Option<Spanned<f64>>,
    pub(super) solver: Option<Spanned<String>>,
    pub(super) rtol: Option<Spanned<f64>>,
    pub(super) atol: Option<Spanned<f64>>,
    pub(super) linear_algebra: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EventSpec {
    pub(super) t: f64,
    pub(super) set: SpannedMap<toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CheckSpec {
    pub(super) value: Spanned<String>,
    pub(super) expected: Spanned<String>,
    pub(super) tol: Spanned<f64>,
}

/// What parsing found: the sections, the [`Source`], the parameters' values, and the
/// problems so far (every one, in file order).
pub(super) struct Parsed {
    pub(super) spec: FileSpec,
    pub(super) source: Source,
    pub(super) parameters: IndexMap<String, f64>,
    pub(super) scene: Scene,
    pub(super) problems: Vec<ModelError>,
    pub(super) failed: Failed,
}

/// Names whose problem is reported already: what uses them is not reported again.
#[derive(Default)]
pub(super) struct Failed {
    /// Parameters that have no value.
    pub(super) params: HashSet<String>,
    /// Entries that were not built.
    pub(super) elements: HashSet<String>,
}

impl Parsed {
    /// The first problem, if there is one (what [`super::Model::load`] reports).
    pub(super) fn first_problem(&mut self) -> Result<(), ModelError> {
        if self.problems.is_empty() {
            Ok(())
        } else {
            Err(self.problems.remove(0))
        }
    }
}

fn syntax(file: &str, text: &str, e: &toml::de::Error) -> ModelError {
    let pos = e
        .span()
        .map(|s| s.start)
        .or_else(|| {
            // the parser names no place for an integer past i64: find the first one
            e.message()
                .contains("overflow")
                .then(|| crate::error::too_large_integer(text))
                .flatten()
        })
        .map(|at| line_col(text, at));
    let mut message = e.message().trim().to_owned();
    if let Some(s) = e.span() {
        // name the key or value the parser stopped at
        let at = text.get(s.clone()).unwrap_or("").trim();
        if !at.is_empty() && at.len() < 60 && !at.contains('\n') && !message.contains(at) {
            message = format!("{message}: `{at}`");
        }
    }
    ModelError::new(ErrorKind::Syntax, file, message)
        .at(pos)
        .hint("a model has the sections title, description, [parameters], [elements], [bonds], [simulation], [initial], [[events]], [outputs], [[check]], [scene], [[plot]], [inputs], [tables]")
}

/// The lines (1-based) of `after` that differ from those of `before`.
fn changed_lines(before: &str, after: &str) -> Vec<usize> {
    if before == after {
        return Vec::new();
    }
    let old: Vec<&str> = before.lines().collect();
    after
        .lines()
        .enumerate()
        .filter(|(i, l)| old.get(*i) != Some(l))
        .map(|(i, _)| i + 1)
        .collect()
}

/// Largest model file (and model text after `--set`), in bytes.
pub const MAX_FILE_BYTES: usize = 16 << 20;

/// Read a model file: at most [`MAX_FILE_BYTES`] (`/dev/zero` is refused, not read until
/// memory runs out), UTF-8 (an invalid byte is named with its line, column and offset).
pub(super) fn read_model(path: &Path, file: &str) -> Result<String, ModelError> {
    use std::io::Read;
    let io = |e: std::io::Error| {
        ModelError::new(ErrorKind::Io, file, format!("cannot read: {e}")).hint("check the path")
    };
    // a FIFO without a writer blocks `open` for ever, and a directory is no model: both are
    // refused before opening (issue 24, item 10); devices such as /dev/zero are read, bounded
    if let Ok(meta) = std::fs::metadata(path) {
        let kind = meta.file_type();
        #[cfg(unix)]
        let special = {
            use std::os::unix::fs::FileTypeExt;
            if kind.is_fifo() {
                Some("a FIFO (named pipe)")
            } else if kind.is_socket() {
                Some("a socket")
            } else {
                None
            }
        };
        #[cfg(not(unix))]
        let special: Option<&str> = None;
        let what = if kind.is_dir() {
            Some("a directory")
        } else {
            special
        };
        if let Some(what) = what {
            return Err(ModelError::new(
                ErrorKind::Io,
                file,
                format!("cannot read: it is {what}, not a model file"),
            )
            .hint("give the path of a model's .toml file (write piped text to a file first)"));
        }
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES as u64 + 1).read_to_end(&mut bytes))
        .map_err(io)?;
    check_size(file, bytes.len())?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let valid = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        let pos = line_col(valid, valid.len());
        ModelError::new(
            ErrorKind::Syntax,
            file,
            format!(
                "not UTF-8 text: the byte at offset {at} (0x{:02x}) is not valid UTF-8",
                bytes.get(at).copied().unwrap_or(0)
            ),
        )
        .at(Some(pos))
        .hint("save the model as UTF-8")
    })
}

fn check_size(file: &str, len: usize) -> Result<(), ModelError> {
    if len > MAX_FILE_BYTES {
        return Err(ModelError::new(
            ErrorKind::Io,
            file,
            format!(
                "is larger than {} MiB, the limit for a model file",
                MAX_FILE_BYTES >> 20
            ),
        )
        .hint("a model file is text of a few kB; is this the right file?"));
    }
    Ok(())
}

pub(super) fn valid_name(n: &str) -> bool {
    let mut c = n.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

fn raw(v: &Spanned<toml::Value>) -> RawValue {
    RawValue {
        value: v.get_ref().clone(),
        span: v.span(),
    }
}

/// Parse `text` (named `file` in errors) with `--set` overrides applied.
pub(super) fn parse(
    file: &str,
    text: &str,
    registry: &Registry,
    overrides: &[String],
) -> Result<Parsed, ModelError> {
    check_size(file, text.len())?;
    let original = text;
    let text = crate::overrides::apply(file, text, overrides)?;
    check_size(file, text.len())?;
    let changed_lines = changed_lines(original, &text);
    let spec: FileSpec = toml::from_str(&text)
        .map_err(|e| mark_set_line(syntax(file, &text, &e), &changed_lines))?;
    if spec.elements.is_empty() {
        return Err(ModelError::new(ErrorKind::Syntax, file, "the model has no elements")
            .at(Some((1, 1)))
            .hint("add an [elements] section, e.g. `mass = { kind = \"I\", m = 1.0 }`; see docs/model-format.md"));
    }
    let mut source = Source {
        file: file.to_owned(),
        text: text.clone(),
        registry: registry.clone(),
        param_exprs: IndexMap::new(),
        param_units: std::sync::Arc::default(),
        elements: Vec::new(),
        events: Vec::new(),
        changed_lines,
        plots: Vec::new(),
        inputs: Vec::new(),
        tables: std::sync::Arc::default(),
        line_starts: super::source::line_starts(&text),
        index: std::sync::OnceLock::new(),
    };
    let mut problems = Vec::new();
    let mut failed = Failed::default();
    match crate::plots::read(&text, &|span, m| source.err(ErrorKind::Plot, span, m)) {
        Ok(plots) => source.plots = plots,
        Err(e) => problems.push(e),
    }
    for (k, v) in &spec.parameters {
        if !valid_name(k.get_ref()) || RESERVED.contains(&k.get_ref().as_str()) {
            problems.push(source
                .err(ErrorKind::BadParameter, Some(&k.span()), format!("`{}` cannot be a parameter name", clip(k.get_ref())))
                .hint("parameter names are letters, digits and _ (starting with a letter); `t`, `time` and `pi` are reserved"));
            failed.params.insert(k.get_ref().clone());
            continue;
        }
        source.param_exprs.insert(k.get_ref().clone(), raw(v));
    }
    source.param_units = std::sync::Arc::new(source.units_of_parameters());
    let (parameters, errors, failed_params) = source.evaluate_all(&IndexMap::new());
    problems.extend(errors);
    failed.params.extend(failed_params);
    for (name, table) in &spec.elements {
        match entry(&source, name, table.get_ref()) {
            Ok(def) => source.elements.push(def),
            Err(e) => {
                problems.push(e);
                failed.elements.insert(name.get_ref().clone());
            }
        }
    }
    source.inputs = super::inputs::read(&spec.inputs, &source, &parameters, &mut problems);
    source.tables = std::sync::Arc::new(super::tables::read(&spec.tables, &source, &mut problems));
    for ev in &spec.events {
        let set = ev
            .get_ref()
            .set
            .iter()
            .map(|(k, v)| (k.get_ref().clone(), raw(v)))
            .collect();
        source.events.push(EventDef {
            t: ev.get_ref().t,
            set,
            span: ev.span(),
        });
    }
    let scene = crate::scene::read(file, &text, &spec.scene, &|span, m| {
        source.err(ErrorKind::Scene, span, m)
    })
    .unwrap_or_else(|e| {
        problems.push(e);
        Scene::default()
    });
    Ok(Parsed {
        spec,
        source,
        parameters,
        scene,
        problems,
        failed,
    })
}

/// One `[elements]` entry: its name, `kind` and raw parameters.
fn entry(
    source: &Source,
    name: &Spanned<String>,
    table: &SpannedMap<toml::Value>,
) -> Result<ElementDef, ModelError> {
    let n = name.get_ref();
    if !valid_name(n) {
        return Err(source
            .err(
                ErrorKind::Syntax,
                Some(&name.span()),
                format!("`{}` cannot be an element name", clip(n)),
            )
            .hint("element names are letters, digits and _ (starting with a letter), no dots"));
    }
    let mut params = IndexMap::new();
    let mut kind = None;
    for (k, v) in table {
        if k.get_ref() == "kind" {
            match v.get_ref() {
                toml::Value::String(s) => kind = Some(s.clone()),
                _ => {
                    return Err(source
                        .err(
                            ErrorKind::Syntax,
                            Some(&v.span()),
                            "`kind` must be a string such as \"R\" or \"hydraulics.orifice\"",
                        )
                        .element(n))
                }
            }
        } else {
            params.insert(k.get_ref().clone(), raw(v));
        }
    }
    let kind = kind.ok_or_else(|| {
        source
            .err(ErrorKind::Syntax, Some(&name.span()), "has no `kind`")
            .element(n)
            .hint("write e.g. `mass = { kind = \"I\", m = 1.0 }`")
    })?;
    Ok(ElementDef {
        name: n.clone(),
        kind,
        params,
        name_span: name.span(),
        used: HashSet::new(),
        members: vec![n.clone()],
        ports: Vec::new(),
    })
}
