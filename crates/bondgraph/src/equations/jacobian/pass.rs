//! One pass of the plan carrying gradients: each block evaluated, its partials asked for (or
//! differenced locally) and chained through the compiled updates.

use crate::element::{Element, Io};
use crate::equations::{StateEquations, StateInfo, Workspace};
use crate::local_jacobian::{Index, LocalJacobian};

use super::compile::{BlockCode, Cell, Compiled, Run, Src, Storage, Target};
use super::Out;

/// Local differences use central differences up to this many perturbed scalars per block,
/// forward differences (half the evaluations, about half the digits) above.
const CENTRAL_MAX: usize = 8;

/// The buffers of a compiled Jacobian, sized by it.
#[derive(Debug)]
pub(in crate::equations) struct Work {
    /// Every gradient's values, on its pattern ([`Compiled::cols`]); the first `width` are
    /// the unit gradients (1).
    pub(super) g: Vec<f64>,
    /// A local block's values (all zero between blocks).
    local: Vec<f64>,
    /// Row values at the evaluation point, and perturbed.
    base: Vec<f64>,
    plus: Vec<f64>,
    /// The state vector (perturbed by local differences) and the derivatives.
    x: Vec<f64>,
    dx: Vec<f64>,
    /// Per column: its typical size.
    nominal: Vec<f64>,
}

impl Work {
    pub(in crate::equations) fn new(c: &Compiled, states: &[StateInfo]) -> Self {
        let mut g = vec![0.0; c.cols.len()];
        g[..c.width].fill(1.0);
        let mut nominal: Vec<f64> = states.iter().map(|s| s.nominal).collect();
        nominal.resize(c.width, 1.0);
        Self {
            g,
            local: vec![0.0; c.max_entries],
            base: vec![0.0; c.max_rows],
            plus: vec![0.0; c.max_rows],
            x: vec![0.0; states.len()],
            dx: vec![0.0; states.len()],
            nominal,
        }
    }
}

/// `g[d..d + len] += c · g[s..s + len]` for every run.
#[inline(always)]
fn apply(g: &mut [f64], runs: &[Run], c: f64) {
    for run in runs {
        let (d, s, len) = (run.d as usize, run.s as usize, run.len as usize);
        debug_assert!(s + len <= d, "a run's source lies before its destination");
        if len == 1 {
            // a state's unit gradient, or one isolated column: no slices to set up
            g[d] += c * g[s];
            continue;
        }
        let (src, dst) = g.split_at_mut(d);
        for (a, b) in dst[..len].iter_mut().zip(&src[s..s + len]) {
            *a += c * b;
        }
    }
}

/// Entries of a block of at least `CHUNKED_MIN` are scanned for nonzeros `CHUNK` at a time.
const CHUNK: usize = 8;
const CHUNKED_MIN: usize = 64;

/// Whether every value is ±0 (one test for a chunk of a mostly empty local block).
#[inline]
fn all_zero(values: &[f64]) -> bool {
    values.iter().fold(0u64, |acc, v| acc | v.to_bits()) << 1 == 0
}

/// One Jacobian pass: the plan's values and the gradient workspace.
pub(super) struct Pass<'a> {
    eqs: &'a StateEquations,
    code: &'a Compiled,
    t: f64,
    w: &'a mut Work,
    effort: &'a mut [f64],
    flow: &'a mut [f64],
    signals: &'a mut [f64],
    /// An element left the structure compiled for it.
    stale: bool,
}

impl<'a> Pass<'a> {
    /// Run every block of `code` at (t, x). Returns whether the plan must be compiled again
    /// (an element set a partial outside its block's structure, or gave partials where it
    /// was compiled to be differenced, or the other way round).
    pub(super) fn run(
        eqs: &'a StateEquations,
        code: &'a Compiled,
        w: &'a mut Work,
        ws: &'a mut Workspace,
        t: f64,
        x: &[f64],
    ) -> bool {
        w.x.copy_from_slice(x);
        // every block's gradients (its `out`, disjoint and in plan order after the unit
        // gradients) start from 0, cleared here at once rather than block by block
        w.g[code.width..].fill(0.0);
        let mut pass = Pass {
            eqs,
            code,
            t,
            w,
            effort: &mut ws.effort,
            flow: &mut ws.flow,
            signals: &mut ws.signals,
            stale: false,
        };
        for b in &code.blocks {
            pass.block(b);
        }
        pass.stale
    }

    fn eval(&mut self, id: usize, target: Target) {
        let layout = &self.eqs.layouts[id];
        let element = self.eqs.graph.node(id).element.as_ref();
        let mut io = Io {
            t: self.t,
            x: &self.w.x,
            effort: self.effort,
            flow: self.flow,
            signals: self.signals,
            layout,
        };
        match target {
            Target::Stage(s) => element.eval(s, &mut io),
            Target::Derivatives => {
                let (o, m) = (layout.state_offset, layout.n_states);
                element.derivatives(&io, &mut self.w.dx[o..o + m]);
            }
        }
    }

