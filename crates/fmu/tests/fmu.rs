//! The FMU without an importer: the description and the archive `bg-sim fmu` writes, and the
//! exported C functions called through the rlib as an importer would (instantiate, set an
//! input, step, read outputs, saved states, two instances, a broken model's error status
//! and logged message, a panic caught at the boundary). FMPy checks the same FMUs from
//! Python (crates/python/tests/test_fmu.py).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::cell::RefCell;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::ptr;
use std::rc::Rc;

use bg_fmu::description::Role;
use bg_fmu::fmi2::*;
use bg_fmu::fmi3::*;
use bg_fmu::{export, FmiVersion};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Export `model` (the engine: any file, not loaded here) and unpack it into `dir`.
fn unpacked(model: &Path, dir: &Path, version: FmiVersion) -> bg_fmu::Exported {
    let fmu = dir.join("m.fmu");
    let x = export(model, &[], version, model, &fmu).unwrap();
    let mut z = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    z.extract(dir.join("unzipped")).unwrap();
    x
}

fn msd() -> PathBuf {
    root().join("models/msd_force.toml")
}

#[test]
fn description_of_the_msd_model() {
    let text = std::fs::read_to_string(msd()).unwrap();
    let m = bg_model::Model::from_text("msd_force.toml", &text, &bg_fmu::instance::registry(), &[])
        .unwrap();
    let d = bg_fmu::Description::of(&m, &text, "msd_force");
    let names: Vec<(&str, &Role)> = d
        .variables
        .iter()
        .map(|v| (v.name.as_str(), &v.role))
        .collect();
    assert_eq!(
        names,
        [
            ("time", &Role::Time),
            ("F", &Role::Input(0)),
            // the output column `F` is the input itself: not a second variable
            ("x", &Role::Output(0)),
            ("v", &Role::Output(1)),
            ("m", &Role::Parameter("m".into())),
            ("k", &Role::Parameter("k".into())),
            ("c", &Role::Parameter("c".into())),
            ("F_step", &Role::Parameter("F_step".into())),
            ("F_model", &Role::Parameter("F_model".into())),
        ]
    );
    assert!(d
        .variables
        .iter()
        .enumerate()
        .all(|(i, v)| v.vr as usize == i));
    assert_eq!(d.variables[1].unit, "N");
    assert_eq!(d.variables[1].start, Some(0.0));
    assert_eq!(d.variables[5].start, Some(100.0));
    assert_eq!(
        (d.start_time, d.stop_time, d.step_size, d.tolerance),
        (0.0, 20.0, 0.01, 1e-10)
    );
    // the token is the text's: stable, and another text gets another
    assert_eq!(d.token, bg_fmu::description::token(&text));
    assert_ne!(
        d.token,
        bg_fmu::description::token(&text.replace("k = 100.0", "k = 100.5"))
    );
    assert_eq!(d.token.len(), 38);

    let x2 = d.xml(FmiVersion::V2, "msd_force");
    for s in [
        "fmiVersion=\"2.0\"",
        &format!("guid=\"{}\"", d.token),
        "<CoSimulation modelIdentifier=\"msd_force\"",
        "<Unit name=\"N\"/>",
        "<DefaultExperiment startTime=\"0.0\" stopTime=\"20.0\" stepSize=\"0.01\" tolerance=\"1e-10\"/>",
        "name=\"F\" valueReference=\"1\" description=\"external force on the mass\" causality=\"input\" variability=\"continuous\">\n      <Real unit=\"N\" start=\"0.0\"/>",
        "name=\"x\" valueReference=\"2\" causality=\"output\"",
        "name=\"k\" valueReference=\"5\" causality=\"parameter\" variability=\"fixed\" initial=\"exact\">\n      <Real start=\"100.0\"/>",
        "<Outputs>\n      <Unknown index=\"3\"/>\n      <Unknown index=\"4\"/>\n    </Outputs>",
    ] {
        assert!(x2.contains(s), "FMI 2 description lacks {s}:\n{x2}");
    }
    let x3 = d.xml(FmiVersion::V3, "msd_force");
    for s in [
        "fmiVersion=\"3.0\"",
        &format!("instantiationToken=\"{}\"", d.token),
        "<Float64 name=\"time\" valueReference=\"0\" description=\"simulation time\" causality=\"independent\" variability=\"continuous\" unit=\"s\"/>",
        "<Float64 name=\"F\" valueReference=\"1\" description=\"external force on the mass\" causality=\"input\" variability=\"continuous\" unit=\"N\" start=\"0.0\"/>",
        "<Output valueReference=\"2\"/>\n    <Output valueReference=\"3\"/>",
        "<InitialUnknown valueReference=\"2\"/>",
    ] {
        assert!(x3.contains(s), "FMI 3 description lacks {s}:\n{x3}");
    }
    // both parse as XML with one variable element per variable
    for (x, tag) in [(&x2, "ScalarVariable"), (&x3, "Float64")] {
        let doc = roxmltree::Document::parse(x).unwrap();
        let n = doc.descendants().filter(|n| n.has_tag_name(tag)).count();
        assert_eq!(n, d.variables.len());
    }
}

