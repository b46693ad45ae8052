//! The FMI 3.0 co-simulation functions (`fmi3*`), written against the standard's
//! `fmi3Functions.h`, on the same [`Instance`] as FMI 2 (the names differ, so one library
//! exports both). Every function of the standard is exported (importers look them all up);
//! those of model exchange, scheduled execution, clocks and the integer, boolean, string and
//! binary types return `fmi3Error` (there are no such variables).
//!
//! C types: `fmi3Instance` = `void*` (a `Box<Instance>`), `fmi3Float64` = `double`,
//! `fmi3ValueReference` = `uint32_t`, `fmi3Boolean` = `bool` (read as a byte: any non-zero
//! is true), `fmi3Status` = `int` ([`Status`]).

use std::ffi::{c_char, c_int, c_void, CString};
use std::ptr;

use crate::ffi::{guard, instance, run, slice, slice_mut, text};
use crate::instance::{Failure, Instance, Log, Snapshot, Status};

/// `fmi3LogMessageCallback`.
pub type Fmi3LogMessage = unsafe extern "C" fn(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
);

fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// A [`Log`] calling the importer's `logMessage`.
fn logger(log: Option<Fmi3LogMessage>, env: *mut c_void) -> Log {
    Box::new(move |status: Status, category: &str, message: &str| {
        if let Some(log) = log {
            let (category, message) = (c_string(category), c_string(message));
            // SAFETY: the importer's callback, called as fmi3Functions.h declares it, with
            // NUL-terminated strings that live through the call.
            unsafe { log(env, status as c_int, category.as_ptr(), message.as_ptr()) };
        }
    })
}

/// `fmi3GetVersion`.
#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// `fmi3InstantiateCoSimulation`: load the model named by the manifest in `resourcePath`.
/// Null (the error logged: file, line, hint) if it does not load.
///
/// # Safety
/// Pointers as the FMI 3.0 standard defines them: strings NUL-terminated or null.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: u8,
    logging_on: u8,
    _event_mode_used: u8,
    _early_return_allowed: u8,
    _required_intermediate: *const u32,
    _n_required_intermediate: usize,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
    _intermediate_update: *const c_void,
) -> *mut c_void {
    guard(ptr::null_mut(), || {
        // SAFETY: NUL-terminated or null by the caller's contract.
        let (name, token, path) =
            unsafe { (text(instance_name), text(token), text(resource_path)) };
        let name = name.unwrap_or_else(|| "bg-fmu".into());
        let log = logger(log_message, instance_environment);
        let Some(path) = path else {
            log(
                Status::Error,
                "logStatusError",
                "no resourcePath: the model file is found in the FMU's resources/",
            );
            return ptr::null_mut();
        };
        match Instance::new(
            &name,
            &crate::ffi::resource_dir(&path),
            token.as_deref(),
            log,
            logging_on != 0,
        ) {
            Ok(i) => Box::into_raw(Box::new(i)).cast(),
            Err(_) => ptr::null_mut(),
        }
    })
}

/// `fmi3InstantiateModelExchange`: not offered (null, the reason logged).
///
/// # Safety
/// As [`fmi3InstantiateCoSimulation`].
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: u8,
    _logging_on: u8,
    instance_environment: *mut c_void,
    log_message: Option<Fmi3LogMessage>,
) -> *mut c_void {
    guard(ptr::null_mut(), || {
        logger(log_message, instance_environment)(
            Status::Error,
            "logStatusError",
            "this FMU offers co-simulation only (no model exchange)",
        );
        ptr::null_mut()
    })
}

/// `fmi3InstantiateScheduledExecution`: not offered (null).
#[no_mangle]
pub extern "C" fn fmi3InstantiateScheduledExecution() -> *mut c_void {
    ptr::null_mut()
}

/// `fmi3FreeInstance`.
///
/// # Safety
/// `c` null or from [`fmi3InstantiateCoSimulation`], not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        guard((), || {
            // SAFETY: made by `Box::into_raw` at instantiation, freed once.
            drop(unsafe { Box::from_raw(c.cast::<Instance>()) });
        });
    }
}

