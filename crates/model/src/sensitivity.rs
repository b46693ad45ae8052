//! [`Model::sensitivities`]: one run with the forward sensitivities of its `[outputs]`
//! columns to chosen parameters (docs/sensitivity.md).
//!
//! A parameter is named as a `--set` key: `beta` or `parameters.beta` (a `[parameters]`
//! entry; everything derived from it follows, `A_p = "pi/4*d_p^2"` included, and so does a
//! steady start `[initial.steady]`), `elements.cyl1.beta` (one element's value, as written
//! in the file), `initial.NAME` (an initial state). For each, a twin of the model is built
//! from the file's text with that one value moved by h (`bondgraph::sensitivity`): its
//! initial state gives ∂x0/∂p (through the steady solve, derived parameters and all), its
//! right-hand side ∂f/∂p at each stage point of each step, its outputs ∂y/∂p.

use bondgraph::sensitivity::{param_step, simulate_sensitivities, Perturbation};

use crate::error::{ErrorKind, ModelError};
use crate::Model;

/// Forward sensitivities of a run's `[outputs]` columns to chosen parameters.
#[derive(Clone, Debug, Default)]
pub struct Sensitivities {
    /// The names as given (the grammar of `--set` keys).
    pub params: Vec<String>,
    /// The parameter values the run used (SI).
    pub values: Vec<f64>,
    /// The `[outputs]` column names, without `t`, in CSV order.
    pub outputs: Vec<String>,
    /// Times of the output rows.
    pub t: Vec<f64>,
    /// Outputs, row-major: `y[row * outputs.len() + j]`.
    pub y: Vec<f64>,
    /// Row-major: `dy_dp[(row * outputs.len() + j) * params.len() + k]`.
    pub dy_dp: Vec<f64>,
    /// Accepted solver steps.
    pub steps: usize,
}

impl Sensitivities {
    /// dy_j/dp_k at row `row`.
    #[must_use]
    pub fn get(&self, row: usize, j: usize, k: usize) -> f64 {
        self.dy_dp[(row * self.outputs.len() + j) * self.params.len() + k]
    }
}

/// A parameter name resolved: the `--set` key to move it by, its value, whether it is an
/// initial state (∂f/∂p = 0).
struct Resolved {
    key: String,
    value: f64,
    initial: bool,
}

fn unknown(model: &Model, _name: &str, message: String, hint: String) -> ModelError {
    ModelError::new(ErrorKind::Override, model.file(), message).hint(hint)
}

/// The value of `elements.E.K` as written in the file (a number or an expression of the
/// `[parameters]`).
fn element_value(model: &Model, entry: &str, key: &str, name: &str) -> Result<f64, ModelError> {
    let (text, _) = model.text_and_registry();
    let doc: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        ModelError::new(ErrorKind::Syntax, model.file(), e.to_string())
    })?;
    let elements = doc.get("elements").and_then(toml::Value::as_table);
    let Some(el) = elements
        .and_then(|t| t.get(entry))
        .and_then(toml::Value::as_table)
    else {
        let names: Vec<&str> = elements
            .map(|t| t.keys().map(String::as_str).collect())
            .unwrap_or_default();
        let hint = match bondgraph::kind::suggest(entry, names.iter().copied()) {
            Some(c) => format!("did you mean `elements.{c}.{key}`?"),
            None => format!("the model's elements: {}", names.join(", ")),
        };
        return Err(unknown(
            model,
            name,
            format!("sensitivity to `{name}`: no element `{entry}`"),
            hint,
        ));
    };
    let lookup = |n: &str| model.parameters.get(n).copied();
    match el.get(key) {
        Some(toml::Value::Float(v)) => Ok(*v),
        Some(toml::Value::Integer(v)) => Ok(*v as f64),
        Some(toml::Value::String(s)) => crate::expr::Expr::parse(s)
            .map_err(|e| e.to_string())
            .and_then(|e| e.eval(&lookup))
            .map_err(|m| {
                unknown(
                    model,
                    name,
                    format!("sensitivity to `{name}`: `{s}` is not a constant: {m}"),
                    "only constant values (numbers, expressions of [parameters]) have a sensitivity".into(),
                )
            }),
        Some(_) => Err(unknown(
            model,
            name,
            format!("sensitivity to `{name}`: not a number"),
            "name a scalar value".into(),
        )),
        None => {
            let keys: Vec<&str> = el.keys().map(String::as_str).collect();
            let hint = match bondgraph::kind::suggest(key, keys.iter().copied()) {
                Some(c) => format!("did you mean `elements.{entry}.{c}`?"),
                None => format!(
                    "`{key}` is not written in the file (a default): write it there to vary it; written: {}",
                    keys.join(", ")
                ),
            };
            Err(unknown(
                model,
                name,
                format!("sensitivity to `{name}`: `{entry}` has no `{key}`"),
                hint,
            ))
        }
    }
}