#[test]
fn archive_layout_with_a_data_file_outside_the_model_folder() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("project/models");
    let data = dir.path().join("project/data");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::create_dir_all(&data).unwrap();
    std::fs::copy(
        root().join("data/msd_force_step.csv"),
        data.join("step.csv"),
    )
    .unwrap();
    let text = std::fs::read_to_string(msd()).unwrap().replace(
        "F = { default = 0.0, unit = \"N\", description = \"external force on the mass\" }",
        "F = { file = \"../data/step.csv\", column = \"F\", interp = \"hold\", unit = \"N\" }",
    );
    assert!(text.contains("../data/step.csv"));
    let model = models.join("msd_data.toml");
    std::fs::write(&model, &text).unwrap();

    for version in [FmiVersion::V2, FmiVersion::V3] {
        let out = dir.path().join(format!("v{version:?}"));
        std::fs::create_dir_all(&out).unwrap();
        let x = unpacked(&model, &out, version);
        let lib = format!("binaries/{}/msd_data.so", version.platform());
        assert_eq!(
            x.entries,
            [
                "modelDescription.xml",
                lib.as_str(),
                "resources/bg-sim-fmu.toml",
                "resources/models/msd_data.toml",
                "resources/data/step.csv",
            ]
        );
        let u = out.join("unzipped");
        assert_eq!(
            std::fs::read_to_string(u.join("resources/models/msd_data.toml")).unwrap(),
            text
        );
        assert_eq!(
            bg_fmu::instance::model_file(&u.join("resources")).unwrap(),
            u.join("resources/models/msd_data.toml")
        );
        // the library is executable in the archive
        let mut z = zip::ZipArchive::new(std::fs::File::open(out.join("m.fmu")).unwrap()).unwrap();
        assert_eq!(
            z.by_name(&lib).unwrap().unix_mode().map(|m| m & 0o777),
            Some(0o755)
        );
        assert_eq!(
            z.by_name("modelDescription.xml").unwrap().compression(),
            zip::CompressionMethod::Deflated
        );
    }
}

#[test]
fn export_refuses_a_broken_model_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("broken.toml");
    let text = std::fs::read_to_string(msd())
        .unwrap()
        .replace("kind = \"C\", k = \"k\"", "kind = \"Cx\", k = \"k\"");
    std::fs::write(&model, text).unwrap();
    let e = export(
        &model,
        &[],
        FmiVersion::V2,
        &model,
        &dir.path().join("b.fmu"),
    )
    .unwrap_err();
    let bg_fmu::ExportError::Model(e) = e else {
        panic!("not a model error: {e}")
    };
    assert_eq!(e.line, Some(28));
    assert!(e.hint.is_some());
}

// ---- the C functions, called as an importer calls them ----

/// The messages an FMI 3 logger received: (status, message).
type Messages = RefCell<Vec<(c_int, String)>>;

