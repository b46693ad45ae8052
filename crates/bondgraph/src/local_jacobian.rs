//! [`LocalJacobian`]: the partial derivatives an element states about one of its stages (or its
//! state derivatives), in its own local variables; the evaluation plan chains them into the
//! system Jacobian ∂f/∂x.

use crate::io::{Layout, Slot};

/// Where an element's local columns and a stage's rows lie in a [`LocalJacobian`], fixed
/// when the evaluation plan is built (so filling one never allocates).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LocalShape {
    /// Per port: (first effort column, dimension); its flow columns follow its efforts.
    pub(crate) ports: Vec<(usize, usize)>,
    /// Per signal input: (first column, dimension).
    pub(crate) inputs: Vec<(usize, usize)>,
    /// First state column.
    pub(crate) states: usize,
    n_states: usize,
    pub(crate) n_cols: usize,
    /// Per written slot: (slot, first row, dimension).
    rows: Vec<(Slot, usize, usize)>,
    n_rows: usize,
}

impl LocalShape {
    /// The columns of an element with this layout, no rows yet.
    pub(crate) fn columns(layout: &Layout) -> Self {
        let mut col = 0;
        let mut ports = Vec::with_capacity(layout.ports.len());
        for p in &layout.ports {
            ports.push((col, p.dim));
            col += 2 * p.dim;
        }
        let mut inputs = Vec::with_capacity(layout.inputs.len());
        for &(_, dim) in &layout.inputs {
            inputs.push((col, dim));
            col += dim;
        }
        Self {
            ports,
            inputs,
            states: col,
            n_states: layout.n_states,
            n_cols: col + layout.n_states,
            rows: Vec::new(),
            n_rows: 0,
        }
    }

    /// The shape for a stage of an element with this layout that writes `writes` (in order).
    ///
    /// # Panics
    /// If a slot names a port, input or output the layout does not have, or is an input
    /// (inputs are never written): the plan checks this before it builds shapes.
    #[must_use]
    pub fn stage(layout: &Layout, writes: &[Slot]) -> Self {
        let mut shape = Self::columns(layout);
        let mut row = 0;
        for &slot in writes {
            let dim = match slot {
                Slot::Effort(p) | Slot::Flow(p) => layout.ports[p].dim,
                Slot::Output(i) => layout.outputs[i].1,
                Slot::Input(_) => panic!("a stage cannot write a signal input"),
            };
            shape.rows.push((slot, row, dim));
            row += dim;
        }
        shape.n_rows = row;
        shape
    }

    /// The shape for the state derivatives of an element with this layout (rows: its states).
    #[must_use]
    pub fn derivatives(layout: &Layout) -> Self {
        let mut shape = Self::columns(layout);
        shape.n_rows = layout.n_states;
        shape
    }

    /// Number of rows.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }

    /// Number of columns (the element's local variables).
    #[must_use]
    pub fn n_cols(&self) -> usize {
        self.n_cols
    }

    /// Number of values a [`LocalJacobian`] of this shape holds (`n_rows · n_cols`).
    #[must_use]
    pub fn len(&self) -> usize {
        self.n_rows * self.n_cols
    }

    /// Whether the shape has no entries.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Column of component `k` of the effort at `port`.
    #[must_use]
    pub fn effort_col(&self, port: usize, k: usize) -> usize {
        let (c, dim) = self.ports[port];
        debug_assert!(k < dim, "effort component {k} of a {dim}-port");
        c + k
    }

    /// Column of component `k` of the flow *into the element* at `port`.
    #[must_use]
    pub fn flow_col(&self, port: usize, k: usize) -> usize {
        let (c, dim) = self.ports[port];
        debug_assert!(k < dim, "flow component {k} of a {dim}-port");
        c + dim + k
    }

    /// Column of component `k` of signal input `i`.
    #[must_use]
    pub fn input_col(&self, i: usize, k: usize) -> usize {
        let (c, dim) = self.inputs[i];
        debug_assert!(k < dim, "component {k} of a {dim}-signal");
        c + k
    }

    /// Column of the element's own state `k`.
    #[must_use]
    pub fn state_col(&self, k: usize) -> usize {
        debug_assert!(k < self.n_states, "state {k} of {}", self.n_states);
        self.states + k
    }

