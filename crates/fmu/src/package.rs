//! The `.fmu` archive of a model ([`export`]): `modelDescription.xml`, the shared library
//! (this crate's `cdylib`) under `binaries/<platform>/<modelIdentifier>.so`, and under
//! `resources/` the model file (after `--set`), every data and table file it names (at the
//! same relative paths) and the manifest naming the model ([`MANIFEST`]).

use std::io::Write as _;
use std::path::{Component, Path, PathBuf};

use bg_model::{Model, ModelError};
use zip::write::SimpleFileOptions;

use crate::description::{Description, FmiVersion};
use crate::instance::{registry, MANIFEST};

/// Why an export failed: the model (file, line, hint) or the files around it.
#[derive(Debug)]
pub enum ExportError {
    /// The model does not load.
    Model(Box<ModelError>),
    /// A file the model names (or the engine library) is missing, unreadable or absolute.
    File(String),
    /// The FMU could not be written.
    Output(String),
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Model(e) => write!(f, "{e}"),
            Self::File(m) | Self::Output(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for ExportError {}

impl From<ModelError> for ExportError {
    fn from(e: ModelError) -> Self {
        Self::Model(Box::new(e))
    }
}

/// What was written.
#[derive(Debug)]
pub struct Exported {
    /// The description written.
    pub description: Description,
    /// `modelIdentifier` (the library's name in the FMU).
    pub model_identifier: String,
    /// The archive's entries, in order.
    pub entries: Vec<String>,
}

/// A `modelIdentifier` from a file stem: letters, digits and `_`, starting with a letter.
#[must_use]
pub fn model_identifier(stem: &str) -> String {
    let mut id: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic()) {
        id.insert_str(0, "m_");
    }
    id
}

/// The data and table files the model text names (`[inputs].X.file`, `[tables].X.file`),
/// as written.
fn named_files(text: &str) -> Vec<String> {
    let Ok(doc) = toml::from_str::<toml::Table>(text) else {
        return Vec::new();
    };
    let mut files = Vec::new();
    for section in ["inputs", "tables"] {
        if let Some(t) = doc.get(section).and_then(toml::Value::as_table) {
            for entry in t.values() {
                if let Some(f) = entry.get("file").and_then(toml::Value::as_str) {
                    files.push(f.to_owned());
                }
            }
        }
    }
    files
}

/// `p` without `.` and with `..` applied (no file system access).
fn normal(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            c => out.push(c),
        }
    }
    out
}

/// Export `model` (with `--set` `overrides`) as an FMU of `version` to `out`, the engine
/// being the shared library at `library`.
///
/// # Errors
/// The model failing to load (file, line, hint), a named file missing or absolute, the
/// library or the output not readable / writable.
pub fn export(
    model: &Path,
    overrides: &[String],
    version: FmiVersion,
    library: &Path,
    out: &Path,
) -> Result<Exported, ExportError> {
    let file = model.display().to_string();
    let text = std::fs::read_to_string(model)
        .map_err(|e| ExportError::File(format!("{file}: cannot read the model: {e}")))?;
    let shipped = bg_model::overrides::apply(&file, &text, overrides)?;
    let loaded = Model::from_text(&file, &shipped, &registry(), &[])?;
    let stem = model
        .file_stem()
        .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
    let description = Description::of(&loaded, &shipped, &stem);
    let id = model_identifier(&stem);

    // the model and its files, relative to their deepest common folder
    let dir =
        normal(&std::path::absolute(model).map_err(|e| ExportError::File(format!("{file}: {e}")))?)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
    let mut files = Vec::new();
    for f in named_files(&shipped) {
        let p = Path::new(&f);
        if p.is_absolute() {
            return Err(ExportError::File(format!(
                "{file}: the model names the file `{f}` by an absolute path: the FMU cannot carry it\n  hint: write it relative to the model file"
            )));
        }
        files.push(normal(&dir.join(p)));
    }
    let mut root = dir.clone();
    while !files.iter().all(|f| f.starts_with(&root)) {
        if !root.pop() {
            break;
        }
    }
    let rel = |p: &Path| -> PathBuf { p.strip_prefix(&root).unwrap_or(p).to_path_buf() };
    let model_rel = rel(&dir.join(format!("{stem}.toml")));
    let model_rel = match model.file_name() {
        Some(n) => rel(&dir.join(n)),
        None => model_rel,
    };

    let lib = std::fs::read(library).map_err(|e| {
        ExportError::File(format!(
            "{}: cannot read the FMU library: {e}\n  hint: build it with `cargo build -p bg-fmu` (or name it with --library)",
            library.display()
        ))
    })?;
    let o = std::fs::File::create(out)
        .map_err(|e| ExportError::Output(format!("{}: cannot write: {e}", out.display())))?;
    let mut zip = zip::ZipWriter::new(o);
    let deflate = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .unix_permissions(0o644);
    let mut entries: Vec<String> = Vec::new();
    let mut write = |name: &str, bytes: &[u8], mode: u32| -> Result<(), ExportError> {
        let werr = |e: &dyn std::fmt::Display| {
            ExportError::Output(format!("{}: cannot write `{name}`: {e}", out.display()))
        };
        zip.start_file(name, deflate.unix_permissions(mode))
            .map_err(|e| werr(&e))?;
        zip.write_all(bytes).map_err(|e| werr(&e))
    };
    let mut add = |name: String, bytes: &[u8], mode: u32| -> Result<(), ExportError> {
        if entries.contains(&name) {
            return Ok(());
        }
        write(&name, bytes, mode)?;
        entries.push(name);
        Ok(())
    };
    let slash = |p: &Path| {
        p.components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/")
    };
    add(
        "modelDescription.xml".into(),
        description.xml(version, &id).as_bytes(),
        0o644,
    )?;
    add(
        format!("binaries/{}/{id}.so", version.platform()),
        &lib,
        0o755,
    )?;
    let manifest = format!(
        "# written by `bg-sim fmu`: the model this FMU runs, relative to resources/\nmodel = {}\n",
        toml::Value::String(slash(&model_rel))
    );
    add(format!("resources/{MANIFEST}"), manifest.as_bytes(), 0o644)?;
    add(
        format!("resources/{}", slash(&model_rel)),
        shipped.as_bytes(),
        0o644,
    )?;
    for f in &files {
        let bytes = std::fs::read(f).map_err(|e| {
            ExportError::File(format!(
                "{}: cannot read `{}`, named by the model: {e}",
                file,
                f.display()
            ))
        })?;
        add(format!("resources/{}", slash(&rel(f))), &bytes, 0o644)?;
    }
    zip.finish()
        .map_err(|e| ExportError::Output(format!("{}: cannot write: {e}", out.display())))?;
    Ok(Exported {
        description,
        model_identifier: id,
        entries,
    })
}
