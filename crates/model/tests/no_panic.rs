//! Loading never panics: every model in `models/`, mutated at random (a line deleted or
//! duplicated, a number replaced by nan, inf, -1, 0, 1e308 or a string, a character
//! changed), either loads or gives a `ModelError`. A model that loads is also run briefly
//! (t_end clipped to 0.1 s after t_start) and checked; that must not panic either.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::ops::Range;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

use bg_model::{Model, Registry};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

const MODELS: &[(&str, &str)] = &[
    (
        "algebraic_loop.toml",
        include_str!("../../../models/algebraic_loop.toml"),
    ),
    (
        "dc_motor.toml",
        include_str!("../../../models/dc_motor.toml"),
    ),
    (
        "derivative_causality.toml",
        include_str!("../../../models/derivative_causality.toml"),
    ),
    (
        "mass_spring_damper.toml",
        include_str!("../../../models/mass_spring_damper.toml"),
    ),
    (
        "mtf_displacement.toml",
        include_str!("../../../models/mtf_displacement.toml"),
    ),
    (
        "rlc_series.toml",
        include_str!("../../../models/rlc_series.toml"),
    ),
    (
        "tf_lever.toml",
        include_str!("../../../models/tf_lever.toml"),
    ),
];

/// What a number may be replaced by.
const REPLACEMENTS: &[&str] = &["nan", "inf", "-1", "0", "1e308", "\"x\"", "x"];

/// Characters likely to upset a parser (a random `char` is drawn too).
const CHARS: &[char] = &[
    '"', '=', '[', ']', '{', '}', '.', ',', '-', '>', '#', '(', ')', '^', '/', '*', '0', '1', '9',
    'e', 'x', ' ', '\n', '\\', '\'', 'é', '\u{0}',
];

#[derive(Clone, Debug)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    /// Number (index, mod their count) replaced by `REPLACEMENTS[k]`.
    ReplaceNumber(usize, usize),
    /// Character (index, mod their count) replaced by a character.
    ChangeChar(usize, char),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), 0..REPLACEMENTS.len()).prop_map(|(i, k)| Mutation::ReplaceNumber(i, k)),
        (
            any::<usize>(),
            prop_oneof![3 => proptest::sample::select(CHARS), 1 => any::<char>()]
        )
            .prop_map(|(i, c)| Mutation::ChangeChar(i, c)),
    ]
}

/// Byte ranges of the numbers in `text` (digits, `.`, `_`, exponent), not inside names.
fn number_spans(text: &str) -> Vec<Range<usize>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
        let mut j = i;
        while j < b.len() {
            let c = b[j];
            if c.is_ascii_digit() || c == b'.' || c == b'_' {
                j += 1;
            } else if (c == b'e' || c == b'E')
                && j + 1 < b.len()
                && (b[j + 1].is_ascii_digit() || b[j + 1] == b'-' || b[j + 1] == b'+')
            {
                j += 2;
            } else {
                break;
            }
        }
        out.push(start..j);
        i = j;
    }
    out
}

fn apply(text: &str, m: &Mutation) -> String {
    match *m {
        Mutation::DeleteLine(i) | Mutation::DuplicateLine(i) => {
            let mut lines: Vec<&str> = text.split_inclusive('\n').collect();
            if lines.is_empty() {
                return text.to_owned();
            }
            let k = i % lines.len();
            if matches!(m, Mutation::DeleteLine(_)) {
                lines.remove(k);
            } else {
                let l = lines[k];
                lines.insert(k, l);
                if !l.ends_with('\n') {
                    lines.insert(k + 1, "\n");
                }
            }
            lines.concat()
        }
        Mutation::ReplaceNumber(i, k) => {
            let spans = number_spans(text);
            if spans.is_empty() {
                return text.to_owned();
            }
            let s = &spans[i % spans.len()];
            format!("{}{}{}", &text[..s.start], REPLACEMENTS[k], &text[s.end..])
        }
        Mutation::ChangeChar(i, c) => {
            let mut chars: Vec<char> = text.chars().collect();
            if chars.is_empty() {
                return text.to_owned();
            }
            let k = i % chars.len();
            chars[k] = c;
            chars.into_iter().collect()
        }
    }
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(non-string panic)".into())
}

/// How long one load (and short run) may take before it counts as hung.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// Set once a case hung: its thread keeps spinning, so later cases only load (no runs), to
/// keep the remaining cases fast; the hang itself is reported as a failure.
static HUNG: AtomicBool = AtomicBool::new(false);