    /// Ask the element for its partials into `w.local`; `false` if it gives none.
    fn partials(&mut self, b: &BlockCode) -> bool {
        let layout = &self.eqs.layouts[b.id];
        let element: &dyn Element = self.eqs.graph.node(b.id).element.as_ref();
        let (index, len) = match &b.entries {
            Some(e) => match &e.storage {
                Storage::Dense(_) => (Index::Dense, e.len),
                Storage::Sparse(row_ptr, cols) => (Index::Sparse { row_ptr, cols }, e.len),
            },
            None => (
                Index::Sparse {
                    row_ptr: &self.code.no_structure[..=b.rows.len()],
                    cols: &[],
                },
                0,
            ),
        };
        let mut jac = LocalJacobian::on(&b.shape, &mut self.w.local[..len], index);
        let io = Io {
            t: self.t,
            x: &self.w.x,
            effort: self.effort,
            flow: self.flow,
            signals: self.signals,
            layout,
        };
        let gives = match b.target {
            Target::Stage(s) => element.stage_partials(s, &io, &mut jac),
            Target::Derivatives => element.derivative_partials(&io, &mut jac),
        };
        if jac.outside() || (gives && b.entries.is_none()) {
            self.stale = true;
        }
        gives
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

    /// Typical size of a cell's variations: its |value| or Σⱼ |∂v/∂xⱼ|·nominalⱼ.
    fn scale(&self, cell: Cell, src: Src) -> f64 {
        let spread: f64 = src
            .span
            .range()
            .map(|q| self.w.g[q].abs() * self.w.nominal[self.code.cols[q] as usize])
            .sum();
        self.get(cell).abs().max(spread)
    }

    fn depends(&self, src: Src) -> bool {
        self.w.g[src.span.range()].iter().any(|&v| v != 0.0)
    }

    /// Evaluate a block and set the gradients of what it writes: analytic partials, or a
    /// local difference.
    fn block(&mut self, b: &BlockCode) {
        self.eval(b.id, b.target);
        debug_assert!(
            self.w.g[b.out.range()].iter().all(|&v| v == 0.0),
            "a block's gradients are cleared at the start of the pass and written only by it"
        );
        let code = self.code;
        let updates = &code.updates;
        if let Some(constant) = &b.constant {
            // the partials compiled once, nonzero ones in storage order
            for k in constant {
                apply(
                    &mut self.w.g,
                    &updates[k.first as usize..k.end as usize],
                    k.c,
                );
            }
            return;
        }
        let gives = self.partials(b);
        let w = &mut *self.w;
        if let Some(e) = &b.entries {
            // Entry by entry in storage order (row by row, columns ascending), each value
            // zeroed again for the next block.
            let mask = match &e.storage {
                Storage::Dense(Some(mask)) => Some(mask),
                _ => None,
            };
            // the block's slices, bounded once
            let n = e.len;
            let (local, fac, first) = (&mut w.local[..n], &e.fac[..n], &e.first[..=n]);
            // small blocks (mostly nonzero) are read entry by entry
            let chunked = n >= CHUNKED_MIN;
            let step = if chunked { CHUNK } else { n };
            let mut start = 0;
            while start < n {
                let end = n.min(start + step);
                if chunked && all_zero(&local[start..end]) {
                    start = end;
                    continue;
                }
                for i in start..end {
                    let v = local[i];
                    if v == 0.0 {
                        continue;
                    }
                    local[i] = 0.0;
                    if !gives {
                        continue;
                    }
                    let (a, z) = (first[i] as usize, first[i + 1] as usize);
                    if a == z {
                        if mask.is_some_and(|m| !m[i]) {
                            // outside a wide block's structure
                            self.stale = true;
                        }
                        continue;
                    }
                    apply(&mut w.g, &updates[a..z], v * fac[i]);
                }
                start = end;
            }
        }
        if gives {
            return;
        }
        let Some(d) = &b.diffs else {
            self.stale = true;
            return;
        };
        let m = b.rows.len();
        for (r, row) in b.rows.iter().enumerate() {
            self.w.base[r] = self.get(row.0);
        }
        let central = d.central || d.cells.len() <= CENTRAL_MAX;
        for (k, &(cell, src)) in d.cells.iter().enumerate() {
            if !self.depends(src) {
                continue;
            }
            let v = self.get(cell);
            let s = self.scale(cell, src);
            let (h, h_den) = if central {
                let h = (v + 6.055_454_452_393_343e-6 * s) - v;
                (h, 2.0 * h)
            } else {
                let h = (v + f64::EPSILON.sqrt() * s) - v;
                (h, h)
            };
            self.set(cell, v + h);
            self.eval(b.id, b.target);
            for (r, row) in b.rows.iter().enumerate() {
                self.w.plus[r] = self.get(row.0);
            }
            if central {
                self.set(cell, v - h);
                self.eval(b.id, b.target);
            } else {
                for (r, row) in b.rows.iter().enumerate() {
                    self.set(row.0, self.w.base[r]);
                }
            }
            self.set(cell, v);
            for r in 0..m {
                let dr = (self.w.plus[r] - self.get(b.rows[r].0)) / h_den;
                if dr != 0.0 {
                    let i = k * m + r;
                    let run = d.first[i] as usize..d.first[i + 1] as usize;
                    apply(&mut self.w.g, &updates[run], dr * src.scale);
                }
            }
        }
        for (r, row) in b.rows.iter().enumerate() {
            self.set(row.0, self.w.base[r]);
        }
    }
}

/// The Jacobian's rows, from the gradients of a pass, into `out` (which the caller zeroed;
/// an entry a sparse pattern lacks — only after the plan was widened — is dropped).
pub(super) fn write_rows(code: &Compiled, w: &Work, out: &mut Out<'_>) {
    match out {
        Out::Dense(jac) => {
            // column-major: entry (i, j) at j·n + i
            let n = jac.nrows();
            let values = jac.as_mut_slice();
            for &(i, span) in &code.rows {
                let q = span.range();
                for (&j, &v) in code.cols[q.clone()].iter().zip(&w.g[q]) {
                    values[j as usize * n + i] = v;
                }
            }
        }
        Out::Sparse(pattern, values) => {
            for &(i, span) in &code.rows {
                for q in span.range() {
                    let (j, v) = (code.cols[q] as usize, w.g[q]);
                    if v != 0.0 {
                        if let Some(slot) = pattern.slot(i, j) {
                            values[slot] = v;
                        }
                    }
                }
            }
        }
    }
}
