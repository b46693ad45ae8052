//! The exact Jacobian ∂f/∂x, assembled through the evaluation plan (forward mode).
//!
//! The plan is evaluated in `rhs` order while every effort, flow and signal scalar carries its
//! gradient with respect to x (a dense n-vector in a preallocated workspace, with the range
//! of its nonzero entries). After a stage is evaluated, the gradients of the scalars it wrote
//! follow by the chain rule from its local partials ([`Element::stage_partials`]) and the
//! gradients of its columns; the state-derivative rows follow likewise from
//! [`Element::derivative_partials`]. An element that gives no partials is differenced
//! *locally*: each scalar its stage reads (or, for the derivatives, every port variable,
//! input and own state) is perturbed, only that stage is re-run, and the difference of its
//! writes is chained like an analytic partial.
//!
//! Sizes are fixed by the plan: after the first call (which allocates the workspace) a
//! Jacobian allocates nothing.

use bg_solver::SparsePattern;
use nalgebra::DMatrix;

mod sparse;

use crate::element::{Element, Io, Layout, Slot, Source};
use crate::local_jacobian::{LocalJacobian, LocalShape, Touched};

use super::StateEquations;

mod outputs;

/// How a scalar depends on the state vector x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Dep {
    /// Not at all (time, a constant).
    None,
    /// It is state `i`: the unit vector eᵢ.
    State(usize),
    /// `scale` times the gradient held in slot `g` (efforts, then flows, then signals).
    Grad(usize, f64),
}

/// Where a scalar of the plan is stored (what a local difference perturbs or reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cell {
    Effort(usize),
    Flow(usize),
    Signal(usize),
    State(usize),
    /// A state derivative (rows of the derivative block).
    Derivative(usize),
}

/// The Jacobian plan of one stage (or of an element's derivatives).
#[derive(Debug)]
pub(super) struct BlockPlan {
    shape: LocalShape,
    /// Per local row: the gradient slot (or, for derivatives, the state index) it fills, the
    /// factor from the local value to the stored one (±1 for `f_in` rows) and its cell.
    rows: Vec<(usize, f64, Cell)>,
    /// Per local column, its dependence on x (`Dep::None` for the columns the stage writes).
    col_dep: Vec<Dep>,
    /// Scalars perturbed by the local difference, with their dependence on x.
    fd: Vec<(Cell, Dep)>,
}

/// Per element: one plan per stage, and one for the derivatives if it has states.
#[derive(Debug, Default)]
pub(super) struct JacobianPlan {
    stages: Vec<Vec<BlockPlan>>,
    derivatives: Vec<Option<BlockPlan>>,
    max_local: usize,
    max_rows: usize,
}

/// Buffers of the Jacobian, allocated by the first call.
#[derive(Debug, Default)]
pub(super) struct JacobianWork {
    /// Gradient of each slot, n values each.
    grad: Vec<f64>,
    /// Nonzero range [lo, hi) of each slot's gradient (empty: lo ≥ hi).
    range: Vec<(usize, usize)>,
    /// Row accumulators (max_rows × n) and their ranges.
    acc: Vec<f64>,
    acc_range: Vec<(usize, usize)>,
    /// A local Jacobian block (all zero between blocks), the entries an element set in it and
    /// their marks.
    local: Vec<f64>,
    touched: Vec<(u32, u32)>,
    mark: Vec<bool>,
    /// Row values at the evaluation point, and perturbed.
    base: Vec<f64>,
    plus: Vec<f64>,
    /// The state vector (perturbed by local differences) and the derivatives.
    x: Vec<f64>,
    dx: Vec<f64>,
    nominal: Vec<f64>,
}

/// Local differences use central differences up to this many perturbed scalars per block,
/// forward differences (half the evaluations, about half the digits) above.
const CENTRAL_MAX: usize = 8;

const EMPTY: (usize, usize) = (usize::MAX, 0);

impl StateEquations {
    fn grad_slot(&self, cell: Cell) -> Dep {
        let nb = self.n_bond_values;
        match cell {
            Cell::Effort(o) => Dep::Grad(o, 1.0),
            Cell::Flow(o) => Dep::Grad(nb + o, 1.0),
            Cell::Signal(o) => Dep::Grad(2 * nb + o, 1.0),
            Cell::State(i) => Dep::State(i),
            Cell::Derivative(_) => Dep::None,
        }
    }

