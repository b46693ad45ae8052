//! Fuzz target over the model loader, the expression parser and the inputs of the CLI's
//! other commands (a results CSV for `plot` and `compare`, a sweep spec for `sweep`):
//! generated inputs must give a value or an error, never a panic, a stack overflow or a hang.
//!
//! cargo-fuzz needs a nightly toolchain; this is the same idea on proptest, run as a test:
//! a corpus built from `models/` (every model file, whole), mutated with structure in mind
//! (lines deleted, duplicated or swapped; numbers replaced by extremes; strings replaced by
//! generated expressions, deep and long ones included; TOML and expression tokens inserted;
//! bytes flipped; `--set` overrides on the file's own keys), each loaded with every element
//! kind the CLI knows.
//!
//! Cases: `BG_FUZZ_CASES` (default 300 per target, a few seconds in CI). Seed: `BG_FUZZ_SEED`,
//! or else the commit under test (the first 16 hex digits of `git rev-parse HEAD`, so each
//! commit explores new inputs), or else (no git) a fixed one. Each target prints its seed,
//! and a failure names it: `BG_FUZZ_SEED=N` reproduces it. A long run prints a line every
//! `BG_FUZZ_PROGRESS` cases (default 10 000), so a run stopped early says how far it got.
//! A local sweep:
//! `BG_FUZZ_CASES=500000 BG_FUZZ_SEED=7 cargo test -p bg-tests --test fuzz -- --nocapture`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use bg_model::expr::Expr;
use bg_model::{Model, Registry};
use bg_tests::model_files;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

