//! [`Model::linearize`]: the model's linear model (A, B, C, D) at its start or at a time of a
//! run, inputs and outputs named as in the model file ([`bondgraph::linearize`]).

use bondgraph::{Linearization, Output, Probe, RowSink, StateEquations};

use super::model::Model;
use super::stepping::{request_error, resolve};
use crate::error::ModelError;

/// A row sink that keeps nothing (only the run's final state is wanted).
struct Discard;

impl RowSink for Discard {
    fn row(&mut self, _row: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

/// The signal offset of the input called `name`.
fn input_signal(eqs: &StateEquations, file: &str, name: &str) -> Result<usize, ModelError> {
    eqs.input_index(name)
        .and_then(|i| eqs.input_signal_offset(i))
        .map_err(|e| request_error(file, format!("`{name}` is no input of the model"), e.hint()))
}

/// The named inputs (their signals) and outputs (their probes) of `eqs`.
pub(super) fn names(
    eqs: &StateEquations,
    model_outputs: &[Output],
    file: &str,
    inputs: &[String],
    outputs: &[String],
) -> Result<Signals, ModelError> {
    let ins = inputs
        .iter()
        .map(|n| Ok((n.clone(), input_signal(eqs, file, n)?)))
        .collect::<Result<Vec<_>, ModelError>>()?;
    let outs = outputs
        .iter()
        .map(|n| Ok((n.clone(), resolve(eqs, model_outputs, file, n)?)))
        .collect::<Result<Vec<_>, ModelError>>()?;
    Ok((ins, outs))
}

/// Inputs as (name, signal offset) and outputs as (name, probe).
type Signals = (Vec<(String, usize)>, Vec<(String, Probe)>);

/// Linearise `eqs` at (t, x) for the named inputs and outputs.
pub(super) fn linearize_at(
    eqs: &StateEquations,
    model_outputs: &[Output],
    file: &str,
    t: f64,
    x: &[f64],
    inputs: &[String],
    outputs: &[String],
) -> Result<Linearization, ModelError> {
    let (ins, outs) = names(eqs, model_outputs, file, inputs, outputs)?;
    bondgraph::linearize(eqs, t, x, &ins, &outs).map_err(|e| {
        request_error(
            file,
            format!("cannot linearise at t = {t} s: {e}"),
            Some("linearise at another time (--at) or state".to_owned()),
        )
    })
}

impl Model {
    /// Check that the model has these inputs and outputs (what [`Model::linearize`] checks
    /// first, before any run).
    ///
    /// # Errors
    /// The first unknown name, with "did you mean".
    pub fn check_linear_names(
        &self,
        inputs: &[String],
        outputs: &[String],
    ) -> Result<(), ModelError> {
        names(
            &self.equations,
            &self.outputs,
            &self.source.file,
            inputs,
            outputs,
        )
        .map(|_| ())
    }

    /// The model linearised at its initial state (`at` = `None` or `t_start`) or at time `at`
    /// of a run (its events up to `at` applied): A = ∂f/∂x, B = ∂f/∂u for the named inputs,
    /// C = ∂y/∂x and D = ∂y/∂u for the named outputs (an `[outputs]` column or any variable),
    /// all exact. The elements an event replaced stay replaced (load the file again to run
    /// it from the start).
    ///
    /// # Errors
    /// An unknown input or output (with "did you mean"), `at` before `t_start`, the run to
    /// `at` failing, a Jacobian entry that is not finite.
    pub fn linearize(
        &mut self,
        at: Option<f64>,
        inputs: &[String],
        outputs: &[String],
    ) -> Result<Linearization, ModelError> {
        self.check_linear_names(inputs, outputs)?;
        let file = self.source.file.clone();
        let t0 = self.settings.t_start;
        let (t, x) = match at {
            Some(t_at) if !t_at.is_finite() || t_at < t0 => {
                return Err(request_error(
                    &file,
                    format!("cannot linearise at t = {t_at} s: the run starts at t_start = {t0} s"),
                    Some(format!("give a time from {t0} s on")),
                ))
            }
            Some(t_at) if t_at > t0 => {
                self.settings.t_end = t_at;
                let (out, _) = self.run_into(&mut Discard)?;
                if let Some(e) = &out.error {
                    return Err(request_error(
                        &file,
                        format!("the run to t = {t_at} s stopped early: {e}"),
                        None,
                    ));
                }
                // the elements as the events left them at t_at
                for ev in self.events()? {
                    if ev.t <= t_at {
                        for (id, el) in ev.replacements {
                            self.equations
                                .replace(id, el)
                                .map_err(|e| request_error(&file, e.message(), e.hint()))?;
                        }
                    }
                }
                (out.t_final, out.x_final)
            }
            _ => {
                for ev in self.events()? {
                    if ev.t <= t0 {
                        for (id, el) in ev.replacements {
                            self.equations
                                .replace(id, el)
                                .map_err(|e| request_error(&file, e.message(), e.hint()))?;
                        }
                    }
                }
                (t0, self.x0.clone())
            }
        };
        linearize_at(
            &self.equations,
            &self.outputs,
            &file,
            t,
            &x,
            inputs,
            outputs,
        )
    }
}
