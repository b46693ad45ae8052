//! Inputs with known time derivatives: a sea state (`[inputs] z = { sea = { … } }`) and
//! data interpolated by a spline (`interp = "spline"`). Each becomes a [`Motion`]: the
//! input follows it, and expressions that need exact derivatives of their inputs (a
//! position source, a moving base: [`bondgraph::kind::Params::motion`]) read it.
//!
//! ```toml
//! [inputs]
//! z_b = { sea = { hs = 2.5, tp = 9, seed = 7, rao = "rao.csv", dof = "heave" } }
//! ```
//!
//! Keys of `sea` (numbers may be expressions of `[parameters]`): `hs` [m] and `tp` [s]
//! (required), `spectrum` ("jonswap", the default, or "pm"), `gamma` (3.3), `seed` (0),
//! `duration` (3600 s: the record's length, which sets its frequency resolution and
//! number of components), `dt` (0.1 s: its sampling step, which caps the frequencies at
//! Nyquist), `rao` (an RAO CSV, relative to the model file), `heading` [deg] (0), `dof`
//! ("elevation", the default without `rao`; "heave", the default with it; "sway", "roll"
//! in rad), and the point `x`, `y`, `z` [m] of the vessel whose motion it is (0).

use std::sync::Arc;

use bg_ocean::{Dof, Point, Rao, Spectrum, VesselMotion, WaveRecord};
use bondgraph::{Interp, Motion};
use indexmap::IndexMap;

use super::inputs::relative;
use super::source::Source;
use crate::data::DataFile;
use crate::error::{clip, ModelError};
use crate::expr::Expr;

const KEYS: &[&str] = &[
    "hs", "tp", "spectrum", "gamma", "seed", "duration", "dt", "rao", "heading", "dof", "x",
    "y", "z",
];

/// The motion of the sea input `name` from its `sea` table; `err` makes an error at the
/// entry.
pub(super) fn motion(
    name: &str,
    value: &toml::Value,
    source: &Source,
    parameters: &IndexMap<String, f64>,
    err: &dyn Fn(String) -> ModelError,
) -> Result<Motion, ModelError> {
    let example = "write `sea = { hs = 2.5, tp = 9, seed = 7 }`";
    let toml::Value::Table(table) = value else {
        return Err(err(format!("`sea` of input `{name}` must be a table")).hint(example));
    };
    for k in table.keys() {
        if !KEYS.contains(&k.as_str()) {
            let close = bondgraph::kind::suggest(k, KEYS.iter().copied());
            return Err(err(format!("`sea` of input `{name}` has no key `{}`", clip(k))).hint(
                match close {
                    Some(c) => format!("did you mean `{c}`? keys: {}", KEYS.join(", ")),
                    None => format!("keys: {}", KEYS.join(", ")),
                },
            ));
        }
    }
    let number = |key: &str, default: Option<f64>| -> Result<f64, ModelError> {
        let x = match table.get(key) {
            None => {
                return default.ok_or_else(|| {
                    err(format!("`sea` of input `{name}` needs `{key}`")).hint(example)
                })
            }
            Some(toml::Value::Float(x)) => *x,
            Some(toml::Value::Integer(i)) => *i as f64,
            Some(toml::Value::String(s)) => Expr::parse(s)
                .map_err(|e| err(format!("`sea.{key}` of input `{name}`: {e}")))?
                .eval(&|n| parameters.get(n).copied())
                .map_err(|m| {
                    err(format!("`sea.{key}` of input `{name}`: {m}"))
                        .hint("a number or an expression of [parameters]")
                })?,
            Some(_) => return Err(err(format!("`sea.{key}` of input `{name}` must be a number"))),
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(err(format!("`sea.{key}` of input `{name}` is {x}, not finite")))
        }
    };
    let text = |key: &str| -> Result<Option<String>, ModelError> {
        match table.get(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s.clone())),
            Some(_) => Err(err(format!("`sea.{key}` of input `{name}` must be a string"))),
        }
    };
    let ocean = |e: bg_ocean::OceanError| {
        let mut m = err(format!("`sea` of input `{name}`: {}", e.message));
        if !e.hint.is_empty() {
            m = m.hint(e.hint);
        }
        m
    };
    let (hs, tp) = (number("hs", None)?, number("tp", None)?);
    let spectrum = match text("spectrum")?.as_deref() {
        None | Some("jonswap") => Spectrum::jonswap(hs, tp, number("gamma", Some(3.3))?),
        Some("pm") => {
            if table.contains_key("gamma") {
                return Err(err(format!("`sea` of input `{name}` gives `gamma` to a Pierson–Moskowitz spectrum"))
                    .hint("drop `gamma`, or write spectrum = \"jonswap\""));
            }
            Spectrum::pierson_moskowitz(hs, tp)
        }
        Some(s) => {
            return Err(err(format!("`sea.spectrum` of input `{name}` is `{}`", clip(s)))
                .hint("`spectrum` is \"jonswap\" (the default) or \"pm\""))
        }
    }
    .map_err(ocean)?;
    let seed = number("seed", Some(0.0))?;
    if seed < 0.0 || seed.fract() != 0.0 || seed > 9.0e15 {
        return Err(err(format!("`sea.seed` of input `{name}` = {seed} must be a whole number ≥ 0")));
    }
    let record = WaveRecord::irregular(
        spectrum,
        number("duration", Some(3600.0))?,
        number("dt", Some(0.1))?,
        seed as u64,
    )
    .map_err(ocean)?;
    let rao = match text("rao")? {
        None => None,
        Some(file) => {
            let path = relative(&source.file, &file);
            Some(Rao::read(&path).map_err(|e| {
                let mut m = err(format!(
                    "`sea.rao` of input `{name}`: {}{}",
                    e.line.map(|l| format!("{}:{l}: ", path.display())).unwrap_or_default(),
                    e.message
                ));
                if !e.hint.is_empty() {
                    m = m.hint(e.hint);
                }
                m
            })?)
        }
    };
    let dof = match text("dof")? {
        None if rao.is_some() => Dof::Heave,
        None => Dof::Elevation,
        Some(s) => Dof::parse(&s).ok_or_else(|| {
            err(format!("`sea.dof` of input `{name}` is `{}`", clip(&s)))
                .hint("`dof` is \"elevation\", \"heave\", \"sway\" or \"roll\"")
        })?,
    };
    let point = Point {
        x: number("x", Some(0.0))?,
        y: number("y", Some(0.0))?,
        z: number("z", Some(0.0))?,
    };
    let heading = number("heading", Some(0.0))?;
    let series = match (&rao, dof) {
        (_, Dof::Elevation) => record.harmonics().clone(),
        (Some(r), d) => VesselMotion::new(&record, r, heading, point).series(d).clone(),
        (None, d) => {
            return Err(err(format!(
                "input `{name}` asks for the vessel's {} but gives no `rao`",
                d.name()
            ))
            .hint("add `rao = \"data/rao_supply_vessel.csv\"` (its path relative to the model), or dof = \"elevation\""))
        }
    };
    let series = Arc::new(series);
    Ok(Motion::law(move |t| {
        let (x, v, a) = series.eval(t);
        [x, v, a]
    }))
}

