//! The model's external inputs ([`Input`] elements) seen from outside: list them, set them
//! by index or name (held from then on), give them time series, read their breakpoints, and
//! find where their values live in the plan (for derivatives with respect to inputs).
//!
//! This is the API a program driving the model uses (a stepping loop, a controller, the
//! CLI's `--inputs`); it is stable: new needs add functions, they do not change these.
//! Setting an input between solver steps changes the right-hand side from then on; a
//! caller that keeps a solver running across such a change restarts it when the change is
//! discontinuous (a new value, a new series), as `simulate` does at breakpoints.

use crate::bond::ElementId;
use crate::elements::{Input, InputSpec, Series};
use crate::equations::Probe;
use crate::error::GraphError;
use crate::kind::suggest;

use super::StateEquations;

impl StateEquations {
    /// Number of external inputs.
    #[must_use]
    pub fn n_inputs(&self) -> usize {
        self.inputs.len()
    }

    /// The external inputs, in order (their index is the one every other input function
    /// takes): name, unit, default, description.
    #[must_use]
    pub fn inputs(&self) -> Vec<InputSpec> {
        (0..self.inputs.len())
            .filter_map(|i| self.input(i).map(|u| u.spec().clone()))
            .collect()
    }

    /// The index of the input called `name`.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] with the near miss ("did you mean") or the inputs there
    /// are.
    pub fn input_index(&self, name: &str) -> Result<usize, GraphError> {
        self.inputs
            .iter()
            .position(|&id| self.graph.node(id).name == name)
            .ok_or_else(|| self.unknown_input(name))
    }

    fn unknown_input(&self, name: &str) -> GraphError {
        let names: Vec<&str> = self
            .inputs
            .iter()
            .map(|&id| self.graph.node(id).name.as_str())
            .collect();
        let hint = if names.is_empty() {
            "the model declares no inputs: add them in its [inputs] table".to_owned()
        } else if let Some(s) = suggest(name, names.iter().copied()) {
            format!("did you mean `{s}`? inputs: {}", names.join(", "))
        } else {
            format!("inputs: {}", names.join(", "))
        };
        GraphError::UnknownInput {
            name: name.to_owned(),
            hint,
        }
    }

    fn checked(&self, i: usize) -> Result<&Input, GraphError> {
        self.input(i)
            .ok_or_else(|| self.unknown_input(&format!("#{i}")))
    }

    /// Input `i`, if `i` < [`n_inputs`](Self::n_inputs).
    fn input(&self, i: usize) -> Option<&Input> {
        self.graph.node(*self.inputs.get(i)?).element.as_input()
    }

    /// Hold input `i` at `value` from now on (replacing a series it followed).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn set_input(&self, i: usize, value: f64) -> Result<(), GraphError> {
        self.checked(i)?.set(value);
        Ok(())
    }

    /// Hold the input called `name` at `value` from now on.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`], with "did you mean".
    pub fn set_input_by_name(&self, name: &str, value: f64) -> Result<(), GraphError> {
        self.set_input(self.input_index(name)?, value)
    }

    /// Make input `i` follow `series` (times, values, linear or hold; see [`Series`]) from
    /// now on.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn set_input_series(&self, i: usize, series: Series) -> Result<(), GraphError> {
        self.checked(i)?.set_series(series);
        Ok(())
    }

    /// Put input `i` back to its default value.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn reset_input(&self, i: usize) -> Result<(), GraphError> {
        let u = self.checked(i)?;
        u.set(u.spec().default);
        Ok(())
    }

    /// The value of input `i` at time `t` (as the plan would evaluate it).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_value(&self, i: usize, t: f64) -> Result<f64, GraphError> {
        Ok(self.checked(i)?.value(t))
    }

    /// The series input `i` follows, if any (its [`Series::times`] are its breakpoints).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_series(&self, i: usize) -> Result<Option<Series>, GraphError> {
        Ok(self.checked(i)?.series())
    }

    /// The breakpoints of input `i` (its series' sample times; none for a held value).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_breakpoints(&self, i: usize) -> Result<Vec<f64>, GraphError> {
        Ok(self
            .checked(i)?
            .series()
            .map(|s| s.times().to_vec())
            .unwrap_or_default())
    }

    /// The first breakpoint of any input strictly after `t` (beyond the time tolerance), or
    /// `None` if there is none or stops at breakpoints are off.
    #[must_use]
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        if !self.stop_at_breakpoints {
            return None;
        }
        (0..self.inputs.len())
            .filter_map(|i| self.input(i)?.next_breakpoint(t))
            .reduce(f64::min)
    }

    /// Whether a run stops and restarts at the inputs' breakpoints (default `true`). Turn it
    /// off for dense data (a 10 kHz recording): the solver then steps over the samples'
    /// corners and its error control alone deals with them.
    pub fn set_stop_at_breakpoints(&mut self, on: bool) {
        self.stop_at_breakpoints = on;
    }

    /// See [`set_stop_at_breakpoints`](Self::set_stop_at_breakpoints).
    #[must_use]
    pub fn stops_at_breakpoints(&self) -> bool {
        self.stop_at_breakpoints
    }

    /// Start a segment of a run at `t` that ends at the next breakpoint at the latest: with
    /// stops at breakpoints on, every series is evaluated on the piece holding `t` until the
    /// next call (so no step sees a corner); off, every evaluation looks its time up.
    /// `simulate` calls it at the start of every segment; a stepping loop does the same.
    pub fn begin_segment(&self, t: f64) {
        for u in (0..self.inputs.len()).filter_map(|i| self.input(i)) {
            if self.stop_at_breakpoints {
                u.lock_at(t);
            } else {
                u.unlock();
            }
        }
    }

    /// End the segments of a run: every series is looked up by time again (`simulate` calls
    /// it when the run ends).
    pub fn end_segment(&self) {
        for u in (0..self.inputs.len()).filter_map(|i| self.input(i)) {
            u.unlock();
        }
    }

    /// The element of input `i`.
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_element(&self, i: usize) -> Result<ElementId, GraphError> {
        self.checked(i)?;
        Ok(self.inputs[i])
    }

    /// Where the value of input `i` lives in the plan: the offset of its signal in the
    /// signal array. It is the one output of the one stage of its own element, which reads
    /// nothing: the forward-mode Jacobian seeds ∂/∂uᵢ by giving this signal's gradient the
    /// unit vector of a column of its own (and ∂y/∂u of an output reading it follows).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_signal_offset(&self, i: usize) -> Result<usize, GraphError> {
        self.checked(i)?;
        Ok(self.layouts[self.inputs[i]].outputs[0].0)
    }

    /// A probe reading input `i` (an output column of its value).
    ///
    /// # Errors
    /// [`GraphError::UnknownInput`] for an index out of range.
    pub fn input_probe(&self, i: usize) -> Result<Probe, GraphError> {
        self.input_signal_offset(i).map(Probe::Signal)
    }
}