fn cases() -> u32 {
    std::env::var("BG_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

/// The seed and where it came from: `BG_FUZZ_SEED`, the commit, or the fixed fallback.
fn seed() -> (u64, String) {
    if let Some(s) = std::env::var("BG_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        return (s, "BG_FUZZ_SEED".into());
    }
    let head = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
    match head
        .as_deref()
        .and_then(|h| Some((h, u64::from_str_radix(h.get(..16)?, 16).ok()?)))
    {
        Some((h, s)) => (s, format!("commit {}", &h[..h.len().min(12)])),
        None => (20_261_201, "fixed: not in a git checkout".into()),
    }
}

/// Run `test` over `strategy` with the seed; print it (and the count and time); on a
/// failure, panic naming the seed that reproduces it.
fn fuzz<S: Strategy>(
    target: &str,
    strategy: &S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let (seed, from) = seed();
    eprintln!(
        "{target}: seed {seed} ({from}); reproduce with BG_FUZZ_SEED={seed} BG_FUZZ_CASES={}",
        cases()
    );
    let start = Instant::now();
    // progress for long local sweeps (a killed run still says how far it got): a line every
    // `BG_FUZZ_PROGRESS` cases (default 10 000; CI's few hundred print none)
    let every: u64 = std::env::var("BG_FUZZ_PROGRESS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000)
        .max(1);
    let done = std::cell::Cell::new(0u64);
    let result = runner(seed).run(strategy, |v| {
        let r = test(v);
        done.set(done.get() + 1);
        if done.get() % every == 0 {
            eprintln!(
                "{target}: {} cases run in {:.1} s (seed {seed})",
                done.get(),
                start.elapsed().as_secs_f64()
            );
        }
        r
    });
    eprintln!(
        "{target}: {} inputs in {:.1} s (seed {seed})",
        cases(),
        start.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{target} failed with BG_FUZZ_SEED={seed}: {e}");
    }
}

fn runner(seed: u64) -> TestRunner {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases: cases(),
        failure_persistence: None,
        // a failure is reported with its input; shrinking a loader input is slow
        max_shrink_iters: 200,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

/// The corpus: every model file, as (name, text).
fn corpus() -> Vec<(String, String)> {
    model_files()
        .into_iter()
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect()
}

/// Numbers a value may become.
const EXTREMES: &[&str] = &[
    "nan", "inf", "-inf", "0", "-0.0", "-1", "1e308", "1e-320", "9e99999", "1e16", "11", "64",
    "65", "-1e-300", "\"x\"", "true", "[]", "{}", "\"1/0\"", "\"\"", "1_0", "0x10",
];

/// Tokens of TOML and of expressions, to insert anywhere.
const TOKENS: &[&str] = &[
    "\"",
    "'",
    "=",
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    ".",
    ",",
    "->",
    "#",
    "\n",
    "(",
    ")",
    "^",
    "/",
    "*",
    "-",
    "+",
    "\\",
    "\u{0}",
    "é",
    "\u{feff}",
    "\r\n",
    "clamp(",
    "min(",
    "sqrt(",
    "t",
    "pi",
    "kind",
    "\"I\"",
    "\"1\"",
    "\"0\"",
    "[initial]",
    "[[events]]",
    "[outputs]",
    "[[check]]",
    "[simulation]",
    "t_end",
    "dt_out",
    "rtol",
    "x.y",
    "a[1]",
    "\"a,b\"",
    "e",
    "1e",
    "..",
];

/// A generated expression: names, numbers, operators, calls, deep nesting and long chains.
fn expression() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        prop::sample::select(vec![
            "1", "0", "2.5e-3", "1e308", "t", "pi", "k", "m", "x0", "mass.p", "spring.q", "q[1]",
            "nope", "1e", ".", "_", "time",
        ])
        .prop_map(str::to_owned),
        any::<f64>().prop_map(|v| format!("{v}")),
    ];
    let tree = leaf.prop_recursive(6, 64, 4, |inner| {
        prop_oneof![
            (
                inner.clone(),
                prop::sample::select(vec!["+", "-", "*", "/", "^", " ", ","]),
                inner.clone()
            )
                .prop_map(|(a, op, b)| format!("{a}{op}{b}")),
            inner.clone().prop_map(|a| format!("({a})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            (
                prop::sample::select(vec![
                    "sqrt", "exp", "ln", "atan2", "min", "max", "clamp", "pow", "step", "foo"
                ]),
                prop::collection::vec(inner, 0..4)
            )
                .prop_map(|(f, args)| format!("{f}({})", args.join(", "))),
        ]
    });
    // extremes of depth and length around the limits (200 levels, 10 000 characters)
    let extreme = (
        1usize..400,
        prop::sample::select(vec!["(", "-", "+", "sqrt(", "1+", "2^", "min(1,"]),
    )
        .prop_map(|(n, open)| {
            let close = if open.ends_with('(') { ")" } else { "" };
            format!("{}1{}", open.repeat(n), close.repeat(n))
        });
    let long = (1usize..6_000).prop_map(|n| vec!["1"; n].join("+"));
    prop_oneof![6 => tree, 2 => extreme, 1 => long]
}

#[derive(Clone, Debug)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    /// A number (index, mod their count) replaced.
    Number(usize, &'static str),
    /// A quoted string (index, mod their count) replaced by an expression.
    Expression(usize, String),
    /// A token inserted at a character position.
    Insert(usize, &'static str),
    /// A character replaced by any character.
    Char(usize, char),
    /// The text cut at a character position.
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        2 => any::<usize>().prop_map(Mutation::DeleteLine),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        3 => (any::<usize>(), prop::sample::select(EXTREMES)).prop_map(|(i, v)| Mutation::Number(i, v)),
        3 => (any::<usize>(), expression()).prop_map(|(i, e)| Mutation::Expression(i, e)),
        2 => (any::<usize>(), prop::sample::select(TOKENS)).prop_map(|(i, t)| Mutation::Insert(i, t)),
        1 => (any::<usize>(), any::<char>()).prop_map(|(i, c)| Mutation::Char(i, c)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
    ]
}

/// Byte ranges of numbers (not inside names) and of double-quoted strings.
fn spans(text: &str, strings: bool) -> Vec<std::ops::Range<usize>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if strings {
            if b[i] == b'"' {
                if let Some(j) = text[i + 1..].find(['"', '\n']) {
                    if b[i + 1 + j] == b'"' {
                        out.push(i..i + j + 2);
                    }
                    i += j + 2;
                    continue;
                }
            }
            i += 1;
            continue;
        }
        let starts = b[i].is_ascii_digit()
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_digit() || b"._eE-+".contains(&b[j])) {
            j += 1;
        }
        out.push(i..j);
        i = j;
    }
    out
}

fn char_index(text: &str, i: usize) -> usize {
    let n = text.chars().count().max(1);
    text.char_indices()
        .nth(i % n)
        .map_or(text.len(), |(b, _)| b)
}

fn apply(text: &str, m: &Mutation) -> String {
    let lines = || text.split_inclusive('\n').collect::<Vec<_>>();
    match m {
        Mutation::DeleteLine(i) | Mutation::DuplicateLine(i) => {
            let mut l = lines();
            if l.is_empty() {
                return text.to_owned();
            }
            let k = i % l.len();
            if matches!(m, Mutation::DeleteLine(_)) {
                l.remove(k);
            } else {
                l.insert(k, l[k]);
            }
            l.concat()
        }
        Mutation::SwapLines(a, b) => {
            let mut l = lines();
            if l.is_empty() {
                return text.to_owned();
            }
            let n = l.len();
            l.swap(a % n, b % n);
            l.concat()
        }
        Mutation::Number(i, _) | Mutation::Expression(i, _) => {
            let s = spans(text, matches!(m, Mutation::Expression(..)));
            if s.is_empty() {
                return text.to_owned();
            }
            let r = &s[i % s.len()];
            let with = match m {
                Mutation::Expression(_, e) => format!("\"{e}\""),
                Mutation::Number(_, v) => (*v).to_owned(),
                _ => String::new(),
            };
            format!("{}{with}{}", &text[..r.start], &text[r.end..])
        }
        Mutation::Insert(i, t) => {
            let k = char_index(text, *i);
            format!("{}{t}{}", &text[..k], &text[k..])
        }
        Mutation::Char(i, c) => {
            let k = char_index(text, *i);
            let mut out = text[..k].to_owned();
            out.push(*c);
            out.push_str(text[k..].chars().skip(1).collect::<String>().as_str());
            out
        }
        Mutation::Truncate(i) => text[..char_index(text, *i)].to_owned(),
    }
}

/// `--set` overrides: a key of the file (or a made-up one) with an extreme or an expression.
fn overrides() -> impl Strategy<Value = Vec<String>> {
    let key = prop::sample::select(vec![
        "parameters.k",
        "parameters.m",
        "parameters.modes1",
        "simulation.t_end",
        "simulation.t_start",
        "simulation.rtol",
        "simulation.dt_out",
        "simulation.solver",
        "simulation.nope",
        "elements.mass.m",
        "elements.nope.m",
        "initial.spring.q",
        "initial.\"spring.q\"",
        "events[0].t",
        "events[9].t",
        "events.t",
        "check[0].tol",
        "outputs.x",
        "nope.x",
        "a..b",
        "\"unclosed",
        "",
    ]);
    let value = prop_oneof![
        prop::sample::select(EXTREMES).prop_map(str::to_owned),
        expression(),
    ];
    let one = (key, value).prop_map(|(k, v)| format!("{k}={v}"));
    prop_oneof![3 => Just(Vec::new()), 1 => prop::collection::vec(one, 1..3)]
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(non-string panic)".into())
}

/// Load `text`; if it loads, read its notes and events too. Err: the panic message.
fn exercise(name: &str, text: &str, set: &[String], registry: &Registry) -> Result<bool, String> {
    catch_unwind(AssertUnwindSafe(|| {
        match Model::from_text(name, text, registry, set) {
            Err(e) => {
                let _ = e.to_string();
                false
            }
            Ok(m) => {
                let _ = m.notes();
                let _ = m.events().map(|e| e.len());
                let _ = m.settings.validate();
                true
            }
        }
    }))
    .map_err(|p| panic_message(p.as_ref()))
}

/// The model loader over mutated models from `models/`.
#[test]
fn fuzz_model_loader() {
    let corpus = corpus();
    assert!(corpus.len() >= 5, "the corpus is models/*.toml");
    let registry = bg_sim::registry();
    let strategy = (
        0..corpus.len(),
        prop::collection::vec(mutation(), 1..=3),
        overrides(),
    );
    let loaded = std::cell::Cell::new(0usize);
    fuzz("fuzz_model_loader", &strategy, |(k, mutations, set)| {
        let (name, text) = &corpus[k];
        let mut mutated = text.clone();
        for m in &mutations {
            mutated = apply(&mutated, m);
        }
        match exercise(name, &mutated, &set, &registry) {
            Ok(l) => {
                loaded.set(loaded.get() + usize::from(l));
                Ok(())
            }
            Err(p) => Err(TestCaseError::fail(format!(
                "{name} with {mutations:?} and --set {set:?} panicked: {p}"
            ))),
        }
    });
    eprintln!("fuzz_model_loader: {} loaded", loaded.get());
}

/// The expression parser and evaluator over generated and mutated expressions.
#[test]
fn fuzz_expression_parser() {
    let strategy = (
        expression(),
        prop::collection::vec((any::<usize>(), prop::sample::select(TOKENS)), 0..3),
    );
    fuzz("fuzz_expression_parser", &strategy, |(e, inserts)| {
        let mut s = e;
        for (i, t) in inserts {
            let k = char_index(&s, i);
            s.insert_str(k, t);
        }
        catch_unwind(AssertUnwindSafe(|| {
            if let Ok(x) = Expr::parse(&s) {
                let _ = x.names();
                let _ = x.eval(&|n| (n.len() < 3).then_some(1.5));
                if let Ok(c) = x.compile(
                    &|n| (n == "k").then_some(2.0),
                    &["t".into(), "mass.p".into()],
                ) {
                    let _ = c.eval(&[0.5, -1.0]);
                    let _ = c.constant();
                }
            }
        }))
        .map_err(|p| TestCaseError::fail(format!("`{s}` panicked: {}", panic_message(p.as_ref()))))
    });
}

/// A results CSV as `bg-sim run` writes it: `t` and two columns, `rows` rows.
fn results_csv(rows: usize) -> String {
    let mut s = String::from("t,x,F_c1\n");
    for k in 0..rows {
        let t = k as f64 * 0.05;
        s += &format!("{t},{},{}\n", (3.0 * t).sin(), 5e5 + 1e5 * t);
    }
    s
}

/// Numbers a results cell may become: the extremes of a model file and the values a
/// diverged run writes.
const CELLS: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "5e-324",
    "-0",
    "0",
    "1e-320",
    "",
    " ",
    "x",
    "1e",
    "1,2",
];

