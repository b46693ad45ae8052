//! The results file of `bg-sim run`: rows go to `OUT.partial.csv` as they are computed and
//! become `OUT.csv` in one rename when the run is complete; destinations that would destroy
//! something (the model file, a link, a device) are refused before any work.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use bg_model::Model;
use bondgraph::RowSink;

/// `OUT.partial.csv` beside `OUT.csv`: where the rows go until the run is complete.
pub fn partial_path(p: &Path) -> PathBuf {
    let stem = p
        .file_stem()
        .map_or_else(|| "results".into(), |s| s.to_string_lossy().into_owned());
    p.with_file_name(format!("{stem}.partial.csv"))
}

/// Refuse to write over `p` unless it is absent or a regular file other than the model:
/// `-o model.toml`, a symbolic link, a FIFO, a directory or a device are refused.
fn check_destination(p: &Path, model: &Path) -> Result<(), String> {
    if let Ok(m) = std::fs::symlink_metadata(p) {
        let t = m.file_type();
        let what = if t.is_symlink() {
            Some("a symbolic link")
        } else if t.is_dir() {
            Some("a directory")
        } else if !t.is_file() {
            Some("not a regular file (a FIFO, socket or device)")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(format!(
                "{} is {what}: bg-sim writes results only to regular files\n  hint: name a new or regular file with -o",
                p.display()
            ));
        }
    }
    if same_file(p, model) {
        return Err(format!(
            "{} is the model file: writing the results there would destroy it\n  hint: name another file with -o",
            p.display()
        ));
    }
    Ok(())
}

/// Whether two paths name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        x.dev() == y.dev() && x.ino() == y.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (x, y);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(p), Ok(q)) if p == q)
    }
}

/// Check both destinations, create `OUT.partial.csv` with the header, and remove an `OUT.csv`
/// of an earlier run (so that `OUT.csv` and `OUT.partial.csv` never both exist after a run).
pub fn open_output(
    out: &Path,
    partial: &Path,
    model_path: &Path,
    model: &Model,
) -> Result<CsvSink, String> {
    check_destination(out, model_path)?;
    check_destination(partial, model_path)?;
    let columns: Vec<&str> = std::iter::once("t")
        .chain(model.outputs.iter().map(|o| o.name.as_str()))
        .collect();
    let cannot = |p: &Path, e: std::io::Error| format!("cannot write {}: {e}", p.display());
    if let Some(dir) = partial.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| cannot(dir, e))?;
    }
    let sink = CsvSink::create(partial, &columns).map_err(|e| cannot(partial, e))?;
    match std::fs::remove_file(out) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            let _ = std::fs::remove_file(partial);
            Err(format!("cannot replace {}: {e}", out.display()))
        }
        _ => Ok(sink),
    }
}

/// A CSV field: quoted (RFC 4180) if it holds a comma, a quote or a line break. The loader
/// allows only plain column names; this keeps any other name from breaking the header.
fn csv_field(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) || s.is_empty() {
        format!("\"{}\"", s.replace('"', "\"\"")).into()
    } else {
        s.into()
    }
}

/// Rows streamed to `OUT.partial.csv` as they are computed, in whole lines: rows are
/// formatted into a buffer of complete lines and written 64 kB at a time. If a write fails
/// (a full disk), the file is cut back to its last complete row and as many of the buffered
/// rows as still fit are written one by one.
pub struct CsvSink {
    file: File,
    buf: Vec<u8>,
    /// Time of each buffered row.
    buffered: Vec<f64>,
    /// Bytes of complete lines in the file.
    committed: u64,
    /// Rows in the file.
    pub rows: usize,
    /// Time of the last row in the file.
    pub last_t: Option<f64>,
}

impl CsvSink {
    fn create(path: &Path, columns: &[&str]) -> std::io::Result<Self> {
        let file = File::create(path)?;
        let mut sink = Self {
            file,
            buf: Vec::with_capacity(1 << 17),
            buffered: Vec::new(),
            committed: 0,
            rows: 0,
            last_t: None,
        };
        let header: Vec<_> = columns.iter().map(|c| csv_field(c)).collect();
        writeln!(sink.buf, "{}", header.join(","))?;
        sink.flush()?;
        Ok(sink)
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        use std::io::{Seek, SeekFrom};
        if self.buf.is_empty() {
            return Ok(());
        }
        let buf = std::mem::take(&mut self.buf);
        let times = std::mem::take(&mut self.buffered);
        let r = self.file.write_all(&buf);
        match r {
            Ok(()) => {
                self.committed += buf.len() as u64;
                self.rows += times.len();
                self.last_t = times.last().copied().or(self.last_t);
            }
            Err(ref _e) => {
                // lines before the rows: the header, in the first flush (counted only here:
                // a byte scan of every flush was 5 instructions a byte of the file)
                let lines = buf.iter().filter(|b| **b == b'\n').count();
                let header = lines.saturating_sub(times.len());
                let mut t = times.iter().copied();
                // keep whole rows only, then as many of the buffered ones as fit
                let _ = self.file.set_len(self.committed);
                let _ = self.file.seek(SeekFrom::Start(self.committed));
                for (k, line) in buf.split_inclusive(|b| *b == b'\n').enumerate() {
                    if self.file.write_all(line).is_err() {
                        let _ = self.file.set_len(self.committed);
                        break;
                    }
                    self.committed += line.len() as u64;
                    if k >= header {
                        self.rows += 1;
                        self.last_t = t.next().or(self.last_t);
                    }
                }
            }
        }
        self.buf = buf;
        self.buf.clear();
        self.buffered = times;
        self.buffered.clear();
        r
    }
}

impl RowSink for CsvSink {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        let mut first = true;
        for v in row {
            if !first {
                self.buf.push(b',');
            }
            first = false;
            // as `{v}` writes it, faster (number.rs)
            super::number::push_f64(&mut self.buf, *v);
        }
        self.buf.push(b'\n');
        self.buffered.push(row.first().copied().unwrap_or(f64::NAN));
        if self.buf.len() >= 1 << 16 {
            self.flush().map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}