unsafe extern "C" fn log3(
    env: *mut c_void,
    status: c_int,
    _cat: *const c_char,
    msg: *const c_char,
) {
    // SAFETY: `env` is the `Messages` the test passed as instanceEnvironment, alive for the
    // instance's life; `msg` a C string from the library.
    unsafe {
        let m = &*env.cast::<Messages>();
        m.borrow_mut()
            .push((status, CStr::from_ptr(msg).to_string_lossy().into_owned()));
    }
}

struct Fmu {
    _dir: tempfile::TempDir,
    resources: CString,
    uri: CString,
    token: CString,
}

fn fmu_of(model: &Path, version: FmiVersion) -> Fmu {
    let dir = tempfile::tempdir().unwrap();
    let x = unpacked(model, dir.path(), version);
    let res = dir.path().join("unzipped/resources");
    Fmu {
        resources: CString::new(format!("{}/", res.display())).unwrap(),
        uri: CString::new(format!("file://{}", res.display())).unwrap(),
        token: CString::new(x.description.token).unwrap(),
        _dir: dir,
    }
}

fn instantiate2(f: &Fmu, name: &str) -> *mut c_void {
    let name = CString::new(name).unwrap();
    let cb = Fmi2CallbackFunctions {
        logger: None,
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: ptr::null_mut(),
    };
    // SAFETY: valid C strings and callbacks, alive through the call.
    unsafe {
        fmi2Instantiate(
            name.as_ptr(),
            1,
            f.token.as_ptr(),
            f.uri.as_ptr(),
            &cb,
            0,
            0,
        )
    }
}

fn get2(c: *mut c_void, vr: u32) -> f64 {
    let mut v = f64::NAN;
    // SAFETY: a live instance; one value reference and one value.
    assert_eq!(unsafe { fmi2GetReal(c, &vr, 1, &mut v) }, 0);
    v
}

fn set2(c: *mut c_void, vr: u32, v: f64) -> c_int {
    // SAFETY: a live instance; one value reference and one value.
    unsafe { fmi2SetReal(c, &vr, 1, &v) }
}

fn step2(c: *mut c_void, t: f64, h: f64) -> c_int {
    // SAFETY: a live instance.
    unsafe { fmi2DoStep(c, t, h, 1) }
}

fn init2(c: *mut c_void) {
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2EnterInitializationMode(c), 0);
        assert_eq!(fmi2ExitInitializationMode(c), 0);
    }
}

/// x(t) of the mass–spring–damper (m = 1, k = 100, c = 2) from rest under a constant force
/// `f` from t = 0.
fn msd_x(f: f64, t: f64) -> f64 {
    let (wn, z) = (10.0_f64, 0.1_f64);
    let wd = wn * (1.0 - z * z).sqrt();
    f / 100.0
        * (1.0 - (-z * wn * t).exp() * ((wd * t).cos() + z / (1.0 - z * z).sqrt() * (wd * t).sin()))
}

// value references of msd_force: time 0, F 1, x 2, v 3, m 4, k 5, c 6, F_step 7
const F: u32 = 1;
const X: u32 = 2;
const K: u32 = 5;

