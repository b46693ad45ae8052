//! [`LocalJacobian`]: the partial derivatives an element states about one of its stages (or its
//! state derivatives), in its own local variables; the evaluation plan chains them into the
//! system Jacobian ∂f/∂x.

use crate::element::{Layout, Slot};

/// Where an element's local columns and a stage's rows lie in a [`LocalJacobian`], fixed
/// when the evaluation plan is built (so filling one never allocates).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LocalShape {
    /// Per port: (first effort column, dimension); its flow columns follow its efforts.
    ports: Vec<(usize, usize)>,
    /// Per signal input: (first column, dimension).
    inputs: Vec<(usize, usize)>,
    /// First state column.
    states: usize,
    n_states: usize,
    n_cols: usize,
    /// Per written slot: (slot, first row, dimension).
    rows: Vec<(Slot, usize, usize)>,
    n_rows: usize,
}

impl LocalShape {
    /// The columns of an element with this layout, no rows yet.
    fn columns(layout: &Layout) -> Self {
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
/// [`Element::stage_partials`](crate::Element::stage_partials) and
/// [`Element::derivative_partials`](crate::Element::derivative_partials).
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
}

impl<'a> LocalJacobian<'a> {
    /// A view of `values` (row-major, `shape.len()` of them) with this shape; not zeroed.
    ///
    /// # Panics
    /// If `values` does not have `shape.len()` entries.
    pub fn new(shape: &'a LocalShape, values: &'a mut [f64]) -> Self {
        assert_eq!(values.len(), shape.len(), "local Jacobian buffer size");
        Self { shape, values }
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
        self.values[row * self.shape.n_cols + col] = v;
    }

    /// Add `v` to entry (row, col).
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        self.values[row * self.shape.n_cols + col] += v;
    }

    /// Entry (row, col).
    #[must_use]
    pub fn get(&self, row: usize, col: usize) -> f64 {
        self.values[row * self.shape.n_cols + col]
    }

    /// Set every entry to zero.
    pub fn zero(&mut self) {
        self.values.fill(0.0);
    }

    /// The values, row-major.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        self.values
    }
}