    /// Row of component `k` of the written slot `slot` (`Slot::Flow(p)` rows are `f_in`).
    ///
    /// # Panics
    /// If the stage does not write `slot`.
    #[must_use]
    pub fn row(&self, slot: Slot, k: usize) -> usize {
        match self.rows.iter().find(|r| r.0 == slot) {
            Some(&(_, r, dim)) => {
                debug_assert!(k < dim, "component {k} of a {dim}-slot");
                r + k
            }
            None => panic!("the stage does not write {slot:?}"),
        }
    }

    /// The written slots with their first row and dimension, in order.
    #[must_use]
    pub fn rows(&self) -> &[(Slot, usize, usize)] {
        &self.rows
    }
}

/// The partial derivatives of one stage of an element (or of its state derivatives) with
/// respect to the element's local variables: a dense row-major block the element fills in
/// [`Element::stage_partials`] and
/// [`Element::derivative_partials`].
///
/// **Columns** are the element's local variables as it sees them through [`Io`](crate::Io):
/// for each port `p` in order, its effort components `e(p, k)`, then its flow components as
/// *flow into the element* `f_in(p, k)` (power-in convention, like
/// [`Io::f_in`](crate::Io::f_in) / [`Io::set_f_in`](crate::Io::set_f_in)); then every
/// signal input's components in order; then the element's own states. Time is not a column.
///
/// **Rows** are the stage's written scalars in the order of [`Stage::writes`](crate::Stage),
/// each slot expanded by its dimension (`Slot::Flow(p)` rows are `f_in`), or, for
/// `derivative_partials`, the element's state derivatives in the order of its states.
///
/// **Entries** are ∂(row)/∂(column) holding every other column fixed. The core zeroes the
/// block before the call, so an element sets only its nonzero entries; the `io` it receives
/// holds the values at the evaluation point, including the stage's own writes.
///
/// Use the accessors for indices: [`effort_col`](Self::effort_col),
/// [`flow_col`](Self::flow_col), [`input_col`](Self::input_col),
/// [`state_col`](Self::state_col), [`row`](Self::row) (and
/// [`derivative_row`](Self::derivative_row)), then [`set`](Self::set) / [`add`](Self::add).
/// The block is a view into buffers sized once per element and stage when the plan is built:
/// filling it never allocates.
///
/// A resistor in conductance causality, f_in = e / r, fills one entry:
/// ```
/// # use bondgraph::{LocalJacobian, Slot};
/// # fn fill(jac: &mut LocalJacobian<'_>, r: f64) {
/// jac.set(jac.row(Slot::Flow(0), 0), jac.effort_col(0, 0), 1.0 / r);
/// # }
/// ```
#[derive(Debug)]
pub struct LocalJacobian<'a> {
    shape: &'a LocalShape,
    values: &'a mut [f64],
    /// The entries set so far, when the core keeps a list of them (so that it reads, and
    /// zeroes again, only those).
    touched: Option<Touched<'a>>,
}

/// The list of entries a [`LocalJacobian`] has set, as (row, column), and a mark per entry.
#[derive(Debug)]
pub(crate) struct Touched<'a> {
    pub(crate) list: &'a mut Vec<(u32, u32)>,
    pub(crate) mark: &'a mut [bool],
}

impl<'a> LocalJacobian<'a> {
    /// A view of `values` (row-major, `shape.len()` of them) with this shape; not zeroed.
    ///
    /// # Panics
    /// If `values` does not have `shape.len()` entries.
    pub fn new(shape: &'a LocalShape, values: &'a mut [f64]) -> Self {
        assert_eq!(values.len(), shape.len(), "local Jacobian buffer size");
        Self {
            shape,
            values,
            touched: None,
        }
    }

    /// As [`new`](Self::new), keeping the list of entries set in `touched` (its marks all
    /// false and `values` all zero on entry; `list` has room for every entry, so pushing
    /// never allocates).
    pub(crate) fn tracked(
        shape: &'a LocalShape,
        values: &'a mut [f64],
        touched: Touched<'a>,
    ) -> Self {
        assert_eq!(values.len(), shape.len(), "local Jacobian buffer size");
        Self {
            shape,
            values,
            touched: Some(touched),
        }
    }

    fn note(&mut self, row: usize, col: usize, index: usize) {
        if let Some(t) = &mut self.touched {
            if !t.mark[index] {
                t.mark[index] = true;
                // shapes are far below u32::MAX rows or columns (a block is rows × columns)
                t.list.push((row as u32, col as u32));
            }
        }
    }

