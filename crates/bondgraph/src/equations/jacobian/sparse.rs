//! The sparse path of the Jacobian: its pattern, propagated through the evaluation plan,
//! and the assembly straight into the pattern's value slots.

use bg_solver::SparsePattern;

use super::{Block, BlockPlan, Dep, Out, Target, EMPTY};
use crate::equations::StateEquations;

/// Blocks of elements with up to this many local columns are taken as structurally full
/// (every written scalar reads every column); wider ones (a line of many segments) by the
/// entries their partials set.
const FULL_BLOCK_MAX_COLS: usize = 32;

impl StateEquations {
    /// The sparsity pattern of [`jacobian`](Self::jacobian), from the evaluation plan: the
    /// states each stage's written scalars depend on, propagated in plan order. For small
    /// blocks every written scalar depends on every column the block reads (robust against
    /// partials an element sets only in some regimes); for large blocks (a line of many
    /// segments) on the columns of the entries the element's partials set, found by one
    /// evaluation at the initial state. The diagonal is always included.
    ///
    /// `None` if the pattern cannot be formed (it always can for a valid plan).
    #[must_use]
    pub fn jacobian_pattern(&self) -> Option<SparsePattern> {
        let n = self.states.len();
        let x0 = self.initial_state();
        let mut work = self.jac_work.borrow_mut();
        let w = work.get_or_insert_with(|| self.jacobian_work());
        let mut ws = self.ws.borrow_mut();
        let ws = &mut *ws;
        w.x.copy_from_slice(&x0);
        w.range.fill(EMPTY);
        let n_slots = w.range.len();
        let mut slot_pat: Vec<Vec<usize>> = vec![Vec::new(); n_slots];
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut block = Block {
            eqs: self,
            t: 0.0,
            n,
            w,
            effort: &mut ws.effort,
            flow: &mut ws.flow,
            signals: &mut ws.signals,
        };
        for &(id, s) in &self.rhs_order {
            block.eval(id, Target::Stage(s));
            let plan = &self.jac_plan.stages[id][s];
            let rows = block.structure(id, Target::Stage(s), plan, &slot_pat);
            for (r, &(g, _, _)) in plan.rows.iter().enumerate() {
                slot_pat[g].clone_from(&rows[r]);
            }
        }
        for (id, l) in self.layouts.iter().enumerate() {
            if l.n_states == 0 {
                continue;
            }
            block.eval(id, Target::Derivatives);
            let Some(plan) = self.jac_plan.derivatives[id].as_ref() else {
                continue;
            };
            let rows = block.structure(id, Target::Derivatives, plan, &slot_pat);
            for (r, &(i, _, _)) in plan.rows.iter().enumerate() {
                for &j in &rows[r] {
                    cols[j].push(i);
                }
            }
        }
        SparsePattern::from_columns(n, &cols).ok()
    }

    /// [`jacobian`](Self::jacobian) straight into the value slots of `pattern` (from
    /// [`jacobian_pattern`](Self::jacobian_pattern)), column by column as
    /// [`SparsePattern::row_idx`]: no n×n matrix. Allocates only on the first call.
    pub fn jacobian_sparse(&self, t: f64, x: &[f64], pattern: &SparsePattern, values: &mut [f64]) {
        values.fill(0.0);
        self.jacobian_into(t, x, &mut Out::Sparse(pattern, values));
    }
}

impl Block<'_> {
    /// The sorted states each row of a block depends on, structurally (see
    /// [`StateEquations::jacobian_pattern`]), given those of every gradient slot.
    fn structure(
        &mut self,
        id: usize,
        target: Target,
        plan: &BlockPlan,
        slot_pat: &[Vec<usize>],
    ) -> Vec<Vec<usize>> {
        let dep_pat = |dep: Dep, out: &mut Vec<usize>| match dep {
            Dep::None => {}
            Dep::State(i) => out.push(i),
            Dep::Grad(g, _) => out.extend_from_slice(&slot_pat[g]),
        };
        let gives = self.partials(id, target, plan);
        let nc = plan.shape.n_cols();
        let mut rows = vec![Vec::new(); plan.rows.len()];
        let full = !gives || plan.shape.n_cols() <= FULL_BLOCK_MAX_COLS;
        for k in 0..self.w.touched.len() {
            let (r, c) = self.w.touched[k];
            let (r, c) = (r as usize, c as usize);
            let i = r * nc + c;
            self.w.local[i] = 0.0;
            self.w.mark[i] = false;
            if !full {
                dep_pat(plan.col_dep[c], &mut rows[r]);
            }
        }
        self.w.touched.clear();
        if full {
            let mut all = Vec::new();
            for &d in &plan.col_dep {
                dep_pat(d, &mut all);
            }
            for &(_, d) in &plan.fd {
                dep_pat(d, &mut all);
            }
            all.sort_unstable();
            all.dedup();
            for r in &mut rows {
                r.clone_from(&all);
            }
        }
        for r in &mut rows {
            r.sort_unstable();
            r.dedup();
        }
        rows
    }
}
