//! The chain rule compiled: every gradient on its sparsity pattern, every local partial a run
//! of updates in one flat list.
//!
//! Walking the plan once, in the order the Jacobian will, each block (a stage, or an
//! element's state derivatives) learns where the gradients of its columns lie and which
//! states they depend on; its rows then depend on the union of the patterns of the columns
//! they read — every column for a dense block or a locally differenced one, the columns of
//! the entries the element sets for a wide block (its structure, found by asking it once at
//! the compile point). Each row's gradient gets a place of that size; each local entry (row
//! r, column c) becomes `g[place of r, j] += value · g[place of c, j]` for every state j of
//! c's pattern. States are gradients too: position j of `g` holds 1, the unit gradient eⱼ.

use std::ops::Range;

use crate::element::{Element, Io, Layout, Source};
use crate::local_jacobian::{LocalJacobian, LocalShape, DENSE_MAX_COLS, DENSE_MAX_ENTRIES};

use super::constant::{aliases, constant_partials, Constant};
use super::layout::BlockLayout;

use super::super::StateEquations;

/// A gradient's place: values `g[start..start + len]` of the work, and the state (column)
/// of each at the same positions of [`Compiled::cols`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(in crate::equations) struct Span {
    pub(super) start: u32,
    pub(super) len: u32,
}

impl Span {
    pub(super) const EMPTY: Self = Self { start: 0, len: 0 };

    /// The unit gradient of column j (a state, or a seeded input).
    fn unit(j: usize) -> Self {
        Self {
            start: j as u32,
            len: 1,
        }
    }

    pub(super) fn range(self) -> Range<usize> {
        self.start as usize..(self.start + self.len) as usize
    }
}

/// A scalar's gradient as a block reads it: its place and the factor from the stored value
/// to the local one (−1 for a flow the element sees as flow in against the half-arrow).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Src {
    pub(super) span: Span,
    pub(super) scale: f64,
}

impl Src {
    pub(super) const NONE: Self = Self {
        span: Span::EMPTY,
        scale: 1.0,
    };
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

/// What a block evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Target {
    Stage(usize),
    Derivatives,
}

/// How a block's partials are stored.
#[derive(Debug)]
pub(super) enum Storage {
    /// Row-major; with a mask, the structure of a wide block (the entries it may set).
    Dense(Option<Vec<bool>>),
    /// On the structure: row starts, and the sorted columns of each row.
    Sparse(Vec<u32>, Vec<u32>),
}

/// `g[d..d + len] += value · g[s..s + len]`: one run of the chain rule (the source always
/// lies before the destination: it was written by an earlier block, or is a unit gradient).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Run {
    pub(super) d: u32,
    pub(super) s: u32,
    pub(super) len: u32,
}

/// The compiled partials of a block: where each entry's value lies, and its updates.
#[derive(Debug)]
pub(super) struct Entries {
    pub(super) storage: Storage,
    /// Number of entries.
    pub(super) len: usize,
    /// Per entry: the row's factor times the column's.
    pub(super) fac: Vec<f64>,
    /// Per entry: its first update in [`Compiled::updates`]; one more ends the last.
    pub(super) first: Vec<u32>,
}

/// The compiled local difference of a block.
#[derive(Debug)]
pub(super) struct Differences {
    /// The scalars perturbed (those read, less those written), with their gradients.
    pub(super) cells: Vec<(Cell, Src)>,
    /// Per (cell k, row r), at k·rows + r: its first update; one more ends the last.
    pub(super) first: Vec<u32>,
    /// Central differences whatever the number of cells ([`Element::central_differences`](crate::Element::central_differences)).
    pub(super) central: bool,
}

/// One block of the pass: a stage of an element, or its state derivatives.
#[derive(Debug)]
pub(super) struct BlockCode {
    pub(super) id: usize,
    pub(super) target: Target,
    pub(super) shape: LocalShape,
    /// Per local row: its cell and the factor from the local value to the stored one (the
    /// port's sign for an `f_in` row).
    pub(super) rows: Vec<(Cell, f64)>,
    /// The gradients of all its rows, one after the other (zeroed at the start of a pass).
    pub(super) out: Span,
    /// The element's partials, if it gives them (always for a dense block).
    pub(super) entries: Option<Entries>,
    /// The local difference, if it gives none (always for a dense block).
    pub(super) diffs: Option<Differences>,
    /// The nonzero partials in storage order, if the element's partials are constant
    /// ([`Element::partials_are_constant`]): the pass then neither asks for nor scans them.
    pub(super) constant: Option<Vec<Constant>>,
}