#[derive(Debug)]
enum Verdict {
    Fine,
    Panicked(String),
    Hung,
}

/// Load `text`; if it loads and its t_end is at most 10 s, run it with t_end clipped to
/// 0.1 s after t_start and verify its checks. Runs on a worker thread with a time limit.
fn exercise(file: &str, text: &str) -> Verdict {
    let (file, text) = (file.to_owned(), text.to_owned());
    let simulate = !HUNG.load(Ordering::SeqCst);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let r = catch_unwind(AssertUnwindSafe(|| {
            match Model::from_text(&file, &text, &Registry::with_core(), &[]) {
                Err(e) => {
                    // formatting the error must not panic either
                    let _ = e.to_string();
                }
                Ok(mut model) => {
                    let s = &mut model.settings;
                    if simulate && s.t_end <= 10.0 {
                        s.t_end = s.t_start + (s.t_end - s.t_start).min(0.1);
                        // keep the output grid small: a mutated dt_out could ask for 1e8 rows
                        if (s.t_end - s.t_start) / s.dt_out <= 1e5 {
                            if let Ok(out) = model.run() {
                                let _ = model.verify(&out.trajectory);
                                let _ = model.run();
                            }
                        }
                    }
                }
            }
        }));
        let _ = tx.send(r.map_err(|p| panic_message(p.as_ref())));
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(Ok(())) => Verdict::Fine,
        Ok(Err(p)) => Verdict::Panicked(p),
        Err(_) => {
            HUNG.store(true, Ordering::SeqCst);
            Verdict::Hung
        }
    }
}

#[test]
fn unmutated_models_do_not_panic() {
    for (name, text) in MODELS {
        let v = exercise(name, text);
        assert!(matches!(v, Verdict::Fine), "{name}: {v:?}");
    }
}

/// Deterministic sweep: every line deleted, every number replaced by every replacement.
#[test]
fn every_line_deleted_and_every_number_replaced() {
    let mut failures = Vec::new();
    for (name, text) in MODELS {
        let n_lines = text.split_inclusive('\n').count();
        let mut mutations: Vec<Mutation> = (0..n_lines).map(Mutation::DeleteLine).collect();
        for i in 0..number_spans(text).len() {
            mutations.extend((0..REPLACEMENTS.len()).map(|k| Mutation::ReplaceNumber(i, k)));
        }
        for m in &mutations {
            let mutated = apply(text, m);
            match exercise(name, &mutated) {
                Verdict::Fine => {}
                Verdict::Panicked(p) => failures.push(format!("{name} with {m:?}: panicked: {p}")),
                Verdict::Hung => failures.push(format!(
                    "{name} with {m:?}: did not finish within {TIME_LIMIT:?}"
                )),
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// ~200 random models, each mutated 1 to 3 times. A panic fails the case (and is shrunk);
/// a hang is recorded without shrinking (each try would leave a thread spinning).
#[test]
fn mutated_models_never_panic() {
    let config = Config {
        cases: 200,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = TestRunner::new(config);
    let hangs = Mutex::new(Vec::new());
    let strategy = (0..MODELS.len(), prop::collection::vec(mutation(), 1..=3));
    let result = runner.run(&strategy, |(model, mutations)| {
        let (name, text) = MODELS[model];
        let mut mutated = text.to_owned();
        for m in &mutations {
            mutated = apply(&mutated, m);
        }
        match exercise(name, &mutated) {
            Verdict::Fine => Ok(()),
            Verdict::Panicked(p) => Err(TestCaseError::fail(format!("{name} with {mutations:?} panicked: {p}\n--- mutated model ---\n{mutated}"))),
            Verdict::Hung => {
                hangs.lock().unwrap().push(format!("{name} with {mutations:?}: did not finish within {TIME_LIMIT:?}\n--- mutated model ---\n{mutated}"));
                Ok(())
            }
        }
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    let hangs = hangs.into_inner().unwrap();
    assert!(
        hangs.is_empty(),
        "{} hangs:\n{}",
        hangs.len(),
        hangs.join("\n")
    );
}

#[test]
fn number_spans_find_numbers_not_names() {
    let t = "k1 = 200.0\nx0 = -0.05 # m\nc = 1e-3\nv = \"n0*(1 + a*x1)\"\n";
    let found: Vec<&str> = number_spans(t).into_iter().map(|r| &t[r]).collect();
    assert_eq!(found, ["200.0", "-0.05", "1e-3", "1"]);
}
