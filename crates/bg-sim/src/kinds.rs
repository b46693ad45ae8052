//! `bg-sim kinds [NAME]`: every kind with its summary, or one kind in full — ports,
//! parameters with units, defaults and ranges (from its declaration), states and published
//! signals (from its example, built).

use std::fmt::Write as _;

use bg_model::{describe, parameter_table, ModelError, Registry};

/// The list of kinds, one line each.
#[must_use]
pub fn list(registry: &Registry) -> String {
    let mut out = String::new();
    for k in registry.kinds() {
        let _ = writeln!(out, "{:<28} {}", k.name, k.summary);
    }
    out
}

/// One kind in full.
pub fn report(registry: &Registry, name: &str) -> Result<String, ModelError> {
    let r = describe(registry, name)?;
    let mut out = String::new();
    let _ = writeln!(out, "{} — {}\n", r.decl.name, r.decl.summary);
    if r.exposed.is_empty() {
        if let Some(m) = r.members.first() {
            let ports: Vec<String> = m
                .ports
                .iter()
                .map(|(p, d)| match d {
                    Some(d) if *d > 1 => format!("{p} (dimension {d})"),
                    _ => p.clone(),
                })
                .collect();
            let _ = writeln!(
                out,
                "ports: {}",
                if ports.is_empty() {
                    "none".into()
                } else {
                    ports.join(", ")
                }
            );
        }
    } else {
        let ports: Vec<String> = r
            .exposed
            .iter()
            .map(|(p, inner)| format!("{p} (= {inner})"))
            .collect();
        let _ = writeln!(out, "ports: {}", ports.join(", "));
    }
    let _ = writeln!(out, "\nparameters:\n{}", parameter_table(&r.decl));
    let _ = writeln!(out, "example: {{ {} }}", r.decl.example);
    if !r.decl.simplifications.is_empty() {
        let _ = writeln!(out, "\nsimplifications (`bg-sim reduce --by activity`):");
        for s in r.decl.simplifications {
            let changes: Vec<String> = s.changes.iter().map(ToString::to_string).collect();
            let _ = writeln!(
                out,
                "  {} — {} ({}{})",
                s.name,
                s.doc,
                changes.join(", "),
                if s.members.is_empty() {
                    String::new()
                } else {
                    format!("; the activity of {}", s.members.join(", "))
                }
            );
        }
    }
    let composite = !r.exposed.is_empty();
    if composite {
        let _ = writeln!(
            out,
            "\nmembers of an instance `example` (states and signals are addressed as member.name):"
        );
    }
    for m in &r.members {
        let who = if composite {
            format!("  {} ({})", m.name, m.kind)
        } else {
            "  ".to_owned()
        };
        let list = |v: &[String]| {
            if v.is_empty() {
                "none".to_owned()
            } else {
                v.join(", ")
            }
        };
        let _ = writeln!(
            out,
            "{who}{}states: {}; publishes: {}; reads: {}",
            if composite { " — " } else { "" },
            list(&m.states),
            list(&m.outputs),
            list(&m.inputs)
        );
    }
    Ok(out)
}
