//! A model file with thousands of mistakes (issue 24, item 7): refusing them is linear in
//! their number (20 000 bad `[[events]]` took 94 s, each error's line found by scanning the
//! file from its start), and `bg-sim check` shows the first 20 in full and counts the rest
//! by kind (it printed 6.5 MB); `--format json` lists every one.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;
use std::time::Instant;

fn with_bad_events(n: usize) -> String {
    let mut s = String::from(
        "[parameters]\nm = 1.0\nk = 4.0\n[elements]\nmass = { kind = \"I\", m = \"m\" }\nspring = { kind = \"C\", c = \"1/k\" }\nv = { kind = \"1\" }\n[bonds]\nb1 = \"v -> mass\"\nb2 = \"v -> spring\"\n",
    );
    for i in 0..n {
        s += &format!(
            "[[events]]\nt = 0.{}\nset = {{ nope{i} = 1.0 }}\n",
            i % 9 + 1
        );
    }
    s
}

#[test]
fn twenty_thousand_bad_events_are_refused_at_once_and_the_report_is_capped() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("events.toml");
    std::fs::write(&path, with_bad_events(20_000)).unwrap();
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .arg("check")
        .arg(&path)
        .output()
        .unwrap();
    let took = start.elapsed().as_secs_f64();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(2), "{out}");
    // a guard, not a benchmark: 94 s before, 0.4 s after (debug build, 2 cores)
    assert!(took < 20.0, "refusing 20 000 events took {took:.1} s");
    assert!(out.contains("problems (20000):"), "{out}");
    assert_eq!(out.matches("  error: ").count(), 20, "{out}");
    assert!(
        out.contains("… and 19980 more problems not shown (19980 settings)"),
        "{out}"
    );
    assert!(out.len() < 20_000, "{} bytes", out.len());
    // every one, located, in JSON
    let o = Command::new(env!("CARGO_BIN_EXE_bg-sim"))
        .args(["check", "--format", "json"])
        .arg(&path)
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let problems = json["problems"].as_array().unwrap();
    assert_eq!(problems.len(), 20_000);
    // the last event is at line 10 + 3·19 999 + 3 = 60 010, the value of its `nope19999`
    // at column 21, as the scan from the start found them
    let last = problems
        .iter()
        .find(|p| p["message"].as_str().unwrap().contains("`nope19999`"))
        .unwrap();
    assert_eq!(last["line"], 60_010, "{last}");
    assert_eq!(last["column"], 21, "{last}");
}