/// `bg-sim plot` and `bg-sim compare` over mutated results CSVs: read, drawn (a quick look,
/// as SVG) and scored against themselves and the unmutated file. Each must give figures or
/// an error, never a panic or a hang (issue 24: ±1e308 in a column hung `plot`; NaN scored
/// as a result in `compare`).
#[test]
fn fuzz_plot_and_compare_inputs() {
    use bg_sim::bench::{unscorable, Reference};
    use bg_sim::plot::{draw, quick_look, Format, Results};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.csv");
    let strategy = (
        1usize..40,
        prop::collection::vec(
            prop_oneof![
                3 => (any::<usize>(), prop::sample::select(CELLS)).prop_map(|(i, v)| Mutation::Number(i, v)),
                1 => mutation(),
            ],
            1..=4,
        ),
        prop::sample::select(vec!["x", "F_c1", "t", "nope"]),
    );
    let original = Results::parse(&results_csv(40)).unwrap();
    fuzz(
        "fuzz_plot_and_compare_inputs",
        &strategy,
        |(rows, mutations, column)| {
            let mut text = results_csv(rows);
            for m in &mutations {
                text = apply(&text, m);
            }
            catch_unwind(AssertUnwindSafe(|| {
                let Ok(table) = Results::parse(&text) else {
                    return;
                };
                if let Ok(plot) = quick_look(&table, &path, "r", &[column.to_owned()]) {
                    let _ = draw(&table, &plot, dir.path(), Format::Svg);
                }
                let run = table.to_trajectory();
                for reference in [&table, &original] {
                    let t = reference.time().to_vec();
                    let named = reference
                        .names()
                        .iter()
                        .skip(1)
                        .filter_map(|n| reference.column(n).map(|c| (n.clone(), c.to_vec())))
                        .collect();
                    if let Ok(r) = Reference::new(t, named, None, &[]) {
                        let _ = unscorable(&path, &r, |n| table.column(n));
                        let _ = r.errors(&run);
                        let _ = r.worst(&run);
                    }
                }
            }))
            .map_err(|p| {
                TestCaseError::fail(format!(
                    "{mutations:?} on {rows} rows panicked: {}\n{text}",
                    panic_message(p.as_ref())
                ))
            })
        },
    );
}