    /// The shape (rows and columns).
    #[must_use]
    pub fn shape(&self) -> &LocalShape {
        self.shape
    }

    /// Number of rows.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        self.shape.n_rows
    }

    /// Number of columns.
    #[must_use]
    pub fn n_cols(&self) -> usize {
        self.shape.n_cols
    }

    /// Column of component `k` of the effort at `port`.
    #[must_use]
    pub fn effort_col(&self, port: usize, k: usize) -> usize {
        self.shape.effort_col(port, k)
    }

    /// Column of component `k` of the flow *into the element* at `port`.
    #[must_use]
    pub fn flow_col(&self, port: usize, k: usize) -> usize {
        self.shape.flow_col(port, k)
    }

    /// Column of component `k` of signal input `i`.
    #[must_use]
    pub fn input_col(&self, i: usize, k: usize) -> usize {
        self.shape.input_col(i, k)
    }

    /// Column of the element's own state `k`.
    #[must_use]
    pub fn state_col(&self, k: usize) -> usize {
        self.shape.state_col(k)
    }

    /// Row of component `k` of the written slot `slot` (`Slot::Flow(p)` rows are `f_in`).
    ///
    /// # Panics
    /// If the stage does not write `slot`.
    #[must_use]
    pub fn row(&self, slot: Slot, k: usize) -> usize {
        self.shape.row(slot, k)
    }

    /// Row of the derivative of the element's state `k` (in `derivative_partials`).
    #[must_use]
    pub fn derivative_row(&self, k: usize) -> usize {
        debug_assert!(k < self.shape.n_rows, "state {k} of {}", self.shape.n_rows);
        k
    }

    /// Set entry (row, col).
    pub fn set(&mut self, row: usize, col: usize, v: f64) {
        let i = row * self.shape.n_cols + col;
        self.values[i] = v;
        self.note(row, col, i);
    }

    /// Add `v` to entry (row, col).
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        let i = row * self.shape.n_cols + col;
        self.values[i] += v;
        self.note(row, col, i);
    }

    /// Entry (row, col).
    #[must_use]
    pub fn get(&self, row: usize, col: usize) -> f64 {
        self.values[row * self.shape.n_cols + col]
    }

    /// Set every entry to zero.
    pub fn zero(&mut self) {
        match &mut self.touched {
            Some(t) => {
                for &(r, c) in t.list.iter() {
                    let i = r as usize * self.shape.n_cols + c as usize;
                    self.values[i] = 0.0;
                    t.mark[i] = false;
                }
                t.list.clear();
            }
            None => self.values.fill(0.0),
        }
    }

    /// The values, row-major.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        self.values
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bond::PortCausality;
    use crate::io::{PortLayout, Source};

    #[test]
    fn columns_and_rows_follow_the_documented_order() {
        let layout = Layout {
            ports: vec![
                PortLayout {
                    offset: 0,
                    dim: 2,
                    sign: 1.0,
                    causality: PortCausality::EffortOut,
                },
                PortLayout {
                    offset: 2,
                    dim: 1,
                    sign: -1.0,
                    causality: PortCausality::FlowOut,
                },
            ],
            inputs: vec![(Source::Time, 1), (Source::Signal(0), 3)],
            outputs: vec![(3, 2)],
            state_offset: 5,
            n_states: 2,
        };
        let s = LocalShape::stage(&layout, &[Slot::Output(0), Slot::Effort(0), Slot::Flow(1)]);
        assert_eq!(
            (s.effort_col(0, 1), s.flow_col(0, 0), s.flow_col(0, 1)),
            (1, 2, 3)
        );
        assert_eq!((s.effort_col(1, 0), s.flow_col(1, 0)), (4, 5));
        assert_eq!(
            (s.input_col(0, 0), s.input_col(1, 2), s.state_col(1)),
            (6, 9, 11)
        );
        assert_eq!(s.n_cols(), 12);
        assert_eq!(
            (
                s.row(Slot::Output(0), 1),
                s.row(Slot::Effort(0), 0),
                s.row(Slot::Flow(1), 0)
            ),
            (1, 2, 4)
        );
        assert_eq!((s.n_rows(), s.len()), (5, 60));
        assert_eq!(LocalShape::derivatives(&layout).n_rows(), 2);
    }
}
