//! The FMI 2.0 co-simulation functions (`fmi2*`), written against the standard's
//! `fmi2Functions.h`: each checks its pointers, then calls [`Instance`] inside
//! [`run`](crate::ffi::run) (errors logged through the importer's `logger`, panics caught).
//! Model exchange is not offered (`fmi2Instantiate` refuses `fmi2ModelExchange`).
//!
//! C types: `fmi2Component` = `void*` (a `Box<Instance>`), `fmi2Real` = `double`,
//! `fmi2Integer` = `fmi2Boolean` = `int`, `fmi2ValueReference` = `unsigned int`,
//! `fmi2Status` = `int` ([`Status`]).

use std::ffi::{c_char, c_int, c_uint, c_void, CString};
use std::ptr;

use crate::ffi::{guard, instance, resource_dir, run, slice, slice_mut, text};
use crate::instance::{Failure, Instance, Log, Snapshot, Status};

/// `fmi2CallbackLogger`: the message is a printf format (variadic). It is passed with `%`
/// doubled and no arguments, so importers that format it and importers that print it as
/// it is (FMPy) both show the text.
pub type Fmi2Logger = unsafe extern "C" fn(
    env: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Fmi2CallbackFunctions {
    /// The logger (may be null: then nothing is logged).
    pub logger: Option<Fmi2Logger>,
    /// `calloc`-like (not used: Rust allocates).
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// `free`-like (not used).
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// For asynchronous steps (not used: steps are synchronous).
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    /// Passed back to the logger.
    pub component_environment: *mut c_void,
}

const FMI2_COSIMULATION: c_int = 1;
const FMI2_TRUE: c_int = 1;

fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// A [`Log`] calling the importer's logger.
fn logger(functions: Fmi2CallbackFunctions, name: &str) -> Log {
    let name = c_string(name);
    Box::new(move |status: Status, category: &str, message: &str| {
        if let Some(log) = functions.logger {
            let (category, message) = (c_string(category), c_string(&message.replace('%', "%%")));
            // SAFETY: the importer's logger, called as fmi2Functions.h declares it, with
            // NUL-terminated strings that live through the call and a format without
            // conversions (every `%` doubled), so no variadic argument is read.
            unsafe {
                log(
                    functions.component_environment,
                    name.as_ptr(),
                    status as c_int,
                    category.as_ptr(),
                    message.as_ptr(),
                );
            }
        }
    })
}

/// `fmi2GetTypesPlatform`.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: load the model named by the manifest in `fmuResourceLocation`. Null
/// (with the error logged: file, line, hint) if it does not load.
///
/// # Safety
/// Pointers as the FMI 2.0 standard defines them: strings NUL-terminated or null,
/// `functions` null or a valid `fmi2CallbackFunctions`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const Fmi2CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    guard(ptr::null_mut(), || {
        // SAFETY: null or a valid struct by the caller's contract; copied out at once.
        let functions = unsafe { functions.as_ref() }
            .copied()
            .unwrap_or(Fmi2CallbackFunctions {
                logger: None,
                allocate_memory: None,
                free_memory: None,
                step_finished: None,
                component_environment: ptr::null_mut(),
            });
        // SAFETY: NUL-terminated or null by the caller's contract.
        let (name, guid, location) =
            unsafe { (text(instance_name), text(guid), text(resource_location)) };
        let name = name.unwrap_or_else(|| "bg-fmu".into());
        let log = logger(functions, &name);
        if fmu_type != FMI2_COSIMULATION {
            log(
                Status::Error,
                "logStatusError",
                "this FMU offers co-simulation only (fmuType must be fmi2CoSimulation)",
            );
            return ptr::null_mut();
        }
        let Some(location) = location else {
            log(
                Status::Error,
                "logStatusError",
                "no fmuResourceLocation: the model file is found in the FMU's resources/",
            );
            return ptr::null_mut();
        };
        match Instance::new(
            &name,
            &resource_dir(&location),
            guid.as_deref(),
            log,
            logging_on == FMI2_TRUE,
        ) {
            Ok(i) => Box::into_raw(Box::new(i)).cast(),
            Err(_) => ptr::null_mut(),
        }
    })
}