/// The compiled Jacobian of one order of the plan.
#[derive(Debug)]
pub(in crate::equations) struct Compiled {
    /// Columns: the states, then the seeded inputs.
    pub(super) width: usize,
    /// The column of each gradient position (the first `width` are the unit gradients).
    pub(super) cols: Vec<u32>,
    pub(super) blocks: Vec<BlockCode>,
    /// The runs of every entry, block after block.
    pub(super) updates: Vec<Run>,
    /// Each effort, flow and signal scalar's gradient after the pass, and the factor (±1)
    /// from it to the scalar (a row that aliases another scalar's gradient).
    pub(super) slots: Vec<Src>,
    /// The Jacobian's rows: state index and gradient.
    pub(super) rows: Vec<(usize, Span)>,
    pub(super) max_entries: usize,
    pub(super) max_rows: usize,
    /// `max_rows + 1` zeros: the structure of a block compiled without partials.
    pub(super) no_structure: Vec<u32>,
}

impl Entries {
    /// The (row, column) of every entry a wide block may set (in a plan compiled before).
    fn structure(&self, n_cols: usize) -> Vec<(u32, u32)> {
        match &self.storage {
            Storage::Dense(None) => Vec::new(),
            Storage::Dense(Some(mask)) => (0..mask.len())
                .filter(|&i| mask[i])
                .map(|i| ((i / n_cols) as u32, (i % n_cols) as u32))
                .collect(),
            Storage::Sparse(row_ptr, cols) => (0..row_ptr.len() - 1)
                .flat_map(|r| {
                    let (a, e) = (row_ptr[r] as usize, row_ptr[r + 1] as usize);
                    cols[a..e].iter().map(move |&col| (r as u32, col))
                })
                .collect(),
        }
    }
}

