//! `bg-sim compare`: a comparison that cannot be scored (a NaN, an infinity, a range that
//! overflows f64, a zero scale) fails naming the file, the column and why (issue 24,
//! item 9); a comparison that can be scored reports its worst column.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn compare(a: &str, b: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let (pa, pb) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    std::fs::write(&pa, a).unwrap();
    std::fs::write(&pb, b).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("compare")
        .arg(&pa)
        .arg(&pb)
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
fn a_column_that_cannot_be_scored_fails_naming_it_and_why() {
    // each against itself: before, exit 0 and "worst: x NaN" (or 0 for ±1e308)
    for (text, why) in [
        ("t,x,y\n0,1,NaN\n1,2,3\n", "holds NaN"),
        ("t,x,y\n0,1,inf\n1,2,3\n", "holds inf"),
        ("t,x,y\n0,1,-inf\n1,2,3\n", "holds -inf"),
        ("t,x,y\n0,1,1e308\n1,2,-1e308\n", "overflows f64"),
    ] {
        let (code, out, err) = compare(text, text, &[]);
        assert_eq!(code, Some(2), "{text}: {out}{err}");
        assert!(
            err.contains("column `y`") && err.contains(why),
            "{text}: {err}"
        );
        assert!(!out.contains("worst"), "{text}: {out}");
    }
    // in the results only: named with the results file
    let good = "t,x,y\n0,1,2\n1,2,3\n";
    let (code, _, err) = compare("t,x,y\n0,1,2\n1,NaN,3\n", good, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("a.csv") && err.contains("column `x`") && err.contains("data row 2"),
        "{err}"
    );
    // a NaN time
    let (code, _, err) = compare("t,x\nNaN,1\n1,2\n", "t,x\n0,1\n1,2\n", &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("column `t`"), "{err}");
    // a column that is zero in the reference: equal, it scores 0; different, it cannot be
    // scaled (the hint names the floor); with a floor it scores
    let zero = "t,x,y\n0,1,0\n1,2,0\n";
    let (code, out, err) = compare(zero, zero, &[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("worst: "), "{out}");
    let (code, out, err) = compare("t,x,y\n0,1,0\n1,2,1e-12\n", zero, &[]);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("column `y`") && err.contains("scale 0e0") && err.contains("--floor y="),
        "{err}"
    );
    let (code, out, err) = compare("t,x,y\n0,1,0\n1,2,1e-12\n", zero, &["--floor", "y=1e-9"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("worst: "), "{out}");
    let (code, out, err) = compare(zero, zero, &["--floor", "y=1e-9"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("worst: "), "{out}");
    // a comparison that can be scored: scale max(range 1, mean 1.5), error 0.5 / 1.5
    let (code, out, err) = compare("t,x\n0,1\n1,2.5\n", "t,x\n0,1\n1,2\n", &[]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("worst: x 3.333e-1"), "{out}");
}