/// `fmi2FreeInstance`.
///
/// # Safety
/// `c` null or from [`fmi2Instantiate`], not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        guard((), || {
            // SAFETY: made by `Box::into_raw` in fmi2Instantiate, freed once (caller's
            // contract).
            drop(unsafe { Box::from_raw(c.cast::<Instance>()) });
        });
    }
}

/// `fmi2SetDebugLogging`: on or off for everything but errors (categories ignored).
///
/// # Safety
/// As [`fmi2FreeInstance`]'s `c`, live.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.set_logging(logging_on == FMI2_TRUE);
        Ok(Status::Ok)
    })
}

/// `fmi2SetupExperiment`: the start time (the tolerance is the model's own; a stop time
/// is not needed).
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    tolerance_defined: c_int,
    tolerance: f64,
    start_time: f64,
    _stop_time_defined: c_int,
    _stop_time: f64,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        if tolerance_defined == FMI2_TRUE {
            i.log(
                Status::Ok,
                &format!("tolerance {tolerance} ignored: the model's own [simulation] rtol/atol are used (change them with `bg-sim fmu --set`)"),
            );
        }
        i.setup_checked("fmi2SetupExperiment", start_time)?;
        Ok(Status::Ok)
    })
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.enter_init("fmi2EnterInitializationMode")
            .map(|()| Status::Ok)
    })
}

/// `fmi2ExitInitializationMode`: the run starts.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.exit_init("fmi2ExitInitializationMode")
            .map(|()| Status::Ok)
    })
}

/// `fmi2Terminate`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.terminate("fmi2Terminate").map(|()| Status::Ok)
    })
}

/// `fmi2Reset`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| i.reset().map(|()| Status::Ok))
}

/// `fmi2GetReal`.
///
/// # Safety
/// `c` live; `vr` and `value` arrays of `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *mut f64,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        // SAFETY: arrays of the lengths given (the caller's contract).
        let (vr, value) = unsafe { (slice(vr, nvr)?, slice_mut(value, nvr)?) };
        for (r, v) in vr.iter().zip(value.iter_mut()) {
            *v = i.get(*r)?;
        }
        Ok(Status::Ok)
    })
}

/// `fmi2SetReal`: inputs (any time) and parameters (before the run starts).
///
/// # Safety
/// `c` live; `vr` and `value` arrays of `nvr` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *const f64,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        // SAFETY: arrays of the lengths given (the caller's contract).
        let (vr, value) = unsafe { (slice(vr, nvr)?, slice(value, nvr)?) };
        for (r, v) in vr.iter().zip(value) {
            i.set(*r, *v)?;
        }
        Ok(Status::Ok)
    })
}

fn none_of(kind: &str, nvr: usize) -> Result<Status, Failure> {
    if nvr == 0 {
        Ok(Status::Ok)
    } else {
        Err(Failure {
            message: format!("this FMU has no {kind} variables (all are Real)"),
            status: Status::Error,
        })
    }
}

macro_rules! no_variables {
    ($($name:ident($t:ty, $kind:literal);)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: the FMU has no ", $kind, " variables.")]
        ///
        /// # Safety
        /// `c` live.
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut c_void, _vr: *const c_uint, nvr: usize, _value: $t) -> c_int {
            // SAFETY: `c` is null or live (the caller's contract).
            run(unsafe { instance(c) }, |_| none_of($kind, nvr))
        }
    )*};
}

no_variables! {
    fmi2GetInteger(*mut c_int, "Integer");
    fmi2GetBoolean(*mut c_int, "Boolean");
    fmi2GetString(*mut *const c_char, "String");
    fmi2SetInteger(*const c_int, "Integer");
    fmi2SetBoolean(*const c_int, "Boolean");
    fmi2SetString(*const *const c_char, "String");
}