/// The motion of a data input interpolated by a spline, or `None` if the file cannot be
/// read now (the input's own reading reports that).
pub(super) fn spline(source: &Source, file: &str, column: &str, interp: Interp) -> Option<Motion> {
    if interp != Interp::Spline {
        return None;
    }
    let path = relative(&source.file, file);
    let data = DataFile::read(&path, &path.display().to_string()).ok()?;
    let k = data.column(column)?;
    let series = Arc::new(data.series(k, interp).ok()?);
    Some(Motion::law(move |t| series.jet(t)))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use crate::Model;

    #[test]
    fn a_sea_input_follows_the_wave_record_and_its_derivatives_are_exact() {
        let text = r#"
[parameters]
H = 2.5
[inputs]
eta = { sea = { hs = "H", tp = 9, seed = 7, duration = 600 } }
[elements]
m = { kind = "I", m = 1.0 }
f = { kind = "Se", e = "eta" }
[bonds]
b = "f -> m"
[simulation]
t_end = 1.0
"#;
        let model = Model::from_text("sea.toml", text, &crate::Registry::with_core(), &[]).unwrap();
        let eqs = &model.equations;
        let i = eqs.input_index("eta").unwrap();
        let rec = bg_ocean::WaveRecord::irregular(
            bg_ocean::Spectrum::jonswap(2.5, 9.0, 3.3).unwrap(),
            600.0,
            0.1,
            7,
        )
        .unwrap();
        for t in [0.0, 3.7, 40.0] {
            assert_eq!(eqs.input_value(i, t).unwrap(), rec.eval(t).0);
        }
    }

    #[test]
    fn bad_sea_tables_are_refused_at_the_entry_with_a_hint() {
        for (sea, want) in [
            ("{ hs = 2.5 }", "needs `tp`"),
            ("{ hs = 2.5, tp = 9, sead = 1 }", "did you mean `seed`"),
            ("{ hs = 2.5, tp = 9, dof = \"heave\" }", "gives no `rao`"),
            ("{ hs = 2.5, tp = 9, rao = \"nowhere.csv\" }", "cannot read"),
            ("{ hs = -1, tp = 9 }", "Hs"),
            ("{ hs = 2.5, tp = 9, spectrum = \"pm\", gamma = 2 }", "Pierson"),
        ] {
            let text = format!(
                "[inputs]\neta = {{ sea = {sea} }}\n[elements]\nm = {{ kind = \"I\", m = 1.0 }}\nf = {{ kind = \"Se\", e = \"eta\" }}\n[bonds]\nb = \"f -> m\"\n"
            );
            let e = Model::from_text("sea.toml", &text, &crate::Registry::with_core(), &[]).unwrap_err().to_string();
            assert!(e.contains(want), "{sea}: {e}");
            assert!(e.contains("sea.toml:2"), "{sea}: {e}");
        }
    }
}
