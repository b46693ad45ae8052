//! `[scene]`: the switches a model declares between richer and cheaper scenes, so that tools
//! (`bg-sim reduce`) can enumerate them.
//!
//! ```toml
//! [scene]
//! modes1 = { set = "parameters.modes1", choices = [10, 5, 3, 0] }
//! lumped = { set = "elements.crane.lumped_model", choices = ["springs", "rigid", "none"],
//!            also = { none = ["parameters.m_extra=0"] } }
//! ```
//!
//! Each switch names one value of the file (`set`, a `--set` key) and its `choices`, from
//! the richest scene to the cheapest; `also` lists further `--set key=value` overrides that go
//! with a choice. A choice is applied as `--set`, so a scene is the file with one override
//! per switch ([`Scene::overrides`]). Everything is checked at load time: unknown keys, empty
//! or repeated choices, and every override (each choice and each `also`) must be one that
//! `--set` accepts on this file.

use std::ops::Range;

use indexmap::IndexMap;
use toml::Spanned;

use crate::error::{clip, ModelError};

/// Longest list of choices of one switch, and most switches in a scene.
pub const MAX_CHOICES: usize = 64;

/// The scene switches of a model, in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The switches.
    pub switches: Vec<Switch>,
}

/// One scene switch: a value of the file and its choices, richest first.
#[derive(Clone, Debug, PartialEq)]
pub struct Switch {
    /// The switch's name (its key in `[scene]`).
    pub name: String,
    /// The `--set` key it changes (`parameters.modes1`).
    pub set: String,
    /// The choices, from the richest scene to the cheapest.
    pub choices: Vec<Choice>,
    /// 1-based line of the switch in the file.
    pub line: usize,
}

/// One choice of a [`Switch`].
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// As shown in tables: `10`, `springs`.
    pub label: String,
    /// As written after `--set key=`: a TOML value (`10`, `"springs"`).
    pub value: String,
    /// Further `--set key=value` overrides that go with this choice.
    pub also: Vec<String>,
}

impl Switch {
    /// The `--set` overrides of choice `k` (the choice itself, then its `also`).
    #[must_use]
    pub fn overrides(&self, k: usize) -> Vec<String> {
        self.choices.get(k).map_or_else(Vec::new, |c| {
            std::iter::once(format!("{}={}", self.set, c.value))
                .chain(c.also.iter().cloned())
                .collect()
        })
    }
}

