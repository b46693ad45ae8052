//! `bg-sim sea`: the record's CSV (with an RAO: heave, sway and roll at the point) and its
//! summary; bad input exits with status 2 and a hint, naming the RAO file's line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn sea(extra: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("sea")
        .args(extra)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn writes_the_record_and_the_motion_at_the_point_and_the_same_seed_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let rao = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/rao_supply_vessel.csv"
    );
    let run = |name: &str| {
        let out = dir.path().join(name);
        let (code, stdout, err) = sea(&[
            "--hs",
            "2.5",
            "--tp",
            "9",
            "--rao",
            rao,
            "--heading",
            "90",
            "--point",
            "0,8,12",
            "--duration",
            "600",
            "--dt",
            "0.1",
            "--seed",
            "7",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, Some(0), "{stdout}{err}");
        assert!(stdout.contains("517 components"), "{stdout}");
        std::fs::read_to_string(out).unwrap()
    };
    let a = run("a.csv");
    assert!(a.starts_with("t,eta,heave,sway,roll\n"));
    assert_eq!(a.lines().count(), 1 + 6001);
    assert_eq!(a, run("b.csv"));
}

#[test]
fn bad_input_exits_2_with_a_hint() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.csv");
    let o = out.to_str().unwrap();
    let bad_rao = dir.path().join("bad.csv");
    std::fs::write(&bad_rao, "heading_deg,omega_rad_s\n0,0.5\n").unwrap();
    for (args, want) in [
        (
            vec![
                "--hs",
                "2.5",
                "--tp",
                "9",
                "--spectrum",
                "bretschneider",
                "-o",
                o,
            ],
            "not a spectrum",
        ),
        (vec!["--hs=-1", "--tp", "9", "-o", o], "Hs"),
        (
            vec!["--hs", "2.5", "--tp", "9", "--dt", "4", "-o", o],
            "cannot resolve",
        ),
        (
            vec![
                "--hs",
                "2.5",
                "--tp",
                "9",
                "--rao",
                bad_rao.to_str().unwrap(),
                "-o",
                o,
            ],
            "bad.csv:1",
        ),
    ] {
        let (code, stdout, err) = sea(&args);
        assert_eq!(code, Some(2), "{args:?}: {stdout}{err}");
        assert!(
            err.contains(want) && err.contains("hint"),
            "{args:?}: {err}"
        );
    }
}
