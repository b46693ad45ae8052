//! `bg-sim check`: list a model's elements, bonds with causal strokes, states, scene
//! switches and problems.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bg_model::inspect;
use bg_sim::registry;
use serde_json::json;

use super::json::{problems, Format};
use super::BAD_INPUT;

/// The options of `bg-sim check` (its summary is on `Command::Check` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// Override a value of the model file (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// text, or json (elements, states, problems and notes as one JSON document).
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
}

/// `bg-sim check`.
pub fn command(a: &Args) -> ExitCode {
    match a.format {
        Format::Text => check(&a.model, &a.set),
        Format::Json => check_json(&a.model, &a.set),
    }
}

/// `check --format json`: `{file, ok, elements: [{name, kind, line}], states: [{name,
/// initial}], problems: [..], notes: [..]}` with problems and notes as [`problems`] writes
/// them; exit 1 if there are problems, 2 if the model could not be read.
fn check_json(path: &Path, set: &[String]) -> ExitCode {
    let report = inspect(path, &registry(), set);
    let elements: Vec<_> = report
        .elements
        .iter()
        .map(|(name, kind, line)| json!({"name": name, "kind": kind, "line": line}))
        .collect();
    let states: Vec<_> = report
        .states
        .iter()
        .map(|(name, v)| json!({"name": name, "initial": v}))
        .collect();
    let inputs: Vec<_> = report
        .inputs
        .iter()
        .map(|(s, from)| {
            json!({"name": s.name, "unit": s.unit, "default": s.default,
                   "description": s.description, "data": from})
        })
        .collect();
    crate::report::document(&json!({
        "file": path.display().to_string(),
        "ok": report.problems.is_empty(),
        "elements": elements,
        "inputs": inputs,
        "states": states,
        "problems": problems(&report.problems),
        "notes": problems(&report.notes),
    }));
    status(&report.problems)
}

/// 0 without problems; else 2: a model with problems is bad input, as for every command
/// (an unreadable file and a wrong parameter alike; docs/limits.md, "Exit statuses").
fn status(problems: &[bg_model::ModelError]) -> ExitCode {
    if problems.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(BAD_INPUT)
    }
}

fn check(path: &Path, set: &[String]) -> ExitCode {
    let report = inspect(path, &registry(), set);
    if !report.elements.is_empty() {
        say!("elements ({}):", report.elements.len());
        for (name, kind, line) in &report.elements {
            say!("  {name:<20} {kind:<20} line {line}");
        }
    }
    if !report.inputs.is_empty() {
        say!("inputs ({}):", report.inputs.len());
        for (s, from) in &report.inputs {
            let unit = if s.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", s.unit)
            };
            let data = if from.is_empty() {
                String::new()
            } else {
                format!(", from {from}")
            };
            let what = if s.description.is_empty() {
                String::new()
            } else {
                format!("  {}", s.description)
            };
            say!("  {:<20} default {}{unit}{data}{what}", s.name, s.default);
        }
    }
    if !report.bonds.is_empty() {
        say!(
            "bonds ({}), `|` marks the causal stroke (the end that receives the effort):",
            report.bonds.len()
        );
        for b in &report.bonds {
            say!("  {b}");
        }
    }
    if !report.states.is_empty() {
        say!("states ({}):", report.states.len());
        for (name, v) in &report.states {
            say!("  {name:<24} initial {v}");
        }
    }
    if !report.scene.is_empty() {
        say!(
            "scene switches ({}, {} scenes; `bg-sim reduce` searches them), richest choice first:",
            report.scene.switches.len(),
            report.scene.grid_size()
        );
        for sw in &report.scene.switches {
            let choices: Vec<&str> = sw.choices.iter().map(|c| c.label.as_str()).collect();
            say!("  {:<20} {} = {}", sw.name, sw.set, choices.join(" | "));
        }
    }
    for n in &report.notes {
        say!("  note: {n}");
    }
    if report.problems.is_empty() {
        say!("no problems found");
        ExitCode::SUCCESS
    } else {
        say!("problems ({}):", report.problems.len());
        for p in report.problems.iter().take(SHOWN) {
            say!("  error: {p}");
        }
        if let Some(rest) = rest_by_kind(&report.problems) {
            say!("  {rest}");
        }
        status(&report.problems)
    }
}

/// How many problems the text report shows in full; the rest are counted by kind (issue 24,
/// item 7: 20 000 bad events printed 6.5 MB). `--format json` lists every one.
pub const SHOWN: usize = 20;

/// `… and N more problems not shown: n₁ kind₁, n₂ kind₂` for the problems after the first
/// [`SHOWN`], or `None` if there are no more.
#[must_use]
pub fn rest_by_kind(problems: &[bg_model::ModelError]) -> Option<String> {
    let rest = problems.get(SHOWN..).filter(|r| !r.is_empty())?;
    let mut kinds: Vec<(String, usize)> = Vec::new();
    for p in rest {
        let k = format!("{:?}", p.kind).to_lowercase();
        match kinds.iter_mut().find(|(n, _)| *n == k) {
            Some((_, c)) => *c += 1,
            None => kinds.push((k, 1)),
        }
    }
    let counts: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
    Some(format!(
        "… and {} more problems not shown ({}); `--format json` lists every one",
        rest.len(),
        counts.join(", ")
    ))
}