fn resolve(model: &Model, name: &str) -> Result<Resolved, ModelError> {
    let trimmed = name.trim();
    let params_hint = |p: &str| {
        match bondgraph::kind::suggest(p, model.parameters.keys().map(String::as_str)) {
        Some(c) => format!("did you mean `{c}`?"),
        None => format!(
            "parameters are named as `--set` keys: a [parameters] entry ({}), `elements.NAME.KEY`, `initial.STATE`",
            model.parameters.keys().take(12).cloned().collect::<Vec<_>>().join(", ")
        ),
    }
    };
    if let Some(state) = trimmed.strip_prefix("initial.") {
        let state = state.trim_matches('"');
        let Some(i) = model
            .equations
            .states()
            .iter()
            .position(|s| s.name == state)
        else {
            let names: Vec<String> = model
                .equations
                .states()
                .iter()
                .map(|s| s.name.clone())
                .collect();
            let hint = match bondgraph::kind::suggest(state, names.iter().map(String::as_str)) {
                Some(c) => format!("did you mean `initial.{c}`?"),
                None => format!("the states: {}", names.join(", ")),
            };
            return Err(unknown(
                model,
                name,
                format!("sensitivity to `{name}`: no state `{state}`"),
                hint,
            ));
        };
        return Ok(Resolved {
            key: format!("initial.\"{state}\""),
            value: model.x0[i],
            initial: true,
        });
    }
    if let Some(rest) = trimmed.strip_prefix("elements.") {
        let Some((entry, key)) = rest.split_once('.') else {
            return Err(unknown(
                model,
                name,
                format!("sensitivity to `{name}`: expected `elements.NAME.KEY`"),
                "e.g. elements.cyl1.beta".into(),
            ));
        };
        let value = element_value(model, entry, key, name)?;
        return Ok(Resolved {
            key: format!("elements.{entry}.{key}"),
            value,
            initial: false,
        });
    }
    let p = trimmed.strip_prefix("parameters.").unwrap_or(trimmed);
    match model.parameters.get(p) {
        Some(&value) => Ok(Resolved {
            key: format!("parameters.{p}"),
            value,
            initial: false,
        }),
        None => Err(unknown(
            model,
            name,
            format!("sensitivity to `{name}`: not a parameter of the model"),
            params_hint(p),
        )),
    }
}

impl Model {
    /// Runs the model once with its settings, integrating the sensitivity equations of the
    /// chosen parameters with it (Radau, whatever `[simulation] solver` says), and returns
    /// the `[outputs]` columns and their sensitivities at the output times. The elements
    /// events replace are restored afterwards, as after [`Model::run`].
    ///
    /// # Errors
    /// An unknown parameter (with a "did you mean"), a twin that does not build with the
    /// moved value (its error), the run's failure.
    pub fn sensitivities(&mut self, params: &[String]) -> Result<Sensitivities, ModelError> {
        let resolved: Vec<Resolved> = params
            .iter()
            .map(|p| resolve(self, p))
            .collect::<Result<_, _>>()?;
        let n = self.equations.n_states();
        let np = resolved.len();
        let mut s0 = vec![0.0; n * np];
        let mut twins = Vec::with_capacity(np);
        for (k, r) in resolved.iter().enumerate() {
            let h = param_step(r.value);
            let moved = r.value + h;
            let (text, registry) = self.text_and_registry();
            let set = vec![format!("{}={moved:?}", r.key)];
            let twin = Model::from_text(self.file(), text, registry, &set).map_err(|e| {
                let msg = format!(
                    "sensitivity to `{}`: the model does not build with {} = {moved:?}: {}",
                    params[k], r.key, e.message
                );
                ModelError::new(ErrorKind::Override, self.file(), msg)
            })?;
            if twin.equations.n_states() != n {
                return Err(ModelError::new(
                    ErrorKind::Override,
                    self.file(),
                    format!(
                        "sensitivity to `{}`: the model's states change with it ({} → {})",
                        params[k],
                        n,
                        twin.equations.n_states()
                    ),
                )
                .hint("a parameter that sets a count (modes, segments) has no sensitivity"));
            }
            for i in 0..n {
                s0[k * n + i] = (twin.x0[i] - self.x0[i]) / h;
            }
            // The inputs as the model has them (data from --inputs included).
            for i in 0..self.equations.n_inputs() {
                let series = self.equations.input_series(i).ok().flatten();
                let res = match series {
                    Some(s) => twin.equations.set_input_series(i, s),
                    None => self
                        .equations
                        .input_value(i, self.settings.t_start)
                        .and_then(|v| twin.equations.set_input(i, v)),
                };
                res.map_err(|e| ModelError::new(ErrorKind::Settings, self.file(), e.message()))?;
            }
            let events = twin.events()?;
            twins.push(Perturbation {
                eqs: twin.equations,
                h,
                events,
                rhs_free: r.initial,
            });
        }
        let events = self.events()?;
        let result = simulate_sensitivities(
            &mut self.equations,
            &self.x0,
            &s0,
            &self.settings,
            &self.outputs,
            events,
            &mut twins,
        );
        self.restore_event_entries()?;
        let run = result.map_err(|e| {
            ModelError::new(
                ErrorKind::Settings,
                self.file(),
                format!("sensitivity run: {}", e.message()),
            )
        })?;
        Ok(Sensitivities {
            params: params.to_vec(),
            values: resolved.iter().map(|r| r.value).collect(),
            outputs: self.outputs.iter().map(|o| o.name.clone()).collect(),
            t: run.t,
            y: run.y,
            dy_dp: run.dy_dp,
            steps: run.steps,
        })
    }
}
