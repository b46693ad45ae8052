//! Reports on stdout and stderr that never panic: [`say!`] and [`tell!`] stand in for
//! `println!` and `eprintln!`, and the first failure to write stdout is kept for `main`.
//! With `--format json` stdout holds one JSON document ([`document`]) and `say!` goes to
//! stderr ([`keep_stdout_for_document`]).

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The first error writing to stdout (a closed pipe, a full disk). The report is lost, not
/// the run: the CSV is still written and the checks still decide the exit status.
pub static STDOUT_ERROR: Mutex<Option<std::io::ErrorKind>> = Mutex::new(None);

/// Set when stdout is kept for one machine-readable document.
static SAY_ON_STDERR: AtomicBool = AtomicBool::new(false);

/// From now on `say!` writes to stderr: stdout is kept for the one document of
/// `--format json`, written by [`document`].
pub fn keep_stdout_for_document() {
    SAY_ON_STDERR.store(true, Ordering::Relaxed);
}

/// Write a JSON document to stdout (pretty-printed, one trailing line break).
pub fn document(v: &serde_json::Value) {
    write_line(false, format_args!("{v:#}"));
}

/// Write one line of a report: `say!` (`to_stderr` false) to stdout, unless stdout is kept
/// for a document, `tell!` to stderr.
pub fn emit(to_stderr: bool, args: std::fmt::Arguments<'_>) {
    write_line(to_stderr || SAY_ON_STDERR.load(Ordering::Relaxed), args);
}

/// Write one line to stdout (`to_stderr`: stderr) without ever panicking.
fn write_line(to_stderr: bool, args: std::fmt::Arguments<'_>) {
    let written = if to_stderr {
        let mut e = std::io::stderr().lock();
        e.write_fmt(args).and_then(|()| e.write_all(b"\n"))
    } else {
        let mut o = std::io::stdout().lock();
        o.write_fmt(args).and_then(|()| o.write_all(b"\n"))
    };
    if let (Err(e), false) = (written, to_stderr) {
        if let Ok(mut first) = STDOUT_ERROR.lock() {
            first.get_or_insert(e.kind());
        }
    }
}

/// `println!` that never panics.
macro_rules! say {
    ($($arg:tt)*) => { $crate::report::emit(false, format_args!($($arg)*)) };
}

/// `eprintln!` that never panics.
macro_rules! tell {
    ($($arg:tt)*) => { $crate::report::emit(true, format_args!($($arg)*)) };
}