    /// The cells of signal input `i` of an element with layout `l`.
    fn input_cells(l: &Layout, i: usize) -> impl Iterator<Item = Option<Cell>> {
        let (src, dim) = l.inputs[i];
        (0..dim).map(move |k| match src {
            Source::Time => None,
            Source::State(o) => Some(Cell::State(o + k)),
            Source::Signal(o) => Some(Cell::Signal(o + k)),
            Source::Effort(o) => Some(Cell::Effort(o + k)),
            Source::Flow(o) => Some(Cell::Flow(o + k)),
        })
    }

    /// The dependence on x of every local column of element `id`, in column order.
    fn column_deps(&self, id: usize) -> Vec<Dep> {
        let l = &self.layouts[id];
        let mut deps = Vec::new();
        for p in &l.ports {
            deps.extend((0..p.dim).map(|k| self.grad_slot(Cell::Effort(p.offset + k))));
            deps.extend(
                (0..p.dim).map(|k| match self.grad_slot(Cell::Flow(p.offset + k)) {
                    Dep::Grad(g, _) => Dep::Grad(g, p.sign),
                    d => d,
                }),
            );
        }
        for i in 0..l.inputs.len() {
            deps.extend(
                Self::input_cells(l, i).map(|c| c.map_or(Dep::None, |c| self.grad_slot(c))),
            );
        }
        deps.extend((0..l.n_states).map(|k| Dep::State(l.state_offset + k)));
        deps
    }

    /// Build the Jacobian plan (after the evaluation plan).
    pub(super) fn jacobian_plan(&self) -> JacobianPlan {
        let mut plan = JacobianPlan::default();
        for (id, l) in self.layouts.iter().enumerate() {
            let element = self.graph.node(id).element.as_ref();
            let causality: Vec<_> = l.ports.iter().map(|p| p.causality).collect();
            let deps = self.column_deps(id);
            let own_states = || (0..l.n_states).map(move |k| Some(Cell::State(l.state_offset + k)));
            let mut stages = Vec::new();
            for stage in element.stages(&causality) {
                let shape = LocalShape::stage(l, &stage.writes);
                let mut rows = Vec::new();
                let mut written = Vec::new();
                for &(slot, _, dim) in shape.rows() {
                    for k in 0..dim {
                        let (cell, scale, col) = match slot {
                            Slot::Effort(p) => (
                                Cell::Effort(l.ports[p].offset + k),
                                1.0,
                                Some(shape.effort_col(p, k)),
                            ),
                            Slot::Flow(p) => (
                                Cell::Flow(l.ports[p].offset + k),
                                l.ports[p].sign,
                                Some(shape.flow_col(p, k)),
                            ),
                            Slot::Output(i) | Slot::Input(i) => {
                                (Cell::Signal(l.outputs[i].0 + k), 1.0, None)
                            }
                        };
                        let slot = match self.grad_slot(cell) {
                            Dep::Grad(g, _) => g,
                            _ => 0,
                        };
                        rows.push((slot, scale, cell));
                        written.extend(col);
                    }
                }
                let col_dep = deps
                    .iter()
                    .enumerate()
                    .map(|(c, d)| if written.contains(&c) { Dep::None } else { *d })
                    .collect();
                let mut cells: Vec<Option<Cell>> = Vec::new();
                for &slot in &stage.reads {
                    match slot {
                        Slot::Effort(p) => {
                            let o = l.ports[p].offset;
                            cells.extend((0..l.ports[p].dim).map(|k| Some(Cell::Effort(o + k))));
                        }
                        Slot::Flow(p) => {
                            let o = l.ports[p].offset;
                            cells.extend((0..l.ports[p].dim).map(|k| Some(Cell::Flow(o + k))));
                        }
                        Slot::Input(i) => cells.extend(Self::input_cells(l, i)),
                        Slot::Output(_) => {}
                    }
                }
                cells.extend(own_states());
                let fd = self.fd_targets(cells, &rows);
                plan.max_local = plan.max_local.max(shape.len());
                plan.max_rows = plan.max_rows.max(shape.n_rows());
                stages.push(BlockPlan {
                    shape,
                    rows,
                    col_dep,
                    fd,
                });
            }
            plan.stages.push(stages);
            if l.n_states == 0 {
                plan.derivatives.push(None);
                continue;
            }
            let shape = LocalShape::derivatives(l);
            let rows: Vec<_> = (0..l.n_states)
                .map(|k| {
                    let i = l.state_offset + k;
                    (i, 1.0, Cell::Derivative(i))
                })
                .collect();
            let col_dep = deps.clone();
            let mut cells: Vec<Option<Cell>> = Vec::new();
            for p in &l.ports {
                cells.extend((0..p.dim).map(|k| Some(Cell::Effort(p.offset + k))));
                cells.extend((0..p.dim).map(|k| Some(Cell::Flow(p.offset + k))));
            }
            for i in 0..l.inputs.len() {
                cells.extend(Self::input_cells(l, i));
            }
            cells.extend(own_states());
            let fd = self.fd_targets(cells, &rows);
            plan.max_local = plan.max_local.max(shape.len());
            plan.max_rows = plan.max_rows.max(shape.n_rows());
            plan.derivatives.push(Some(BlockPlan {
                shape,
                rows,
                col_dep,
                fd,
            }));
        }
        plan
    }

