//! What the FMI 2 and FMI 3 entry points share: the guard every entry point runs its body
//! in (no panic crosses the C boundary: it becomes a logged `Fatal`), slices and strings
//! from the importer's pointers, and resource locations.

use std::ffi::{c_char, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use crate::instance::{Failure, Instance, Status};

/// The message of a caught panic.
fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// The instance behind `c` (`None` for null).
///
/// # Safety
/// `c` is null or a pointer returned by this library's instantiate functions and not yet
/// freed, used by one thread at a time (the FMI standard's rule for importers), so the
/// borrow is the only one for the call.
pub unsafe fn instance<'a>(c: *mut c_void) -> Option<&'a mut Instance> {
    // SAFETY: null or a live `Box<Instance>` made by `into_raw` (caller's contract).
    unsafe { c.cast::<Instance>().as_mut() }
}

/// Run `f` on `inst`: its failure is logged and becomes its status, a panic is caught,
/// logged and becomes `Fatal`; no instance (a null pointer) is `Error`.
pub fn run(
    inst: Option<&mut Instance>,
    f: impl FnOnce(&mut Instance) -> Result<Status, Failure>,
) -> i32 {
    let Some(inst) = inst else {
        return Status::Error as i32;
    };
    match catch_unwind(AssertUnwindSafe(|| f(&mut *inst))) {
        Ok(Ok(s)) => s as i32,
        Ok(Err(e)) => inst.report(&e) as i32,
        Err(p) => {
            let m = format!(
                "internal error in bg-fmu (a panic, caught at the FMI boundary): {}\n  hint: please report it with the model file",
                panic_message(p.as_ref())
            );
            // the logger itself may be what panicked: guard it too
            let _ = catch_unwind(AssertUnwindSafe(|| inst.log(Status::Fatal, &m)));
            Status::Fatal as i32
        }
    }
}

/// Run `f` with nothing to log to: a panic becomes `fallback`.
pub fn guard<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// The slice behind (`p`, `n`); empty for `n == 0`.
///
/// # Safety
/// If `n > 0`, `p` points to `n` valid, initialised elements that outlive the call.
pub unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], Failure> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure {
            message: "a null array with a non-zero length".into(),
            status: Status::Error,
        });
    }
    // SAFETY: non-null, `n` elements by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// The mutable slice behind (`p`, `n`); empty for `n == 0`.
///
/// # Safety
/// If `n > 0`, `p` points to `n` writable elements not otherwise borrowed during the call.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], Failure> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(Failure {
            message: "a null array with a non-zero length".into(),
            status: Status::Error,
        });
    }
    // SAFETY: non-null, `n` writable elements by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The text of a C string; `None` for null.
///
/// # Safety
/// `s` is null or a NUL-terminated string valid for the call.
pub unsafe fn text(s: *const c_char) -> Option<String> {
    if s.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
}

/// The folder of a resource location: an FMI 2 URI (`file:///tmp/x/resources`,
/// `file:/tmp/x/resources`, `file://localhost/…`, percent-escapes decoded) or an FMI 3
/// path.
#[must_use]
pub fn resource_dir(location: &str) -> PathBuf {
    let path = if let Some(rest) = location.strip_prefix("file://") {
        rest.strip_prefix("localhost").unwrap_or(rest)
    } else if let Some(rest) = location.strip_prefix("file:") {
        rest
    } else {
        return PathBuf::from(location);
    };
    let bytes = path.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push(u8::try_from(h * 16 + l).unwrap_or(b'?'));
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    PathBuf::from(String::from_utf8_lossy(&out).into_owned())
}

#[cfg(test)]
mod tests {
    use super::resource_dir;
    use std::path::Path;

    #[test]
    fn resource_locations() {
        assert_eq!(
            resource_dir("file:///tmp/a%20b/resources"),
            Path::new("/tmp/a b/resources")
        );
        assert_eq!(resource_dir("file:/tmp/x/"), Path::new("/tmp/x/"));
        assert_eq!(resource_dir("file://localhost/tmp/x"), Path::new("/tmp/x"));
        assert_eq!(
            resource_dir("/tmp/y/resources/"),
            Path::new("/tmp/y/resources/")
        );
        assert_eq!(resource_dir("file:///tmp/100%"), Path::new("/tmp/100%"));
    }
}