/// `fmi3SetDebugLogging`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    c: *mut c_void,
    logging_on: u8,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.set_logging(logging_on != 0);
        Ok(Status::Ok)
    })
}

/// `fmi3EnterInitializationMode`: the start time (the tolerance is the model's own).
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    c: *mut c_void,
    tolerance_defined: u8,
    tolerance: f64,
    start_time: f64,
    _stop_time_defined: u8,
    _stop_time: f64,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        if tolerance_defined != 0 {
            i.log(
                Status::Ok,
                &format!("tolerance {tolerance} ignored: the model's own [simulation] rtol/atol are used (change them with `bg-sim fmu --set`)"),
            );
        }
        i.setup_checked("fmi3EnterInitializationMode", start_time)?;
        i.enter_init("fmi3EnterInitializationMode")?;
        Ok(Status::Ok)
    })
}

/// `fmi3ExitInitializationMode`: the run starts.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.exit_init("fmi3ExitInitializationMode")
            .map(|()| Status::Ok)
    })
}

/// `fmi3EnterStepMode`: nothing to do (no event mode).
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |_| Ok(Status::Ok))
}

/// `fmi3Terminate`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        i.terminate("fmi3Terminate").map(|()| Status::Ok)
    })
}

/// `fmi3Reset`.
///
/// # Safety
/// `c` live.
#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(c: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| i.reset().map(|()| Status::Ok))
}

fn count(nvr: usize, n_values: usize) -> Result<(), Failure> {
    if nvr == n_values {
        Ok(())
    } else {
        Err(Failure {
            message: format!(
                "{nvr} value references but {n_values} values (all variables are scalars)"
            ),
            status: Status::Error,
        })
    }
}

/// `fmi3GetFloat64`.
///
/// # Safety
/// `c` live; `vr` an array of `nvr`, `values` of `n_values` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *mut f64,
    n_values: usize,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        count(nvr, n_values)?;
        // SAFETY: arrays of the lengths given (the caller's contract).
        let (vr, values) = unsafe { (slice(vr, nvr)?, slice_mut(values, n_values)?) };
        for (r, v) in vr.iter().zip(values.iter_mut()) {
            *v = i.get(*r)?;
        }
        Ok(Status::Ok)
    })
}

/// `fmi3SetFloat64`: inputs (any time) and parameters (before the run starts).
///
/// # Safety
/// `c` live; `vr` an array of `nvr`, `values` of `n_values` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *const f64,
    n_values: usize,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        count(nvr, n_values)?;
        // SAFETY: arrays of the lengths given (the caller's contract).
        let (vr, values) = unsafe { (slice(vr, nvr)?, slice(values, n_values)?) };
        for (r, v) in vr.iter().zip(values) {
            i.set(*r, *v)?;
        }
        Ok(Status::Ok)
    })
}

/// `fmi3DoStep`: integrate from `t` by `h` with the model's method and tolerances, the
/// solver's state kept from the last step.
///
/// # Safety
/// `c` live; the out-pointers null or writable.
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_set_fmu_state_prior: u8,
    event_handling_needed: *mut u8,
    terminate_simulation: *mut u8,
    early_return: *mut u8,
    last_successful_time: *mut f64,
) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        let r = i.do_step("fmi3DoStep", t, h);
        let now = i.t();
        for (p, v) in [
            (event_handling_needed, 0),
            (terminate_simulation, u8::from(r.is_err())),
            (early_return, 0),
        ] {
            if !p.is_null() {
                // SAFETY: non-null, writable (the caller's contract).
                unsafe { *p = v };
            }
        }
        if !last_successful_time.is_null() {
            // SAFETY: non-null, writable (the caller's contract).
            unsafe { *last_successful_time = now };
        }
        r.map(|()| Status::Ok)
    })
}

/// `fmi3GetFMUState`: a snapshot (time, state, inputs, parameters).
///
/// # Safety
/// `c` live; `state` points to an `fmi3FMUState` (null or from this function).
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        if state.is_null() {
            return Err(Failure {
                message: "fmi3GetFMUState: null state pointer".into(),
                status: Status::Error,
            });
        }
        let snap = Box::new(i.get_state());
        // SAFETY: non-null and writable, pointing to null or a `Box<Snapshot>` from an
        // earlier call (the caller's contract), which is replaced and freed once.
        unsafe {
            let old = std::mem::replace(&mut *state, Box::into_raw(snap).cast());
            if !old.is_null() {
                drop(Box::from_raw(old.cast::<Snapshot>()));
            }
        }
        Ok(Status::Ok)
    })
}