/// Sorted union of the patterns of `srcs`.
fn union(cols: &[u32], srcs: impl Iterator<Item = Src>) -> Vec<u32> {
    let mut out: Vec<u32> = srcs
        .flat_map(|s| cols[s.span.range()].iter().copied())
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

impl StateEquations {
    /// The gradient of a cell as compiled so far.
    fn src_of(&self, slots: &[Src], cell: Cell) -> Src {
        let nb = self.n_bond_values;
        match cell {
            Cell::Effort(o) => slots[o],
            Cell::Flow(o) => slots[nb + o],
            Cell::Signal(o) => slots[2 * nb + o],
            Cell::State(i) => Src {
                span: Span::unit(i),
                scale: 1.0,
            },
            Cell::Derivative(_) => Src::NONE,
        }
    }

    /// The slot index of a stored effort, flow or signal cell.
    fn slot_of(&self, cell: Cell) -> Option<usize> {
        let nb = self.n_bond_values;
        match cell {
            Cell::Effort(o) => Some(o),
            Cell::Flow(o) => Some(nb + o),
            Cell::Signal(o) => Some(2 * nb + o),
            Cell::State(_) | Cell::Derivative(_) => None,
        }
    }

    /// The cells of signal input `i` of an element with layout `l`.
    pub(super) fn input_cells(l: &Layout, i: usize) -> impl Iterator<Item = Option<Cell>> {
        let (src, dim) = l.inputs[i];
        (0..dim).map(move |k| match src {
            Source::Time => None,
            Source::State(o) => Some(Cell::State(o + k)),
            Source::Signal(o) => Some(Cell::Signal(o + k)),
            Source::Effort(o) => Some(Cell::Effort(o + k)),
            Source::Flow(o) => Some(Cell::Flow(o + k)),
        })
    }

    /// The gradient of every local column of element `id`, in column order.
    fn column_srcs(&self, id: usize, slots: &[Src]) -> Vec<Src> {
        let l = &self.layouts[id];
        let mut srcs = Vec::new();
        for p in &l.ports {
            srcs.extend((0..p.dim).map(|k| self.src_of(slots, Cell::Effort(p.offset + k))));
            srcs.extend((0..p.dim).map(|k| {
                let s = self.src_of(slots, Cell::Flow(p.offset + k));
                Src {
                    scale: p.sign * s.scale,
                    ..s
                }
            }));
        }
        for i in 0..l.inputs.len() {
            srcs.extend(
                Self::input_cells(l, i).map(|c| c.map_or(Src::NONE, |c| self.src_of(slots, c))),
            );
        }
        srcs.extend((0..l.n_states).map(|k| Src {
            span: Span::unit(l.state_offset + k),
            scale: 1.0,
        }));
        srcs
    }

    /// Compile the Jacobian of the stages `order` (then every element's derivatives), with
    /// the signals at offsets `seeds` taken as independent variables (columns n + k).
    /// Evaluates the plan at (t, x) to ask wide blocks for their structure; `prev` (a plan
    /// compiled before) widens each block's structure to include the earlier one.
    pub(in crate::equations) fn compile(
        &self,
        order: &[(usize, usize)],
        seeds: &[usize],
        t: f64,
        x: &[f64],
        prev: Option<&Compiled>,
    ) -> Compiled {
        let n = self.states.len();
        let width = n + seeds.len();
        let n_slots = 2 * self.n_bond_values + self.n_signal_values();
        let mut c = Compiled {
            width,
            cols: (0..width as u32).collect(),
            blocks: Vec::new(),
            updates: Vec::new(),
            slots: vec![Src::NONE; n_slots],
            rows: Vec::new(),
            max_entries: 0,
            max_rows: 0,
            no_structure: Vec::new(),
        };
        let mut ws = self.ws.borrow_mut();
        let ws = &mut *ws;
        let mut dx = vec![0.0; n];
        let mut record = Vec::new();
        let targets = order.iter().map(|&(id, s)| (id, Target::Stage(s))).chain(
            (0..self.layouts.len())
                .filter(|&id| self.layouts[id].n_states > 0)
                .map(|id| (id, Target::Derivatives)),
        );
        for (k, (id, target)) in targets.enumerate() {
            let l = &self.layouts[id];
            let element: &dyn Element = self.graph.node(id).element.as_ref();
            let causality: Vec<_> = l.ports.iter().map(|p| p.causality).collect();
            let mut io = Io {
                t,
                x,
                effort: &mut ws.effort,
                flow: &mut ws.flow,
                signals: &mut ws.signals,
                layout: l,
            };
            match target {
                Target::Stage(s) => element.eval(s, &mut io),
                Target::Derivatives => {
                    let (o, m) = (l.state_offset, l.n_states);
                    element.derivatives(&io, &mut dx[o..o + m]);
                }
            }
            let BlockLayout {
                shape,
                rows,
                written,
                cells,
            } = self.block_layout(id, target, &causality);
            let mut col_srcs = self.column_srcs(id, &c.slots);
            for &w in &written {
                col_srcs[w] = Src::NONE;
            }
            let mut fd_cells: Vec<(Cell, Src)> = Vec::new();
            for cell in cells {
                if !rows.iter().any(|r| r.0 == cell) && !fd_cells.iter().any(|f| f.0 == cell) {
                    fd_cells.push((cell, self.src_of(&c.slots, cell)));
                }
            }
            let before = prev.and_then(|p| p.blocks.get(k)).filter(|b| b.id == id);
            let m = rows.len();
            // Which code this block gets, and a wide block's structure.
            let wide = shape.n_cols() > DENSE_MAX_COLS;
            let (with_entries, with_diffs, structure) = if wide {
                record.clear();
                let mut jac = LocalJacobian::recording(&shape, &mut record);
                let gives = match target {
                    Target::Stage(s) => element.stage_partials(s, &io, &mut jac),
                    Target::Derivatives => element.derivative_partials(&io, &mut jac),
                };
                if !gives {
                    record.clear();
                }
                let mut entries: Vec<(u32, u32)> = record.clone();
                let (mut had_entries, mut had_diffs) = (false, false);
                if let Some(b) = before {
                    had_diffs = b.diffs.is_some();
                    if let Some(e) = &b.entries {
                        had_entries = true;
                        entries.extend(e.structure(b.shape.n_cols()));
                    }
                }
                entries.sort_unstable();
                entries.dedup();
                let mut row_ptr = vec![0u32; m + 1];
                for &(r, _) in &entries {
                    row_ptr[r as usize + 1] += 1;
                }
                for r in 0..m {
                    row_ptr[r + 1] += row_ptr[r];
                }
                let cols: Vec<u32> = entries.iter().map(|e| e.1).collect();
                (
                    gives || had_entries,
                    !gives || had_diffs,
                    Some((row_ptr, cols)),
                )
            } else {
                (true, true, None)
            };
            // The pattern of each row.
            let mut patterns: Vec<Vec<u32>> = match &structure {
                Some((row_ptr, cols)) if !with_diffs => (0..m)
                    .map(|r| {
                        let (a, e) = (row_ptr[r] as usize, row_ptr[r + 1] as usize);
                        union(
                            &c.cols,
                            cols[a..e].iter().map(|&col| col_srcs[col as usize]),
                        )
                    })
                    .collect(),
                _ => {
                    let all = union(
                        &c.cols,
                        col_srcs
                            .iter()
                            .chain(fd_cells.iter().map(|f| &f.1))
                            .copied(),
                    );
                    vec![all; m]
                }
            };
            // A row that is ±1 times one column of the same pattern (a junction's shared
            // effort or flow) is that column's gradient: no place or updates of its own.
            let alias = if structure.is_some() && !with_diffs && element.partials_are_constant() {
                aliases(element, target, &io, &shape, &rows, &col_srcs, &patterns)
            } else {
                vec![None; m]
            };
            for (p, a) in patterns.iter_mut().zip(&alias) {
                if a.is_some() {
                    p.clear();
                }
            }
            let start = c.cols.len();
            let mut row_spans = Vec::with_capacity(m);
            for p in &patterns {
                row_spans.push(Span {
                    start: c.cols.len() as u32,
                    len: p.len() as u32,
                });
                c.cols.extend_from_slice(p);
            }
            let out = Span {
                start: start as u32,
                len: (c.cols.len() - start) as u32,
            };
            // g[row r] += value · g[src], state by state of src's pattern, in runs.
            let updates = |c: &mut Compiled, r: usize, src: Src| {
                let dst = row_spans[r].start as usize;
                let from = c.updates.len();
                for q in src.span.range() {
                    let Ok(pos) = patterns[r].binary_search(&c.cols[q]) else {
                        continue;
                    };
                    let (d, s) = ((dst + pos) as u32, q as u32);
                    let mine = c.updates.len() > from;
                    match c.updates.last_mut() {
                        Some(run) if mine && run.d + run.len == d && run.s + run.len == s => {
                            run.len += 1;
                        }
                        _ => c.updates.push(Run { d, s, len: 1 }),
                    }
                }
            };
            let entries = with_entries.then(|| {
                let nc = shape.n_cols();
                let dense = shape.len() <= DENSE_MAX_ENTRIES;
                // Each entry's (row, column), in storage order, and whether it is compiled.
                let list: Vec<(usize, usize, bool)> = match &structure {
                    None => (0..m)
                        .flat_map(|r| (0..nc).map(move |col| (r, col, true)))
                        .collect(),
                    Some((row_ptr, cols)) if dense => {
                        let mut known = vec![false; m * nc];
                        for r in 0..m {
                            let (a, e) = (row_ptr[r] as usize, row_ptr[r + 1] as usize);
                            for &col in &cols[a..e] {
                                known[r * nc + col as usize] = true;
                            }
                        }
                        (0..m * nc).map(|i| (i / nc, i % nc, known[i])).collect()
                    }
                    Some((row_ptr, cols)) => (0..m)
                        .flat_map(|r| {
                            let (a, e) = (row_ptr[r] as usize, row_ptr[r + 1] as usize);
                            cols[a..e].iter().map(move |&col| (r, col as usize, true))
                        })
                        .collect(),
                };
                let mut fac = Vec::with_capacity(list.len());
                let mut first = Vec::with_capacity(list.len() + 1);
                for &(r, col, known) in &list {
                    let src = col_srcs[col];
                    fac.push(rows[r].1 * src.scale);
                    first.push(c.updates.len() as u32);
                    if known {
                        updates(&mut c, r, src);
                    }
                }
                first.push(c.updates.len() as u32);
                let storage = match structure.clone() {
                    None => Storage::Dense(None),
                    Some(_) if dense => Storage::Dense(Some(list.iter().map(|e| e.2).collect())),
                    Some((row_ptr, cols)) => Storage::Sparse(row_ptr, cols),
                };
                Entries {
                    storage,
                    len: list.len(),
                    fac,
                    first,
                }
            });
            let diffs = with_diffs.then(|| {
                let mut first = Vec::with_capacity(fd_cells.len() * m + 1);
                for &(_, src) in &fd_cells {
                    for r in 0..m {
                        first.push(c.updates.len() as u32);
                        updates(&mut c, r, src);
                    }
                }
                first.push(c.updates.len() as u32);
                Differences {
                    cells: fd_cells,
                    first,
                    central: element.central_differences(),
                }
            });
            let constant = entries
                .as_ref()
                .filter(|_| element.partials_are_constant())
                .and_then(|e| constant_partials(element, target, &io, &shape, e));
            // What the block wrote now has its gradient.
            for (r, &(cell, _)) in rows.iter().enumerate() {
                if let Cell::Derivative(i) = cell {
                    c.rows.push((i, row_spans[r]));
                } else if let Some(g) = self.slot_of(cell) {
                    c.slots[g] = alias[r].unwrap_or(Src {
                        span: row_spans[r],
                        scale: 1.0,
                    });
                    if let Cell::Signal(o) = cell {
                        if let Some(s) = seeds.iter().position(|&s| s == o) {
                            c.slots[g] = Src {
                                span: Span::unit(n + s),
                                scale: 1.0,
                            };
                        }
                    }
                }
            }
            c.max_entries = c.max_entries.max(entries.as_ref().map_or(0, |e| e.len));
            c.max_rows = c.max_rows.max(m);
            c.blocks.push(BlockCode {
                id,
                target,
                shape,
                rows,
                out,
                entries,
                diffs,
                constant,
            });
        }
        c.no_structure = vec![0; c.max_rows + 1];
        c
    }
}
