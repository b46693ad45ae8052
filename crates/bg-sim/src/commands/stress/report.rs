//! The reports of `bg-sim stress`: the fixed JSON shape, the CSV (one row per link and
//! section) and the text tables.

use std::fmt::Write as _;

use serde_json::{json, Value};

use super::{CylinderPeaks, HotFatigue, LinkEnvelope, QUANTITIES};

fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// The JSON report; with `fatigue` (`--fatigue` given) each `hot_spot` has a `fatigue` key.
pub(super) fn json_report(links: &[LinkEnvelope], cyl: &[CylinderPeaks], fatigue: bool) -> Value {
    let arr = |v: &[f64]| Value::Array(v.iter().map(|x| num(*x)).collect());
    let links: Vec<Value> = links
        .iter()
        .map(|l| {
            let mut o = serde_json::Map::new();
            o.insert("link".into(), json!(l.link));
            o.insert("x".into(), arr(&l.x));
            for (q, e) in QUANTITIES.iter().zip(&l.env) {
                o.insert(
                    (*q).into(),
                    json!({"max": arr(&e.max), "min": arr(&e.min), "t_max": arr(&e.t_max), "t_min": arr(&e.t_min)}),
                );
            }
            let mut hot = match &l.hot {
                Some((j, t, s, _)) => json!({"x": l.x[*j], "t": t, "sigma": s}),
                None => json!({"x": null, "t": null, "sigma": null}),
            };
            if fatigue {
                hot["fatigue"] = l.fatigue.as_ref().map_or(Value::Null, HotFatigue::json);
            }
            o.insert("hot_spot".into(), hot);
            Value::Object(o)
        })
        .collect();
    let cylinders: Vec<Value> = cyl
        .iter()
        .map(|c| {
            json!({"name": c.name, "p_max": num(c.p_max), "force_push_max": num(c.push),
                   "force_pull_max": num(c.pull), "buckling_margin": c.margin.map_or(Value::Null, num)})
        })
        .collect();
    json!({"links": links, "cylinders": cylinders})
}

pub(super) fn csv_report(links: &[LinkEnvelope]) -> String {
    let mut s = String::from("arm,link,x");
    for q in QUANTITIES {
        let _ = write!(s, ",{q}_max,{q}_t_max,{q}_min,{q}_t_min");
    }
    s.push('\n');
    for l in links {
        for (j, x) in l.x.iter().enumerate() {
            let _ = write!(s, "{},{},{x}", l.arm, l.link);
            for e in &l.env {
                let _ = write!(
                    s,
                    ",{},{},{},{}",
                    e.max[j], e.t_max[j], e.min[j], e.t_min[j]
                );
            }
            s.push('\n');
        }
    }
    s
}

pub(super) fn text_report(links: &[LinkEnvelope], cyl: &[CylinderPeaks]) -> String {
    let mut s = String::new();
    for l in links {
        let _ = writeln!(
            s,
            "{} link {}: {} sections, x = 0 … {} m",
            l.arm,
            l.link,
            l.x.len(),
            l.x.last().copied().unwrap_or(0.0)
        );
        let units = [
            ("N", 1e-3, "kN"),
            ("V", 1e-3, "kN"),
            ("M", 1e-3, "kN·m"),
            ("sigma_top", 1e-6, "MPa"),
            ("sigma_bottom", 1e-6, "MPa"),
        ];
        for ((q, scale, unit), e) in units.iter().zip(&l.env) {
            if q.starts_with("sigma") && !l.has_sigma {
                continue;
            }
            let (jmax, jmin) = (argmax(&e.max), argmin(&e.min));
            let _ = writeln!(
                s,
                "  {q:<13} max {:>10.3} {unit} at x = {:.3} m, t = {:.3} s;  min {:>10.3} {unit} at x = {:.3} m, t = {:.3} s",
                e.max[jmax] * scale, l.x[jmax], e.t_max[jmax], e.min[jmin] * scale, l.x[jmin], e.t_min[jmin]
            );
        }
        if let Some((j, t, sg, _)) = &l.hot {
            let _ = writeln!(
                s,
                "  hot spot: σ = {:.3} MPa at x = {:.3} m, t = {t:.3} s",
                sg * 1e-6,
                l.x[*j]
            );
        }
        if let Some(f) = &l.fatigue {
            let _ = writeln!(s, "{}", f.text());
        }
    }
    for c in cyl {
        let _ = writeln!(
            s,
            "cylinder {}: p_max {:.3} MPa, push {:.1} kN, pull {:.1} kN, buckling margin {}",
            c.name,
            c.p_max * 1e-6,
            c.push * 1e-3,
            c.pull * 1e-3,
            c.margin.map_or_else(
                || "not declared".to_owned(),
                |m| format!("{m:.3} (smallest of the run)")
            )
        );
    }
    s
}

fn argmax(v: &[f64]) -> usize {
    (0..v.len()).fold(0, |b, j| if v[j] > v[b] { j } else { b })
}
fn argmin(v: &[f64]) -> usize {
    (0..v.len()).fold(0, |b, j| if v[j] < v[b] { j } else { b })
}