/// `fmi3SetFMUState`: back to a snapshot (the integrator starts afresh there).
///
/// # Safety
/// `c` live; `state` from [`fmi3GetFMUState`], not freed.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(c: *mut c_void, state: *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |i| {
        // SAFETY: null or a live `Box<Snapshot>` from fmi3GetFMUState (the caller's contract).
        let s = unsafe { state.cast::<Snapshot>().as_ref() }.ok_or_else(|| Failure {
            message: "fmi3SetFMUState: null state".into(),
            status: Status::Error,
        })?;
        i.set_state(s).map(|()| Status::Ok)
    })
}

/// `fmi3FreeFMUState`.
///
/// # Safety
/// `c` live; `state` points to null or a snapshot from [`fmi3GetFMUState`].
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    // SAFETY: `c` is null or live (the caller's contract).
    run(unsafe { instance(c) }, |_| {
        if state.is_null() {
            return Ok(Status::Ok);
        }
        // SAFETY: non-null, pointing to null or a `Box<Snapshot>` made by fmi3GetFMUState
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

/// The functions this FMU does not support. Each takes the instance first; the rest of its
/// arguments (as `fmi3Functions.h` declares them) are not read, which the C calling
/// convention allows (the caller owns its arguments), so only the instance is declared.
macro_rules! not_supported {
    ($($name:ident,)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: not supported here (returns `fmi3Error`).")]
        ///
        /// # Safety
        /// `c` live.
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut c_void) -> c_int {
            // SAFETY: `c` is null or live (caller's contract); nothing else is read.
            run(unsafe { instance(c) }, |_| {
                Err(Failure {
                    message: concat!(stringify!($name), " is not supported: this FMU is co-simulation with Float64 variables only").into(),
                    status: Status::Error,
                })
            })
        }
    )*};
}

not_supported! {
    fmi3EnterEventMode,
    fmi3GetFloat32, fmi3GetInt8, fmi3GetUInt8, fmi3GetInt16, fmi3GetUInt16, fmi3GetInt32,
    fmi3GetUInt32, fmi3GetInt64, fmi3GetUInt64, fmi3GetBoolean, fmi3GetString, fmi3GetBinary,
    fmi3GetClock,
    fmi3SetFloat32, fmi3SetInt8, fmi3SetUInt8, fmi3SetInt16, fmi3SetUInt16, fmi3SetInt32,
    fmi3SetUInt32, fmi3SetInt64, fmi3SetUInt64, fmi3SetBoolean, fmi3SetString, fmi3SetBinary,
    fmi3SetClock,
    fmi3GetNumberOfVariableDependencies, fmi3GetVariableDependencies,
    fmi3SerializedFMUStateSize, fmi3SerializeFMUState, fmi3DeserializeFMUState,
    fmi3GetDirectionalDerivative, fmi3GetAdjointDerivative,
    fmi3EnterConfigurationMode, fmi3ExitConfigurationMode,
    fmi3GetIntervalDecimal, fmi3GetIntervalFraction, fmi3GetShiftDecimal, fmi3GetShiftFraction,
    fmi3SetIntervalDecimal, fmi3SetIntervalFraction, fmi3SetShiftDecimal, fmi3SetShiftFraction,
    fmi3EvaluateDiscreteStates, fmi3UpdateDiscreteStates,
    fmi3EnterContinuousTimeMode, fmi3CompletedIntegratorStep, fmi3SetTime,
    fmi3SetContinuousStates, fmi3GetContinuousStateDerivatives, fmi3GetEventIndicators,
    fmi3GetContinuousStates, fmi3GetNominalsOfContinuousStates,
    fmi3GetNumberOfEventIndicators, fmi3GetNumberOfContinuousStates,
    fmi3GetOutputDerivatives, fmi3ActivateModelPartition,
}
