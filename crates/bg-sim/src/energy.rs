//! The energy audit of a run as a person, a script or a spreadsheet reads it (`bg-sim energy`,
//! `bg-sim run --energy`): the table by composite or by element ([`rows`]) as text, JSON or
//! CSV, and the figures a hydraulic engineer reads first ([`Efficiency`]: energy in, useful
//! work, losses, overall efficiency). The figure is drawn by [`crate::plot::energy_bars`].
//! The audit itself is the core's ([`bondgraph::energy`]).

use std::fmt::Write as _;

use bondgraph::{ElementEnergy, EnergyReport, EnergyRole};
use serde_json::{json, Value};

/// The table's rows: by composite (the model file's entries), or every element with
/// `expand`; conservative elements (junctions, TF, MTF, which neither give nor take
/// energy) only with `expand`. Ordered by activity, largest first.
#[must_use]
pub fn rows(report: &EnergyReport, expand: bool) -> Vec<ElementEnergy> {
    let mut v: Vec<ElementEnergy> = if expand {
        report.elements.clone()
    } else {
        report
            .by_composite()
            .into_iter()
            .filter(|g| g.role != EnergyRole::Conservative)
            .collect()
    };
    v.sort_by(|a, b| b.activity.total_cmp(&a.activity));
    v
}

/// What a hydraulic engineer reads first about a run's energy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Efficiency {
    /// Energy the sources delivered (those whose `supplied` is positive: the pump's shaft,
    /// a supply), J.
    pub input: f64,
    /// Work done against the sources that took energy in (gravity on a lifted load, a tank
    /// at pressure), J.
    pub work_on_sources: f64,
    /// Energy stored at the end beyond the start (the arm raised, an accumulator charged), J.
    pub stored: f64,
    /// Energy dissipated, J.
    pub losses: f64,
    /// Useful work: `work_on_sources` + `stored` (when positive), J.
    pub useful: f64,
    /// `useful / input` (0 when nothing came in).
    pub efficiency: f64,
}

impl Efficiency {
    /// The figures of `report`.
    #[must_use]
    pub fn of(report: &EnergyReport) -> Self {
        let mut e = Self::default();
        for el in &report.elements {
            if el.role == EnergyRole::Source {
                if el.supplied > 0.0 {
                    e.input += el.supplied;
                } else {
                    e.work_on_sources -= el.supplied;
                }
            }
        }
        e.stored = report.stored;
        e.losses = report.dissipated;
        e.useful = e.work_on_sources + e.stored.max(0.0);
        e.efficiency = if e.input > 0.0 {
            e.useful / e.input
        } else {
            0.0
        };
        e
    }
}

/// Energies in J with four significant digits (`1.234e5`), or `0`.
fn joules(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.4e}")
    }
}

/// The audit as a table for a person: the rows, the totals, the balance and the engineer's
/// figures.
#[must_use]
pub fn text(report: &EnergyReport, expand: bool) -> String {
    let rows = rows(report, expand);
    let name_w = rows
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(7)
        .max(7);
    let kind_w = rows
        .iter()
        .map(|r| r.kind.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "energy from t = {} s to {} s ({} steps audited), J{}",
        report.t_start,
        report.t_end,
        report.steps,
        if expand {
            ""
        } else {
            "; by composite (--expand: every element)"
        }
    );
    let _ = writeln!(
        s,
        "{:<name_w$}  {:<kind_w$}  {:<13}  {:>11}  {:>11}  {:>11}  {:>11}  {:>6}",
        "element", "kind", "role", "supplied", "stored", "dissipated", "activity", "share"
    );
    for r in &rows {
        let _ = writeln!(
            s,
            "{:<name_w$}  {:<kind_w$}  {:<13}  {:>11}  {:>11}  {:>11}  {:>11}  {:>5.1}%",
            r.name,
            r.kind,
            r.role.name(),
            joules(r.supplied),
            joules(r.stored),
            joules(r.dissipated),
            joules(r.activity),
            100.0 * r.share
        );
    }
    let _ = writeln!(
        s,
        "total: supplied {}, stored {} (at the start {}), dissipated {}",
        joules(report.supplied),
        joules(report.stored),
        joules(report.stored_initial),
        joules(report.dissipated)
    );
    let _ = writeln!(
        s,
        "balance: supplied − stored − dissipated = {:.3e} J, {:.2e} of {} J (the energy moved){}",
        report.residual,
        report.relative_residual(),
        joules(report.reference),
        if report.conservative == 0.0 {
            String::new()
        } else {
            format!(
                "; junctions, TF, GY, MTF: net {:.3e} J",
                report.conservative
            )
        }
    );
    let e = Efficiency::of(report);
    if e.input > 0.0 {
        let _ = writeln!(
            s,
            "efficiency: input {} J, useful {} J (work on loads {} J, stored {} J), losses {} J: {:.1} %",
            joules(e.input),
            joules(e.useful),
            joules(e.work_on_sources),
            joules(e.stored),
            joules(e.losses),
            100.0 * e.efficiency
        );
    }
    s
}