#[test]
fn fmi2_step_with_an_input_matches_the_analytic_response() {
    let f = fmu_of(&msd(), FmiVersion::V2);
    let c = instantiate2(&f, "a");
    assert!(!c.is_null());
    init2(c);
    assert!(get2(c, X).abs() < 1e-300, "at rest at the start");
    assert_eq!(set2(c, F, 10.0), 0);
    let h = 0.01;
    let mut worst = 0.0_f64;
    for i in 0..300 {
        let t = f64::from(i) * h;
        assert_eq!(step2(c, t, h), 0);
        worst = worst.max((get2(c, X) - msd_x(10.0, t + h)).abs());
    }
    assert!((get2(c, 0) - 3.0).abs() < 1e-12);
    // rtol 1e-10 of the model: well within 1e-8 of the 0.1 m deflection
    assert!(worst < 1e-8, "worst |x − analytic| {worst:e}");
    // a step from another time is refused; the time is not an input
    assert_eq!(step2(c, 1.0, h), 3);
    assert_eq!(set2(c, 0, 1.0), 3);
    // a fixed parameter once the run started
    assert_eq!(set2(c, K, 200.0), 3);
    // SAFETY: a live instance, freed once.
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn fmi2_parameters_before_the_start_and_saved_states() {
    let f = fmu_of(&msd(), FmiVersion::V2);
    let c = instantiate2(&f, "p");
    // k = 400: ωn = 20 rad/s; F = 8 N: static deflection 0.02 m
    assert_eq!(set2(c, K, 400.0), 0);
    assert_eq!(set2(c, F, 8.0), 0);
    init2(c);
    let mut t = 0.0;
    while t < 30.0 - 1e-9 {
        assert_eq!(step2(c, t, 0.5), 0);
        t += 0.5;
    }
    assert!((get2(c, X) - 0.02).abs() < 1e-9, "x = {}", get2(c, X));
    assert!((get2(c, K) - 400.0).abs() < 1e-12);

    // a saved state: back to t = 30 after going on, and the same future again
    let mut s: *mut c_void = ptr::null_mut();
    // SAFETY: a live instance and a state pointer it fills.
    assert_eq!(unsafe { fmi2GetFMUstate(c, &mut s) }, 0);
    assert_eq!(set2(c, F, -8.0), 0);
    assert_eq!(step2(c, 30.0, 1.0), 0);
    let x_on = get2(c, X);
    // SAFETY: the state from fmi2GetFMUstate, not freed.
    assert_eq!(unsafe { fmi2SetFMUstate(c, s) }, 0);
    assert!((get2(c, 0) - 30.0).abs() < 1e-12);
    assert!((get2(c, X) - 0.02).abs() < 1e-9);
    assert!((get2(c, F) - 8.0).abs() < 1e-12);
    assert_eq!(set2(c, F, -8.0), 0);
    assert_eq!(step2(c, 30.0, 1.0), 0);
    assert!((get2(c, X) - x_on).abs() < 1e-8, "{} vs {x_on}", get2(c, X));
    // SAFETY: state and instance freed once.
    unsafe {
        assert_eq!(fmi2FreeFMUstate(c, &mut s), 0);
        assert!(s.is_null());
        fmi2FreeInstance(c);
    }
}

#[test]
fn two_instances_are_independent() {
    let f = fmu_of(&msd(), FmiVersion::V2);
    let (a, b) = (instantiate2(&f, "a"), instantiate2(&f, "b"));
    init2(a);
    init2(b);
    assert_eq!(set2(a, F, 10.0), 0);
    for i in 0..100 {
        let t = f64::from(i) * 0.01;
        assert_eq!(step2(a, t, 0.01), 0);
        assert_eq!(step2(b, t, 0.01), 0);
    }
    assert!((get2(a, X) - msd_x(10.0, 1.0)).abs() < 1e-8);
    assert!(get2(b, X).abs() < 1e-300, "b untouched by a's input");
    // SAFETY: live instances, freed once.
    unsafe {
        fmi2FreeInstance(a);
        fmi2FreeInstance(b);
    }
}

#[test]
fn fmi3_broken_model_gives_an_error_and_a_logged_message() {
    let dir = tempfile::tempdir().unwrap();
    let f = fmu_of(&msd(), FmiVersion::V3);
    // break the model inside the unpacked FMU (as a hand-edited FMU would be)
    let res = PathBuf::from(f.resources.to_str().unwrap());
    let model = res.join("msd_force.toml");
    let text = std::fs::read_to_string(&model).unwrap();
    std::fs::write(
        &model,
        text.replace("kind = \"C\", k = \"k\"", "kind = \"Cx\", k = \"k\""),
    )
    .unwrap();
    let messages: Messages = RefCell::new(Vec::new());
    let name = CString::new("broken").unwrap();
    // SAFETY: valid strings; `messages` outlives the call (and no instance is made).
    let c = unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            f.token.as_ptr(),
            f.resources.as_ptr(),
            0,
            0,
            0,
            0,
            ptr::null(),
            0,
            ptr::from_ref(&messages).cast_mut().cast(),
            Some(log3),
            ptr::null(),
        )
    };
    assert!(c.is_null());
    let m = messages.borrow();
    assert_eq!(m.len(), 1, "{m:?}");
    let (status, text) = &m[0];
    assert_eq!(*status, 3);
    assert!(text.contains("msd_force.toml:28:"), "{text}");
    assert!(text.contains("Cx") && text.contains("hint:"), "{text}");
    drop(dir);
}

