//! Reports on stdout and stderr that never panic: [`say!`] and [`tell!`] stand in for
//! `println!` and `eprintln!`, and the first failure to write stdout is kept for `main`.

use std::io::Write;
use std::sync::Mutex;

/// The first error writing to stdout (a closed pipe, a full disk). The report is lost, not
/// the run: the CSV is still written and the checks still decide the exit status.
pub static STDOUT_ERROR: Mutex<Option<std::io::ErrorKind>> = Mutex::new(None);

/// Write one line to stdout (`to_stderr`: stderr) without ever panicking.
pub fn emit(to_stderr: bool, args: std::fmt::Arguments<'_>) {
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
