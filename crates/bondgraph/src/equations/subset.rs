//! Evaluating only what is read: the stages a set of probes needs (the stages that write
//! them and, transitively, the stages those read), found once, then run alone.
//!
//! A stage computes its writes from its reads only, so running the needed stages in plan
//! order gives the probes bit for bit the values of a whole evaluation.

use super::{Probe, StateEquations, Step, Var};
use crate::bond::{ElementId, PortCausality};
use crate::element::Slot;

/// What [`StateEquations::evaluate_only`] runs for a set of probes: the stages that compute
/// them, in plan order, and the elements whose state derivatives they read. Made once by
/// [`StateEquations::subset`]; evaluating it allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct Subset {
    /// The stages, in plan order.
    stages: Vec<Step>,
    /// Elements whose [`derivatives`](crate::element::Element::derivatives) are read, in
    /// element order.
    derivatives: Vec<Step>,
}

/// Two subsets are equal when they run the same stages and derivatives (the layouts are
/// copies of the plan's).
impl PartialEq for Subset {
    fn eq(&self, other: &Self) -> bool {
        let calls = |s: &[Step]| s.iter().map(|c| (c.id, c.stage)).collect::<Vec<_>>();
        calls(&self.stages) == calls(&other.stages)
            && calls(&self.derivatives) == calls(&other.derivatives)
    }
}

impl Eq for Subset {}

impl Subset {
    /// Number of stages run.
    #[must_use]
    pub fn n_stages(&self) -> usize {
        self.stages.len()
    }
    /// Number of elements whose state derivatives are computed.
    #[must_use]
    pub fn n_derivatives(&self) -> usize {
        self.derivatives.len()
    }
}

impl StateEquations {
    /// The stages `probes` need: those writing the variables they read and, transitively,
    /// those writing what these read; a derivative probe needs its element's derivatives
    /// and everything that element can read (its ports and inputs).
    ///
    /// # Complexity
    /// O(S + D) for S stages and D data dependencies.
    #[must_use]
    pub fn subset(&self, probes: &[Probe]) -> Subset {
        let writer = self.writers();
        let reads = self.stage_reads();
        let mut derivatives: Vec<ElementId> = Vec::new();
        let mut wanted: Vec<Var> = Vec::new();
        for &p in probes {
            match p {
                Probe::Time | Probe::State(_) => {}
                Probe::Derivative(i) => {
                    let id = self.states[i].element;
                    if !derivatives.contains(&id) {
                        derivatives.push(id);
                        wanted.extend(self.element_vars(id));
                    }
                }
                Probe::Effort(o) => wanted.extend(self.bond_at(o).map(Var::Effort)),
                Probe::Flow(o) => wanted.extend(self.bond_at(o).map(Var::Flow)),
                Probe::Signal(o) => wanted.extend(self.signal_owner(o)),
                Probe::Power(b) => wanted.extend([Var::Effort(b), Var::Flow(b)]),
            }
        }
        // Depth-first over the writers of what is wanted.
        let mut needed = vec![false; self.order.len()];
        let mut stack: Vec<usize> = wanted.iter().filter_map(&writer).collect();
        while let Some(k) = stack.pop() {
            if std::mem::replace(&mut needed[k], true) {
                continue;
            }
            stack.extend(reads[k].iter().filter_map(&writer));
        }
        derivatives.sort_unstable();
        let stages: Vec<(ElementId, usize)> = self
            .order
            .iter()
            .zip(&needed)
            .filter(|(_, &n)| n)
            .map(|(&st, _)| st)
            .collect();
        Subset {
            stages: self.steps_of(&stages),
            derivatives: self.owners_of(derivatives.into_iter()),
        }
    }

    /// Evaluate only `subset` at (t, x) and keep it for [`read`](Self::read): the probes it
    /// was made for read as after [`evaluate`](Self::evaluate); other variables are stale.
    pub fn evaluate_only(&self, subset: &Subset, t: f64, x: &[f64]) {
        self.evaluate_steps(&subset.stages, &subset.derivatives, t, x);
    }

    /// Forget every value evaluated so far (efforts, flows, signals and derivatives become
    /// NaN): a probe then reads NaN unless its stages run again, which shows a stage
    /// [`subset`](Self::subset) left out.
    pub fn forget(&self) {
        let ws = &mut *self.ws.borrow_mut();
        for v in [&mut ws.effort, &mut ws.flow, &mut ws.signals, &mut ws.dx] {
            v.fill(f64::NAN);
        }
    }

    /// The plan position of the stage writing each variable.
    fn writers(&self) -> impl Fn(&Var) -> Option<usize> + '_ {
        let mut at = std::collections::HashMap::new();
        for (k, &(id, s)) in self.order.iter().enumerate() {
            for &v in &self.writes[id][s] {
                at.insert(v, k);
            }
        }
        move |v| at.get(v).copied()
    }

    /// The variables each stage of the plan reads, by plan position.
    fn stage_reads(&self) -> Vec<Vec<Var>> {
        self.order
            .iter()
            .map(|&(id, s)| {
                let causality: Vec<PortCausality> =
                    self.layouts[id].ports.iter().map(|p| p.causality).collect();
                self.graph.node(id).element.stages(&causality)[s]
                    .reads
                    .iter()
                    .filter_map(|&slot| self.var_of(id, slot))
                    .collect()
            })
            .collect()
    }

    /// Every variable element `id` can read: both sides of its ports and its inputs.
    fn element_vars(&self, id: ElementId) -> Vec<Var> {
        let l = &self.layouts[id];
        let ports = (0..l.ports.len()).flat_map(|p| [Slot::Effort(p), Slot::Flow(p)]);
        let inputs = (0..l.inputs.len()).map(Slot::Input);
        ports
            .chain(inputs)
            .filter_map(|slot| self.var_of(id, slot))
            .collect()
    }

    /// The bond holding value offset `o` of the effort or flow array.
    fn bond_at(&self, o: usize) -> Option<usize> {
        self.bond_offset.iter().rposition(|&b| b <= o)
    }
}

#[cfg(test)]
mod tests;