impl Scene {
    /// Whether the model declares no switch.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.switches.is_empty()
    }

    /// How many scenes the switches span (saturating).
    #[must_use]
    pub fn grid_size(&self) -> usize {
        self.switches
            .iter()
            .fold(1usize, |n, s| n.saturating_mul(s.choices.len()))
    }

    /// The `--set` overrides of the scene that takes choice `pick[i]` of switch `i`
    /// (choices out of range are left out).
    #[must_use]
    pub fn overrides(&self, pick: &[usize]) -> Vec<String> {
        self.switches
            .iter()
            .zip(pick)
            .flat_map(|(s, &k)| s.overrides(k))
            .collect()
    }

    /// `name=label` of each switch, e.g. `modes1=10 lumped=springs`.
    #[must_use]
    pub fn describe(&self, pick: &[usize]) -> String {
        self.switches
            .iter()
            .zip(pick)
            .map(|(s, &k)| {
                let label = s.choices.get(k).map_or("?", |c| c.label.as_str());
                format!("{}={label}", s.name)
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

const KEYS: &[&str] = &["set", "choices", "also"];

/// Read and check `[scene]`. `text` is the file as read (after `--set`); `err` makes an error
/// at a span of it.
pub(crate) fn read(
    file: &str,
    text: &str,
    table: &IndexMap<Spanned<String>, Spanned<toml::Value>>,
    err: &dyn Fn(Option<&Range<usize>>, String) -> ModelError,
) -> Result<Scene, ModelError> {
    if table.len() > MAX_CHOICES {
        return Err(err(
            table.first().map(|(k, _)| k.span()).as_ref(),
            format!(
                "[scene] has {} switches, more than {MAX_CHOICES}",
                table.len()
            ),
        ));
    }
    let mut switches = Vec::new();
    // parsed once for the checks of every choice's overrides below
    let doc: toml_edit::DocumentMut = match text.parse() {
        Ok(d) => d,
        Err(e) => {
            let e: toml_edit::TomlError = e;
            // an integer past i64 has no span from the parser: find it
            let at = e
                .span()
                .or_else(|| crate::error::too_large_integer(text).map(|a| a..a + 1));
            return Err(err(at.as_ref(), e.message().to_owned()));
        }
    };
    for (name, v) in table {
        let span = name.span();
        let fail = |m: String, hint: &str| {
            let e = err(
                Some(&span),
                format!("[scene] `{}`: {m}", clip(name.get_ref())),
            );
            if hint.is_empty() {
                e
            } else {
                e.hint(hint)
            }
        };
        let example = "write e.g. `modes = { set = \"parameters.modes\", choices = [10, 5, 0] }` (choices from the richest scene to the cheapest); see docs/model-format.md";
        let toml::Value::Table(t) = v.get_ref() else {
            return Err(fail("must be a table".into(), example));
        };
        if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return Err(fail(
                format!("unknown key `{}`", clip(k)),
                "a switch has the keys set, choices and also",
            ));
        }
        let set = match t.get("set") {
            Some(toml::Value::String(s)) if !s.trim().is_empty() => s.trim().to_owned(),
            Some(_) => {
                return Err(fail(
                    "`set` must be a `--set` key such as \"parameters.modes1\"".into(),
                    example,
                ))
            }
            None => return Err(fail("has no `set`".into(), example)),
        };
        if set.split('.').next().map(str::trim) == Some("scene") {
            return Err(fail(
                "`set` cannot change [scene] itself".into(),
                "name a parameter or an element option",
            ));
        }
        let list = match t.get("choices") {
            Some(toml::Value::Array(a)) => a,
            Some(_) => return Err(fail("`choices` must be a list".into(), example)),
            None => return Err(fail("has no `choices`".into(), example)),
        };
        if list.is_empty() {
            return Err(fail("`choices` is empty".into(), example));
        }
        if list.len() > MAX_CHOICES {
            return Err(fail(
                format!("{} choices, more than {MAX_CHOICES}", list.len()),
                "",
            ));
        }
        let mut choices: Vec<Choice> = Vec::new();
        for c in list {
            let label = match c {
                toml::Value::String(s) => s.clone(),
                // 1e5 rather than 100000.0; still a TOML float, so also its `--set` value
                toml::Value::Float(x)
                    if x.is_finite() && *x != 0.0 && !(1e-3..1e4).contains(&x.abs()) =>
                {
                    format!("{x:e}")
                }
                toml::Value::Integer(_) | toml::Value::Float(_) | toml::Value::Boolean(_) => {
                    c.to_string()
                }
                _ => {
                    return Err(fail(
                        format!(
                            "choice `{}` must be a number, a string or a boolean",
                            clip(&c.to_string())
                        ),
                        "",
                    ))
                }
            };
            if let toml::Value::Float(x) = c {
                if !x.is_finite() {
                    return Err(fail(format!("choice `{label}` is not finite"), ""));
                }
            }
            if choices.iter().any(|d| d.label == label) {
                return Err(fail(
                    format!("choice `{}` is listed twice", clip(&label)),
                    "",
                ));
            }
            let value = match c {
                toml::Value::Float(_) if label.contains('e') => label.clone(),
                _ => c.to_string(),
            };
            choices.push(Choice {
                label,
                value,
                also: Vec::new(),
            });
        }
        match t.get("also") {
            None => {}
            Some(toml::Value::Table(also)) => {
                for (k, list) in also {
                    let Some(c) = choices.iter_mut().find(|c| &c.label == k) else {
                        let labels: Vec<&str> = choices.iter().map(|c| c.label.as_str()).collect();
                        return Err(fail(
                            format!("`also` names `{}`, which is not a choice", clip(k)),
                            &format!("the choices are: {}", labels.join(", ")),
                        ));
                    };
                    let toml::Value::Array(list) = list else {
                        return Err(fail(
                            format!("`also.{}` must be a list of \"key=value\" strings", clip(k)),
                            "e.g. also = { none = [\"parameters.m_extra=0\"] }",
                        ));
                    };
                    for o in list {
                        match o {
                            toml::Value::String(s) if s.contains('=') => c.also.push(s.clone()),
                            _ => {
                                return Err(fail(
                                    format!(
                                        "`also.{}`: `{}` is not a \"key=value\" string",
                                        clip(k),
                                        clip(&o.to_string())
                                    ),
                                    "e.g. also = { none = [\"parameters.m_extra=0\"] }",
                                ))
                            }
                        }
                    }
                }
            }
            Some(_) => {
                return Err(fail(
                    "`also` must be a table: choice = [\"key=value\", ...]".into(),
                    "e.g. also = { none = [\"parameters.m_extra=0\"] }",
                ))
            }
        }
        let line = crate::error::line_col(text, span.start).0;
        let switch = Switch {
            name: name.get_ref().clone(),
            set,
            choices,
            line,
        };
        // every override of every choice must be one that `--set` accepts on this file
        for k in 0..switch.choices.len() {
            for o in switch.overrides(k) {
                if let Err(e) = crate::overrides::check(file, &doc, &o) {
                    let why = e.message.clone();
                    let hint = e.hint.clone().unwrap_or_else(|| {
                        "`set` and `also` take the keys of `--set`: parameters.NAME, elements.NAME.OPTION, …".into()
                    });
                    return Err(fail(
                        format!("choice `{}`: {why}", switch.choices[k].label),
                        &hint,
                    ));
                }
            }
        }
        switches.push(switch);
    }
    Ok(Scene { switches })
}