#[test]
fn fmi3_steps_and_a_panic_is_caught_at_the_boundary() {
    let f = fmu_of(&msd(), FmiVersion::V3);
    let messages: Messages = RefCell::new(Vec::new());
    let name = CString::new("three").unwrap();
    // SAFETY: valid strings; `messages` outlives the instance (freed below).
    let c = unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            f.token.as_ptr(),
            f.resources.as_ptr(),
            0,
            1,
            0,
            0,
            ptr::null(),
            0,
            ptr::from_ref(&messages).cast_mut().cast(),
            Some(log3),
            ptr::null(),
        )
    };
    assert!(!c.is_null());
    let (vr, v) = ([F], [10.0]);
    let mut out = [0.0; 2];
    let (mut event, mut term, mut early, mut last) = (1_u8, 1_u8, 1_u8, -1.0);
    // SAFETY: a live instance; arrays and out-pointers as declared.
    unsafe {
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi3SetFloat64(c, vr.as_ptr(), 1, v.as_ptr(), 1), 0);
        assert_eq!(fmi3ExitInitializationMode(c), 0);
        for i in 0..50 {
            let t = f64::from(i) * 0.02;
            assert_eq!(
                fmi3DoStep(c, t, 0.02, 1, &mut event, &mut term, &mut early, &mut last),
                0
            );
        }
        assert_eq!((event, term, early), (0, 0, 0));
        assert!((last - 1.0).abs() < 1e-12);
        assert_eq!(
            fmi3GetFloat64(c, [0, X].as_ptr(), 2, out.as_mut_ptr(), 2),
            0
        );
        // a value count that does not match
        assert_eq!(fmi3GetFloat64(c, [X].as_ptr(), 1, out.as_mut_ptr(), 2), 3);
        // not offered
        assert_eq!(fmi3GetInt32(c), 3);
    }
    assert!((out[0] - 1.0).abs() < 1e-12);
    assert!((out[1] - msd_x(10.0, 1.0)).abs() < 1e-8);

    // a panic inside a call: caught, logged, fmi3Fatal (through the guard every entry point uses)
    // SAFETY: a live instance, not otherwise borrowed.
    let inst = unsafe { bg_fmu::ffi::instance(c) };
    let s = bg_fmu::ffi::run(inst, |_| panic!("boom"));
    assert_eq!(s, 4);
    assert!(messages
        .borrow()
        .iter()
        .any(|(s, m)| *s == 4 && m.contains("boom") && m.contains("panic")));
    // a null instance is an error, not a crash
    // SAFETY: null is allowed.
    assert_eq!(unsafe { fmi3Terminate(ptr::null_mut()) }, 3);
    // SAFETY: a live instance, freed once.
    unsafe { fmi3FreeInstance(c) };
}

#[test]
fn the_log_of_a_failure_reaches_a_rust_logger() {
    // the safe layer alone: an unknown value reference is an error with a message
    let f = fmu_of(&msd(), FmiVersion::V2);
    let seen = Rc::new(RefCell::new(Vec::<String>::new()));
    let s2 = Rc::clone(&seen);
    let res = PathBuf::from(f.resources.to_str().unwrap());
    let mut i = bg_fmu::Instance::new(
        "safe",
        &res,
        Some(f.token.to_str().unwrap()),
        Box::new(move |_, _, m| s2.borrow_mut().push(m.to_owned())),
        false,
    )
    .unwrap();
    let e = i.get(99).unwrap_err();
    assert_eq!(i.report(&e), bg_fmu::Status::Error);
    assert!(seen.borrow()[0].contains("99"));
    // a token of another model is refused at instantiation
    let e = bg_fmu::Instance::new("t", &res, Some("{other}"), Box::new(|_, _, _| {}), false)
        .unwrap_err();
    assert!(e.message.contains("token"), "{}", e.message);
}
