//! An input read from a data file with `interp = "hold"` (issue 37, item 8): at a sample
//! time the FMU and `run` see the same value — the one from that sample on (a held series
//! is right-continuous) — and getReal of the input reads what the data drive, not 0.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use bg_fmu::{export, FmiVersion, Instance};

const MODEL: &str = r#"
[inputs]
F = { file = "step.csv", column = "F", interp = "hold" }
[elements]
force  = { kind = "Se", e = "F" }
v      = { kind = "1" }
mass   = { kind = "I", m = 1.0 }
spring = { kind = "C", k = 100.0 }
[bonds]
b0 = "force -> v"
b1 = "v -> mass"
b2 = "v -> spring"
[simulation]
t_end = 3.0
dt_out = 0.5
[outputs]
push = "b0.e"
"#;

#[test]
fn a_held_input_at_a_sample_time_is_the_same_in_the_fmu_and_in_run() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("hold.toml");
    std::fs::write(&model, MODEL).unwrap();
    std::fs::write(dir.path().join("step.csv"), "t,F\n0,0\n1,10\n3,10\n").unwrap();

    // run: the row at t = 1 has the value from the sample at t = 1 on
    let mut m = bg_model::Model::load(&model, &bg_fmu::instance::registry(), &[]).unwrap();
    let traj = m.run().unwrap().trajectory;
    let (t, push) = (traj.column("t").unwrap(), traj.column("push").unwrap());
    let at = |s: f64| push[t.iter().position(|&v| (v - s).abs() < 1e-12).unwrap()];
    assert_eq!((at(0.5), at(1.0), at(1.5)), (0.0, 10.0, 10.0));

    // the FMU, stepping on the same grid
    let fmu = dir.path().join("hold.fmu");
    let x = export(&model, &[], FmiVersion::V2, Path::new(&model), &fmu).unwrap();
    let mut z = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    z.extract(dir.path().join("unzipped")).unwrap();
    let vr = |name: &str| {
        x.description
            .variables
            .iter()
            .find(|v| v.name == name)
            .unwrap()
            .vr
    };
    let mut i = Instance::new(
        "hold",
        &dir.path().join("unzipped/resources"),
        Some(&x.description.token),
        Box::new(|_, _, _| {}),
        false,
    )
    .unwrap();
    i.enter_init("fmi2EnterInitializationMode").unwrap();
    i.exit_init("fmi2ExitInitializationMode").unwrap();
    let mut seen = Vec::new();
    for k in 0..3 {
        let t = f64::from(k) * 0.5;
        i.do_step("fmi2DoStep", t, 0.5).unwrap();
        seen.push((i.get(vr("push")).unwrap(), i.get(vr("F")).unwrap()));
    }
    assert_eq!(seen, [(0.0, 0.0), (10.0, 10.0), (10.0, 10.0)]);
}