/// The sweep specs of the docs (`docs/sweeps/*.toml` and the spec in `docs/sweeps.md`).
fn sweep_specs() -> Vec<(String, String)> {
    let docs = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let mut out: Vec<(String, String)> = std::fs::read_dir(docs.join("sweeps"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    let md = std::fs::read_to_string(docs.join("sweeps.md")).unwrap();
    if let Some((_, rest)) = md.split_once("```toml sweep-spec\n") {
        if let Some((spec, _)) = rest.split_once("```") {
            out.push(("sweeps.md".into(), spec.to_owned()));
        }
    }
    out
}

/// `bg-sim sweep` specs: mutated specs parsed, their design laid out, and the first run's
/// `--set` overrides applied to a model of `models/`. Each must give runs or an error, never a
/// panic or a hang.
#[test]
fn fuzz_sweep_specs() {
    use bg_sim::sweep::{parse_spec, points};
    let specs = sweep_specs();
    assert!(specs.len() >= 2, "docs/sweeps/*.toml and docs/sweeps.md");
    let models = corpus();
    let registry = bg_sim::registry();
    let strategy = (
        0..specs.len(),
        0..models.len(),
        prop::collection::vec(mutation(), 1..=3),
    );
    fuzz("fuzz_sweep_specs", &strategy, |(k, m, mutations)| {
        let (name, text) = &specs[k];
        let mut mutated = text.clone();
        for mu in &mutations {
            mutated = apply(&mutated, mu);
        }
        catch_unwind(AssertUnwindSafe(|| {
            let Ok(spec) = parse_spec(name, &mutated) else {
                return;
            };
            let design = points(&spec);
            if let Some(first) = design.first() {
                let _ = first.id();
                let (model, text) = &models[m];
                let _ = Model::from_text(model, text, &registry, &first.overrides())
                    .map(|m| m.settings.validate());
            }
        }))
        .map_err(|p| {
            TestCaseError::fail(format!(
                "{name} with {mutations:?} panicked: {}\n{mutated}",
                panic_message(p.as_ref())
            ))
        })
    });
}