    /// The distinct cells a local difference perturbs: those read, less those written.
    fn fd_targets(
        &self,
        cells: Vec<Option<Cell>>,
        rows: &[(usize, f64, Cell)],
    ) -> Vec<(Cell, Dep)> {
        let mut out: Vec<(Cell, Dep)> = Vec::new();
        for c in cells.into_iter().flatten() {
            if !rows.iter().any(|r| r.2 == c) && !out.iter().any(|o| o.0 == c) {
                out.push((c, self.grad_slot(c)));
            }
        }
        out
    }

    fn jacobian_work(&self) -> JacobianWork {
        let n = self.states.len();
        let n_slots = 2 * self.n_bond_values + self.n_signal_values();
        let p = &self.jac_plan;
        JacobianWork {
            grad: vec![0.0; n_slots * n],
            range: vec![EMPTY; n_slots],
            acc: vec![0.0; p.max_rows * n],
            acc_range: vec![EMPTY; p.max_rows],
            local: vec![0.0; p.max_local],
            touched: Vec::with_capacity(p.max_local),
            mark: vec![false; p.max_local],
            base: vec![0.0; p.max_rows],
            plus: vec![0.0; p.max_rows],
            x: vec![0.0; n],
            dx: vec![0.0; n],
            nominal: self.states.iter().map(|s| s.nominal).collect(),
        }
    }

    /// The Jacobian ∂f/∂x of [`rhs`](Self::rhs) at (t, x), exact where the elements give
    /// their partial derivatives ([`Element::stage_partials`],
    /// [`Element::derivative_partials`]) and differenced element by element where they do
    /// not.
    ///
    /// # Arguments
    /// `jac` receives ∂fᵢ/∂xⱼ at row i, column j; it is resized to n×n if it is not already.
    ///
    /// # Complexity
    /// One pass over the plan (the cost of about one `rhs`), plus O(n) per nonzero local
    /// partial for the chain rule, plus one or two re-evaluations of a stage per scalar it
    /// reads for every element that gives no partials. Allocates only on the first call.
    pub fn jacobian(&self, t: f64, x: &[f64], jac: &mut DMatrix<f64>) {
        let n = self.states.len();
        if jac.shape() != (n, n) {
            *jac = DMatrix::zeros(n, n);
        }
        jac.fill(0.0);
        self.jacobian_into(t, x, &mut Out::Dense(jac));
    }

    /// One pass of the plan carrying gradients: the derivative rows into `out` (dense or on
    /// a sparse pattern), which the caller has zeroed.
    fn jacobian_into(&self, t: f64, x: &[f64], out: &mut Out<'_>) {
        let n = self.states.len();
        let mut work = self.jac_work.borrow_mut();
        let w = work.get_or_insert_with(|| self.jacobian_work());
        let mut ws = self.ws.borrow_mut();
        let ws = &mut *ws;
        w.x.copy_from_slice(x);
        w.range.fill(EMPTY);
        let mut block = Block {
            eqs: self,
            t,
            n,
            w,
            effort: &mut ws.effort,
            flow: &mut ws.flow,
            signals: &mut ws.signals,
        };
        for &(id, stage) in &self.rhs_order {
            block.stage(id, stage);
        }
        for (id, l) in self.layouts.iter().enumerate() {
            if l.n_states > 0 {
                block.derivatives(id, out);
            }
        }
    }
}

/// Where the derivative rows go.
enum Out<'a> {
    Dense(&'a mut DMatrix<f64>),
    Sparse(&'a SparsePattern, &'a mut [f64]),
}