/// `fmi2GetFMUstate`: a snapshot (time, state, inputs, parameters).
///
/// # Safety
/// `c` live; `state` points to an `fmi2FMUstate` (null or from this function).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        if state.is_null() {
            return Err(Failure {
                message: "fmi2GetFMUstate: null state pointer".into(),
                status: Status::Error,
            });
        }
        let snap = Box::new(i.get_state());
        // SAFETY: non-null; a non-null old value came from this function.
        let old = unsafe { *state };
        if !old.is_null() {
            // SAFETY: a `Box<Snapshot>` from an earlier call, replaced here.
            drop(unsafe { Box::from_raw(old.cast::<Snapshot>()) });
        }
        // SAFETY: non-null, writable.
        unsafe { *state = Box::into_raw(snap).cast() };
        Ok(Status::Ok)
    })
}

/// `fmi2SetFMUstate`: back to a snapshot (the integrator starts afresh there).
///
/// # Safety
/// `c` live; `state` from [`fmi2GetFMUstate`], not freed.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        // SAFETY: null or a live `Box<Snapshot>` from GetFMUstate (the caller's contract).
        let s = unsafe { state.cast::<Snapshot>().as_ref() }.ok_or_else(|| Failure {
            message: "fmi2SetFMUstate: null state".into(),
            status: Status::Error,
        })?;
        i.set_state(s).map(|()| Status::Ok)
    })
}

/// `fmi2FreeFMUstate`.
///
/// # Safety
/// `c` live; `state` points to null or a snapshot from [`fmi2GetFMUstate`].
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |_| {
        if state.is_null() {
            return Ok(Status::Ok);
        }
        // SAFETY: non-null, pointing to null or a `Box<Snapshot>` made by fmi2GetFMUstate
        // (the caller's contract), freed once: the pointer is cleared.
        unsafe {
            let old = std::mem::replace(&mut *state, ptr::null_mut());
            if !old.is_null() {
                drop(Box::from_raw(old.cast::<Snapshot>()));
            }
        }
        Ok(Status::Ok)
    })
}

fn unsupported(what: &str) -> Result<Status, Failure> {
    Err(Failure {
        message: format!("{what} is not supported by this FMU"),
        status: Status::Error,
    })
}

macro_rules! not_supported {
    ($($name:ident($($arg:ident: $t:ty),*);)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: not supported (returns `fmi2Error`).")]
        ///
        /// # Safety
        /// `c` live.
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut c_void, $($arg: $t),*) -> c_int {
            $(let _ = $arg;)*
            // SAFETY: `c` is null or live (the caller's contract).
            run(unsafe { instance(c) }, |_| unsupported(stringify!($name)))
        }
    )*};
}

not_supported! {
    fmi2SerializedFMUstateSize(state: *mut c_void, size: *mut usize);
    fmi2SerializeFMUstate(state: *mut c_void, bytes: *mut c_char, size: usize);
    fmi2DeSerializeFMUstate(bytes: *const c_char, size: usize, state: *mut *mut c_void);
    fmi2GetDirectionalDerivative(u: *const c_uint, nu: usize, z: *const c_uint, nz: usize, du: *const f64, dz: *mut f64);
    fmi2SetRealInputDerivatives(vr: *const c_uint, nvr: usize, order: *const c_int, value: *const f64);
    fmi2GetRealOutputDerivatives(vr: *const c_uint, nvr: usize, order: *const c_int, value: *mut f64);
    fmi2CancelStep();
    fmi2GetStatus(kind: c_int, value: *mut c_int);
    fmi2GetRealStatus(kind: c_int, value: *mut f64);
    fmi2GetIntegerStatus(kind: c_int, value: *mut c_int);
    fmi2GetBooleanStatus(kind: c_int, value: *mut c_int);
    fmi2GetStringStatus(kind: c_int, value: *mut *const c_char);
}

/// `fmi2DoStep`: integrate from `t` by `h` with the model's method and tolerances, the
/// solver's state kept from the last step.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_set_fmu_state_prior: c_int,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.do_step("fmi2DoStep", t, h).map(|()| Status::Ok)
    })
}
