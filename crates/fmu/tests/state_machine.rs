//! The FMI state machines (FMI 2.0 and 3.0 co-simulation, issue 37 item 8): a call out of
//! turn — a step before initialisation or after terminate, entering initialisation twice,
//! exiting without entering — is an error (fmi2Error / fmi3Error) with the reason logged,
//! and neither integrates nor changes the instance.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::cell::RefCell;
use std::ffi::{c_void, CString};
use std::path::{Path, PathBuf};
use std::ptr;
use std::rc::Rc;

use bg_fmu::fmi2::*;
use bg_fmu::fmi3::*;
use bg_fmu::{export, FmiVersion, Instance, Phase};

const ERROR: i32 = 3;
const X: u32 = 2;

struct Unpacked {
    _dir: tempfile::TempDir,
    resources: PathBuf,
    token: String,
}

fn unpacked(version: FmiVersion) -> Unpacked {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/msd_force.toml");
    let dir = tempfile::tempdir().unwrap();
    let fmu = dir.path().join("m.fmu");
    let x = export(&model, &[], version, &model, &fmu).unwrap();
    let mut z = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    z.extract(dir.path().join("unzipped")).unwrap();
    Unpacked {
        resources: dir.path().join("unzipped/resources"),
        token: x.description.token,
        _dir: dir,
    }
}

/// An instance through the safe layer, with its log.
fn instance(u: &Unpacked) -> (Instance, Rc<RefCell<Vec<String>>>) {
    let seen = Rc::new(RefCell::new(Vec::new()));
    let s2 = Rc::clone(&seen);
    let i = Instance::new(
        "sm",
        &u.resources,
        Some(&u.token),
        Box::new(move |_, _, m| s2.borrow_mut().push(m.to_owned())),
        false,
    )
    .unwrap();
    (i, seen)
}

#[test]
fn calls_out_of_turn_are_errors_with_a_reason() {
    let u = unpacked(FmiVersion::V2);
    let (mut i, log) = instance(&u);
    assert_eq!(i.phase(), Phase::Instantiated);
    // a step before initialisation: refused, time does not move
    let e = i.do_step("fmi2DoStep", 0.0, 0.1).unwrap_err();
    assert_eq!(i.report(&e), bg_fmu::Status::Error);
    assert!(
        e.message.contains("fmi2DoStep") && e.message.contains("out of turn"),
        "{}",
        e.message
    );
    assert!(
        e.message.contains("enter initialisation mode first"),
        "{}",
        e.message
    );
    assert!(log.borrow().iter().any(|m| m.contains("out of turn")));
    assert!(i.t().abs() < 1e-15);
    // exit without enter
    let e = i.exit_init("fmi2ExitInitializationMode").unwrap_err();
    assert!(e.message.contains("just instantiated"), "{}", e.message);
    // enter, enter again
    i.setup_checked("fmi2SetupExperiment", 0.0).unwrap();
    i.enter_init("fmi2EnterInitializationMode").unwrap();
    let e = i.enter_init("fmi2EnterInitializationMode").unwrap_err();
    assert!(
        e.message.contains("in initialisation mode"),
        "{}",
        e.message
    );
    // a step inside initialisation, a setup after entering
    assert!(i.do_step("fmi2DoStep", 0.0, 0.1).is_err());
    assert!(i.setup_checked("fmi2SetupExperiment", 0.0).is_err());
    i.exit_init("fmi2ExitInitializationMode").unwrap();
    assert_eq!(i.phase(), Phase::Stepping);
    i.do_step("fmi2DoStep", 0.0, 0.1).unwrap();
    assert!((i.t() - 0.1).abs() < 1e-12);
    // enter again while stepping, then terminate; a step after terminate, terminate twice
    assert!(i.enter_init("fmi2EnterInitializationMode").is_err());
    i.terminate("fmi2Terminate").unwrap();
    let e = i.do_step("fmi2DoStep", 0.1, 0.1).unwrap_err();
    assert!(e.message.contains("terminated"), "{}", e.message);
    assert!((i.t() - 0.1).abs() < 1e-12);
    assert!(i.terminate("fmi2Terminate").is_err());
    // reset: back to the start of the machine
    i.reset().unwrap();
    assert_eq!(i.phase(), Phase::Instantiated);
    i.enter_init("fmi2EnterInitializationMode").unwrap();
    i.exit_init("fmi2ExitInitializationMode").unwrap();
    i.do_step("fmi2DoStep", 0.0, 0.1).unwrap();
}

#[test]
fn fmi2_entry_points_return_fmi2_error_out_of_turn() {
    let u = unpacked(FmiVersion::V2);
    let name = CString::new("c2").unwrap();
    let token = CString::new(u.token.clone()).unwrap();
    let uri = CString::new(format!("file://{}", u.resources.display())).unwrap();
    let cb = Fmi2CallbackFunctions {
        logger: None,
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: ptr::null_mut(),
    };
    // SAFETY: valid C strings and callbacks, alive through the calls; the instance is
    // freed once at the end.
    unsafe {
        let c: *mut c_void =
            fmi2Instantiate(name.as_ptr(), 1, token.as_ptr(), uri.as_ptr(), &cb, 0, 0);
        assert!(!c.is_null());
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), ERROR);
        assert_eq!(fmi2ExitInitializationMode(c), ERROR);
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2EnterInitializationMode(c), 0);
        assert_eq!(fmi2EnterInitializationMode(c), ERROR);
        assert_eq!(fmi2ExitInitializationMode(c), 0);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 1), 0);
        assert_eq!(fmi2Terminate(c), 0);
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 1), ERROR);
        let mut x = f64::NAN;
        assert_eq!(fmi2GetReal(c, &X, 1, &mut x), 0);
        assert!(x.is_finite());
        fmi2FreeInstance(c);
    }
}

#[test]
fn fmi3_entry_points_return_fmi3_error_out_of_turn() {
    let u = unpacked(FmiVersion::V3);
    let name = CString::new("c3").unwrap();
    let token = CString::new(u.token.clone()).unwrap();
    let res = CString::new(format!("{}/", u.resources.display())).unwrap();
    let (mut event, mut term, mut early, mut last) = (0_u8, 0_u8, 0_u8, 0.0);
    // SAFETY: valid strings; no logger; out-pointers writable; the instance freed once.
    unsafe {
        let c = fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            res.as_ptr(),
            0,
            0,
            0,
            0,
            ptr::null(),
            0,
            ptr::null_mut(),
            None,
            ptr::null(),
        );
        assert!(!c.is_null());
        let mut step = |c: *mut c_void, t: f64| {
            fmi3DoStep(c, t, 0.1, 1, &mut event, &mut term, &mut early, &mut last)
        };
        assert_eq!(step(c, 0.0), ERROR);
        assert_eq!(fmi3ExitInitializationMode(c), ERROR);
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), ERROR);
        assert_eq!(fmi3ExitInitializationMode(c), 0);
        assert_eq!(step(c, 0.0), 0);
        assert_eq!(fmi3Terminate(c), 0);
        assert_eq!(step(c, 0.1), ERROR);
        fmi3FreeInstance(c);
    }
}