/// One Jacobian pass: the plan's values and the gradient workspace.
struct Block<'a> {
    eqs: &'a StateEquations,
    t: f64,
    n: usize,
    w: &'a mut JacobianWork,
    effort: &'a mut [f64],
    flow: &'a mut [f64],
    signals: &'a mut [f64],
}

/// What a block evaluates.
#[derive(Clone, Copy)]
enum Target {
    Stage(usize),
    Derivatives,
}

impl Block<'_> {
    fn eval(&mut self, id: usize, target: Target) {
        let layout = &self.eqs.layouts[id];
        let element = self.eqs.graph.node(id).element.as_ref();
        match target {
            Target::Stage(s) => {
                let mut io = Io {
                    t: self.t,
                    x: &self.w.x,
                    effort: self.effort,
                    flow: self.flow,
                    signals: self.signals,
                    layout,
                };
                element.eval(s, &mut io);
            }
            Target::Derivatives => {
                let io = Io {
                    t: self.t,
                    x: &self.w.x,
                    effort: self.effort,
                    flow: self.flow,
                    signals: self.signals,
                    layout,
                };
                let (o, m) = (layout.state_offset, layout.n_states);
                element.derivatives(&io, &mut self.w.dx[o..o + m]);
            }
        }
    }

    /// Ask the element for its partials into `w.local`; `false` if it gives none.
    fn partials(&mut self, id: usize, target: Target, plan: &BlockPlan) -> bool {
        let layout = &self.eqs.layouts[id];
        let element: &dyn Element = self.eqs.graph.node(id).element.as_ref();
        let len = plan.shape.len();
        let touched = Touched {
            list: &mut self.w.touched,
            mark: &mut self.w.mark[..len],
        };
        let mut jac = LocalJacobian::tracked(&plan.shape, &mut self.w.local[..len], touched);
        let io = Io {
            t: self.t,
            x: &self.w.x,
            effort: self.effort,
            flow: self.flow,
            signals: self.signals,
            layout,
        };
        match target {
            Target::Stage(s) => element.stage_partials(s, &io, &mut jac),
            Target::Derivatives => element.derivative_partials(&io, &mut jac),
        }
    }

    fn get(&self, cell: Cell) -> f64 {
        match cell {
            Cell::Effort(o) => self.effort[o],
            Cell::Flow(o) => self.flow[o],
            Cell::Signal(o) => self.signals[o],
            Cell::State(i) => self.w.x[i],
            Cell::Derivative(i) => self.w.dx[i],
        }
    }

    fn set(&mut self, cell: Cell, v: f64) {
        match cell {
            Cell::Effort(o) => self.effort[o] = v,
            Cell::Flow(o) => self.flow[o] = v,
            Cell::Signal(o) => self.signals[o] = v,
            Cell::State(i) => self.w.x[i] = v,
            Cell::Derivative(i) => self.w.dx[i] = v,
        }
    }

    /// Add `coef` times the gradient of `dep` to accumulator row `r`.
    fn add(&mut self, r: usize, coef: f64, dep: Dep) {
        let n = self.n;
        let w = &mut *self.w;
        let (lo, hi, scale) = match dep {
            Dep::None => return,
            Dep::State(i) => (i, i + 1, 1.0),
            Dep::Grad(g, s) => {
                let (lo, hi) = w.range[g];
                if lo >= hi {
                    return;
                }
                (lo, hi, s)
            }
        };
        let acc = &mut w.acc[r * n..(r + 1) * n];
        match dep {
            Dep::Grad(g, _) => {
                let c = coef * scale;
                let src = &w.grad[g * n + lo..g * n + hi];
                for (a, s) in acc[lo..hi].iter_mut().zip(src) {
                    *a += c * s;
                }
            }
            _ => acc[lo] += coef,
        }
        let ar = &mut w.acc_range[r];
        *ar = (ar.0.min(lo), ar.1.max(hi));
    }

    /// Typical size of a cell's variations: its |value| or Σⱼ |∂v/∂xⱼ|·nominalⱼ.
    fn scale(&self, cell: Cell, dep: Dep) -> f64 {
        let n = self.n;
        let spread = match dep {
            Dep::None => 0.0,
            Dep::State(i) => self.w.nominal[i],
            Dep::Grad(g, _) => {
                let (lo, hi) = self.w.range[g];
                (lo..hi)
                    .map(|j| self.w.grad[g * n + j].abs() * self.w.nominal[j])
                    .sum()
            }
        };
        self.get(cell).abs().max(spread)
    }

    fn depends(&self, dep: Dep) -> bool {
        match dep {
            Dep::None => false,
            Dep::State(_) => true,
            Dep::Grad(g, _) => self.w.range[g].0 < self.w.range[g].1,
        }
    }

    /// Fill the accumulator rows of a block: analytic partials, or a local difference.
    fn rows(&mut self, id: usize, target: Target, plan: &BlockPlan) {
        let gives = self.partials(id, target, plan);
        let nc = plan.shape.n_cols();
        for k in 0..self.w.touched.len() {
            let (r, c) = self.w.touched[k];
            let (r, c) = (r as usize, c as usize);
            let i = r * nc + c;
            let v = std::mem::take(&mut self.w.local[i]);
            self.w.mark[i] = false;
            if gives && v != 0.0 {
                self.add(r, v * plan.rows[r].1, plan.col_dep[c]);
            }
        }
        self.w.touched.clear();
        if gives {
            return;
        }
        let m = plan.rows.len();
        for (r, row) in plan.rows.iter().enumerate() {
            self.w.base[r] = self.get(row.2);
        }
        let central = plan.fd.len() <= CENTRAL_MAX;
        for &(cell, dep) in &plan.fd {
            if !self.depends(dep) {
                continue;
            }
            let v = self.get(cell);
            let s = self.scale(cell, dep);
            let (h, h_den) = if central {
                let h = (v + 6.055_454_452_393_343e-6 * s) - v;
                (h, 2.0 * h)
            } else {
                let h = (v + f64::EPSILON.sqrt() * s) - v;
                (h, h)
            };
            self.set(cell, v + h);
            self.eval(id, target);
            for (r, row) in plan.rows.iter().enumerate() {
                self.w.plus[r] = self.get(row.2);
            }
            if central {
                self.set(cell, v - h);
                self.eval(id, target);
            } else {
                for (r, row) in plan.rows.iter().enumerate() {
                    self.set(row.2, self.w.base[r]);
                }
            }
            self.set(cell, v);
            for r in 0..m {
                let d = (self.w.plus[r] - self.get(plan.rows[r].2)) / h_den;
                if d != 0.0 {
                    self.add(r, d, dep);
                }
            }
        }
        for (r, row) in plan.rows.iter().enumerate() {
            self.set(row.2, self.w.base[r]);
        }
    }

    /// Evaluate stage `s` of element `id` and set the gradients of what it writes.
    fn stage(&mut self, id: usize, s: usize) {
        let eqs = self.eqs;
        self.eval(id, Target::Stage(s));
        let plan = &eqs.jac_plan.stages[id][s];
        self.rows(id, Target::Stage(s), plan);
        let n = self.n;
        let w = &mut *self.w;
        for (r, &(g, _, _)) in plan.rows.iter().enumerate() {
            let (lo, hi) = std::mem::replace(&mut w.acc_range[r], EMPTY);
            if lo >= hi {
                w.range[g] = EMPTY;
                continue;
            }
            let acc = &mut w.acc[r * n + lo..r * n + hi];
            w.grad[g * n + lo..g * n + hi].copy_from_slice(acc);
            acc.fill(0.0);
            w.range[g] = (lo, hi);
        }
    }

    /// The derivative rows of element `id`, into `out`.
    fn derivatives(&mut self, id: usize, out: &mut Out<'_>) {
        let eqs = self.eqs;
        self.eval(id, Target::Derivatives);
        let Some(plan) = eqs.jac_plan.derivatives[id].as_ref() else {
            return;
        };
        self.rows(id, Target::Derivatives, plan);
        let n = self.n;
        let w = &mut *self.w;
        for (r, &(i, _, _)) in plan.rows.iter().enumerate() {
            let (lo, hi) = std::mem::replace(&mut w.acc_range[r], EMPTY);
            if lo >= hi {
                continue;
            }
            let acc = &mut w.acc[r * n + lo..r * n + hi];
            match out {
                Out::Dense(jac) => {
                    for (j, a) in (lo..hi).zip(acc.iter_mut()) {
                        jac[(i, j)] = *a;
                        *a = 0.0;
                    }
                }
                Out::Sparse(pattern, values) => {
                    for (j, a) in (lo..hi).zip(acc.iter_mut()) {
                        if *a != 0.0 {
                            // Outside the pattern only if an element's partials left it
                            // (jacobian_pattern); the entry is then dropped.
                            if let Some(slot) = pattern.slot(i, j) {
                                values[slot] = *a;
                            }
                            *a = 0.0;
                        }
                    }
                }
            }
        }
    }
}
