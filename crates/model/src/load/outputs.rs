//! `[outputs]`: the columns of the results, each a probe of the equations
//! ([`StateEquations::probe`]), and notes on columns that likely meant another variable.

use bondgraph::{Output, StateEquations};
use toml::Spanned;

use super::parse::SpannedMap;
use super::source::Source;
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::RESERVED;

/// Longest output column name, in characters.
pub const MAX_COLUMN_NAME: usize = 100;

/// Whether `n` may name an output column: 1 to [`MAX_COLUMN_NAME`] characters, letters,
/// digits, `_`, `.`, `[`, `]`, starting with a letter or `_`; not `t`, `time` or `pi`. Such a
/// name needs no quoting in a CSV header and can be used in a `[[check]]`.
#[must_use]
pub fn valid_column_name(n: &str) -> bool {
    let mut c = n.chars();
    n.chars().count() <= MAX_COLUMN_NAME
        && !RESERVED.contains(&n)
        && c.next()
            .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || "_.[]".contains(ch))
}

/// The columns `[outputs]` asks for (every state if the section is absent), the notes on
/// outputs that likely meant another variable, and the names of the columns refused (their
/// problems go to `problems`).
pub(super) fn read(
    spec: &SpannedMap<String>,
    source: &Source,
    eqs: &StateEquations,
    problems: &mut Vec<ModelError>,
) -> (Vec<Output>, Vec<ModelError>, Vec<String>) {
    let mut outputs = Vec::new();
    let mut notes = Vec::new();
    let mut refused = Vec::new();
    if spec.is_empty() {
        for (i, s) in eqs.states().iter().enumerate() {
            outputs.push(Output {
                name: s.name.clone(),
                probe: bondgraph::Probe::State(i),
            });
        }
        return (outputs, notes, refused);
    }
    let names = eqs.probe_names();
    for (col, name) in spec {
        match column(col, name, source, eqs, &names) {
            Ok((output, note)) => {
                outputs.push(output);
                notes.extend(note);
            }
            Err(e) => {
                problems.push(e);
                refused.push(col.get_ref().clone());
            }
        }
    }
    (outputs, notes, refused)
}

/// A stress output written `<arm>.link<k>.<quantity>(x=<number>)` (docs/stress.md) as the
/// signal of the arm's stress block: `<arm>_stress.link<k>.<quantity>(x=<x as f64 prints>)`;
/// `None` if `name` is not of that form.
fn stress_alias(name: &str) -> Option<String> {
    let (head, x) = name.strip_suffix(')')?.split_once("(x=")?;
    let x: f64 = x.trim().parse().ok()?;
    let mut parts = head.splitn(3, '.');
    let (arm, link, quantity) = (parts.next()?, parts.next()?, parts.next()?);
    let k: usize = link.strip_prefix("link")?.parse().ok()?;
    let known = ["N", "V", "M", "M_modal", "sigma_top", "sigma_bottom"];
    (known.contains(&quantity) && !arm.is_empty())
        .then(|| format!("{arm}_stress.link{k}.{quantity}(x={x})"))
}

/// Column `col` reading `name`, and a note if it likely meant another variable:
/// `p_hose = "hose.P"` reads the power, next to `hose.p`, the pressure (a column whose name
/// starts with `P` or says `power` is taken to mean a power).
fn column(
    col: &Spanned<String>,
    name: &Spanned<String>,
    source: &Source,
    eqs: &StateEquations,
    names: &[String],
) -> Result<(Output, Option<ModelError>), ModelError> {
    if !valid_column_name(col.get_ref()) {
        return Err(source
            .err(
                ErrorKind::Settings,
                Some(&col.span()),
                format!("[outputs] `{}` cannot be a column name", clip(col.get_ref())),
            )
            .hint(format!("column names are 1 to {MAX_COLUMN_NAME} letters, digits, `_`, `.`, `[`, `]`, starting with a letter or `_`; `t` is the first column already, `time` and `pi` are reserved")));
    }
    let probe = eqs
        .probe(name.get_ref())
        .or_else(|| stress_alias(name.get_ref()).and_then(|n| eqs.probe(&n)));
    if probe.is_none() {
        if let Some(canonical) = stress_alias(name.get_ref()) {
            return Err(source
                .err(
                    ErrorKind::Settings,
                    Some(&name.span()),
                    format!("[outputs] `{}`: no stress section `{canonical}`", col.get_ref()),
                )
                .hint("declare the section on the arm: `stress_at = [{ link = 1, x = 4.0 }]`; sigma_top and sigma_bottom also need `section = { … }` on the link (docs/stress.md)"));
        }
    }
    let probe = probe.ok_or_else(|| {
        let el = name.get_ref().split('.').next().unwrap_or("");
        let offers: Vec<&String> = names
            .iter()
            .filter(|n| n.starts_with(&format!("{el}.")))
            .take(16)
            .collect();
        let offers: Vec<&str> = offers.iter().map(|s| s.as_str()).collect();
        source.err(ErrorKind::Settings, Some(&name.span()), format!("[outputs] `{}`: nothing is called `{}`", col.get_ref(), clip(name.get_ref()))).hint(if offers.is_empty() {
            "outputs name a state (`mass.p`), its derivative (`mass.p.dot`), a signal (`ctrl.out`) or a bond variable (`mass.e`, `mass.f`, `b3.P`, `lever.2.e`)".to_owned()
        } else {
            format!("`{}` offers: {}", clip(el), offers.join(", "))
        })
    })?;
    // A power read into a column whose name does not say so (or the reverse), where a
    // variable differing only in case exists: likely the other was meant.
    let mut note = None;
    let col_says_power =
        col.get_ref().starts_with('P') || col.get_ref().to_ascii_lowercase().contains("power");
    let is_power = matches!(probe, bondgraph::Probe::Power(_));
    let other = names
        .iter()
        .find(|n| *n != name.get_ref() && n.eq_ignore_ascii_case(name.get_ref()));
    if let Some(other) = other.filter(|_| col_says_power != is_power) {
        let what = |p: Option<bondgraph::Probe>| match p {
            Some(bondgraph::Probe::State(_)) => "a state",
            Some(bondgraph::Probe::Derivative(_)) => "a state's derivative",
            Some(bondgraph::Probe::Effort(_)) => "an effort",
            Some(bondgraph::Probe::Flow(_)) => "a flow",
            Some(bondgraph::Probe::Signal(_)) => "a signal",
            Some(bondgraph::Probe::Power(_)) => "a power (e·f)",
            _ => "a variable",
        };
        note = Some(
            source
                .err(
                    ErrorKind::Settings,
                    Some(&name.span()),
                    format!(
                        "[outputs] `{}` reads `{}`, {}; `{other}` is {}: names differ in case",
                        col.get_ref(),
                        name.get_ref(),
                        what(Some(probe)),
                        what(eqs.probe(other))
                    ),
                )
                .hint(format!(
                    "if you meant {}, write `{other}`",
                    what(eqs.probe(other))
                )),
        );
    }
    Ok((
        Output {
            name: col.get_ref().clone(),
            probe,
        },
        note,
    ))
}