fn row_json(r: &ElementEnergy) -> Value {
    json!({
        "name": r.name,
        "kind": r.kind,
        "composite": r.composite,
        "role": r.role.name(),
        "supplied": r.supplied,
        "stored": r.stored,
        "dissipated": r.dissipated,
        "net": r.net,
        "activity": r.activity,
        "share": r.share,
        "stored_by_function": r.stored_by_function,
    })
}

/// The audit as one JSON document: `{t_start, t_end, steps, rows: [{name, kind, composite,
/// role, supplied, stored, dissipated, net, activity, share, stored_by_function}], totals:
/// {supplied, stored, stored_initial, dissipated, conservative, residual, reference,
/// relative_residual}, efficiency: {input, useful, work_on_sources, stored, losses,
/// efficiency}}`; `rows` by composite unless `expand`.
#[must_use]
pub fn json(report: &EnergyReport, expand: bool) -> Value {
    let e = Efficiency::of(report);
    json!({
        "t_start": report.t_start,
        "t_end": report.t_end,
        "steps": report.steps,
        "rows": rows(report, expand).iter().map(row_json).collect::<Vec<_>>(),
        "totals": {
            "supplied": report.supplied,
            "stored": report.stored,
            "stored_initial": report.stored_initial,
            "dissipated": report.dissipated,
            "conservative": report.conservative,
            "residual": report.residual,
            "reference": report.reference,
            "relative_residual": report.relative_residual(),
        },
        "efficiency": {
            "input": e.input,
            "useful": e.useful,
            "work_on_sources": e.work_on_sources,
            "stored": e.stored,
            "losses": e.losses,
            "efficiency": e.efficiency,
        },
    })
}

/// The columns of [`csv`], in order.
pub const CSV_COLUMNS: [&str; 10] = [
    "name",
    "kind",
    "composite",
    "role",
    "supplied",
    "stored",
    "dissipated",
    "net",
    "activity",
    "share",
];

/// The audit's rows as CSV ([`CSV_COLUMNS`]; full precision), by composite unless `expand`.
#[must_use]
pub fn csv(report: &EnergyReport, expand: bool) -> String {
    let mut s = CSV_COLUMNS.join(",");
    s.push('\n');
    for r in rows(report, expand) {
        let _ = writeln!(
            s,
            "{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e}",
            quote(&r.name),
            quote(&r.kind),
            quote(&r.composite),
            r.role.name(),
            r.supplied,
            r.stored,
            r.dissipated,
            r.net,
            r.activity,
            r.share
        );
    }
    s
}

/// A CSV field, quoted when it holds a comma or a quote.
fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn el(name: &str, role: EnergyRole, net: f64) -> ElementEnergy {
        let (mut supplied, mut stored, mut dissipated) = (0.0, 0.0, 0.0);
        match role {
            EnergyRole::Source => supplied = -net,
            EnergyRole::Storage => stored = net,
            _ => dissipated = net,
        }
        ElementEnergy {
            name: name.into(),
            kind: "k".into(),
            composite: name.into(),
            role,
            supplied,
            stored,
            dissipated,
            net,
            activity: net.abs(),
            share: 0.0,
            through: net.abs(),
            stored_by_function: false,
        }
    }

    #[test]
    fn efficiency_counts_work_against_gravity_and_storage_as_useful() {
        let report = EnergyReport {
            elements: vec![
                el("pump", EnergyRole::Source, -100.0),
                el("gravity", EnergyRole::Source, 30.0),
                el("acc", EnergyRole::Storage, 10.0),
                el("valve", EnergyRole::Dissipation, 60.0),
            ],
            supplied: 70.0,
            stored: 10.0,
            dissipated: 60.0,
            ..EnergyReport::default()
        };
        let e = Efficiency::of(&report);
        for (got, want) in [
            (e.input, 100.0),
            (e.work_on_sources, 30.0),
            (e.useful, 40.0),
        ] {
            assert!((got - want).abs() < 1e-12, "{e:?}");
        }
        assert!((e.efficiency - 0.4).abs() < 1e-15);
        let t = text(&report, true);
        assert!(t.contains("40.0 %"), "{t}");
        let c = csv(&report, false);
        assert_eq!(c.lines().count(), 5, "{c}");
        assert!(c.starts_with("name,kind,composite,role,"), "{c}");
    }
}
