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
    /// The (first row, dimension) of each slot, first row [`NO_ROW`] if it is not written:
    /// efforts of ports 0..P, then their flows, then the outputs (a direct look-up for
    /// [`row`](Self::row)).
    first_row: Vec<(usize, usize)>,
    n_rows: usize,
}

/// [`LocalShape::first_row`] of a slot the stage does not write.
const NO_ROW: usize = usize::MAX;

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
            first_row: Vec::new(),
            n_rows: 0,
        }
    }

    /// Index of `slot` in [`first_row`](Self::first_row) (`None` for an input, or a port or
    /// output beyond the shape's).
    #[inline]
    fn slot_index(&self, slot: Slot) -> Option<usize> {
        let np = self.ports.len();
        let i = match slot {
            Slot::Effort(p) if p < np => p,
            Slot::Flow(p) if p < np => np + p,
            Slot::Output(i) => 2 * np + i,
            _ => return None,
        };
        (i < self.first_row.len()).then_some(i)
    }

    /// The shape for a stage of an element with this layout that writes `writes` (in order).
    ///
    /// # Panics
    /// If a slot names a port, input or output the layout does not have, or is an input
    /// (inputs are never written): the plan checks this before it builds shapes.
    #[must_use]
    pub fn stage(layout: &Layout, writes: &[Slot]) -> Self {
        let mut shape = Self::columns(layout);
        shape.first_row = vec![(NO_ROW, 0); 2 * layout.ports.len() + layout.outputs.len()];
        let mut row = 0;
        for &slot in writes {
            let dim = match slot {
                Slot::Effort(p) | Slot::Flow(p) => layout.ports[p].dim,
                Slot::Output(i) => layout.outputs[i].1,
                Slot::Input(_) => panic!("a stage cannot write a signal input"),
            };
            shape.rows.push((slot, row, dim));
            if let Some(i) = shape.slot_index(slot) {
                if shape.first_row[i].0 == NO_ROW {
                    shape.first_row[i] = (row, dim);
                }
            }
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
    #[inline]
    pub fn effort_col(&self, port: usize, k: usize) -> usize {
        let (c, dim) = self.ports[port];
        debug_assert!(k < dim, "effort component {k} of a {dim}-port");
        c + k
    }

    /// Column of component `k` of the flow *into the element* at `port`.
    #[must_use]
    #[inline]
    pub fn flow_col(&self, port: usize, k: usize) -> usize {
        let (c, dim) = self.ports[port];
        debug_assert!(k < dim, "flow component {k} of a {dim}-port");
        c + dim + k
    }

    /// Column of component `k` of signal input `i`.
    #[must_use]
    #[inline]
    pub fn input_col(&self, i: usize, k: usize) -> usize {
        let (c, dim) = self.inputs[i];
        debug_assert!(k < dim, "component {k} of a {dim}-signal");
        c + k
    }

    /// Column of the element's own state `k`.
    #[must_use]
    #[inline]
    pub fn state_col(&self, k: usize) -> usize {
        debug_assert!(k < self.n_states, "state {k} of {}", self.n_states);
        self.states + k
    }

    /// Row of component `k` of the written slot `slot` (`Slot::Flow(p)` rows are `f_in`).
    ///
    /// # Panics
    /// If the stage does not write `slot`.
    #[must_use]
    #[inline]
    pub fn row(&self, slot: Slot, k: usize) -> usize {
        // r = first_row[slot]: one look-up, not a search of the written slots
        match self.slot_index(slot).map(|i| self.first_row[i]) {
            Some((r, dim)) if r != NO_ROW => {
                debug_assert!(k < dim, "component {k} of a {dim}-slot");
                r + k
            }
            _ => panic!("the stage does not write {slot:?}"),
        }
    }

    /// The written slots with their first row and dimension, in order.
    #[must_use]
    pub fn rows(&self) -> &[(Slot, usize, usize)] {
        &self.rows
    }
}

/// The partial derivatives of one stage of an element (or of its state derivatives) with
/// respect to the element's local variables: a block the element fills in
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
///
/// **Structure.** A block of up to [`DENSE_MAX_COLS`] columns may set any entry. A wider one
/// (a line of many segments, a manipulator field, a junction of many bonds) has a
/// *structure*: the entries the element set when the core first asked (at the initial
/// state). Such an element should set the same entries wherever it is asked (a zero is
/// fine); a nonzero entry outside the structure is noted, and the core then widens the
/// structure and assembles the Jacobian again. A block of up to [`DENSE_MAX_ENTRIES`] entries is
/// stored dense, row-major; a larger one on its structure, each row's columns sorted — so a
/// line of N segments holds about 5N values, not 4N². Either way the block is a view into
/// buffers sized when the plan is compiled: filling it never allocates.
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
    index: Index<'a>,
    /// Whether a nonzero entry outside a sparse structure was set (and dropped).
    outside: bool,
}

/// Blocks with up to this many local columns may set any entry; wider ones have a structure
/// (see [`LocalJacobian`]).
pub const DENSE_MAX_COLS: usize = 32;

/// Blocks of up to this many entries (rows × columns) are stored dense (see
/// [`LocalJacobian`]).
pub const DENSE_MAX_ENTRIES: usize = 1024;

/// How a [`LocalJacobian`] finds the value of entry (row, column).
#[derive(Debug)]
pub(crate) enum Index<'a> {
    /// Row-major, `row · n_cols + col`.
    Dense,
    /// On a structure: the columns of row r are `cols[row_ptr[r]..row_ptr[r + 1]]`, sorted;
    /// the entry's value is at the same position.
    Sparse { row_ptr: &'a [u32], cols: &'a [u32] },
    /// No values: the entries set are listed (to find a structure; allocates).
    Record(&'a mut Vec<(u32, u32)>),
}

impl<'a> LocalJacobian<'a> {
    /// A dense view of `values` (row-major, `shape.len()` of them) with this shape; not
    /// zeroed.
    ///
    /// # Panics
    /// If `values` does not have `shape.len()` entries.
    pub fn new(shape: &'a LocalShape, values: &'a mut [f64]) -> Self {
        assert_eq!(values.len(), shape.len(), "local Jacobian buffer size");
        Self {
            shape,
            values,
            index: Index::Dense,
            outside: false,
        }
    }

    /// A view of `values` (all zero, one per entry of `index`).
    pub(crate) fn on(shape: &'a LocalShape, values: &'a mut [f64], index: Index<'a>) -> Self {
        Self {
            shape,
            values,
            index,
            outside: false,
        }
    }

    /// No values: every entry set is pushed to `list` as (row, column).
    pub(crate) fn recording(shape: &'a LocalShape, list: &'a mut Vec<(u32, u32)>) -> Self {
        Self {
            shape,
            values: &mut [],
            index: Index::Record(list),
            outside: false,
        }
    }

    /// Whether a nonzero entry outside the block's structure was set (and dropped).
    pub(crate) fn outside(&self) -> bool {
        self.outside
    }

    /// Position of entry (row, col) in `values`; `None` outside the structure or when
    /// recording (the entry is then listed).
    #[inline]
    fn position(&mut self, row: usize, col: usize) -> Option<usize> {
        debug_assert!(
            row < self.shape.n_rows && col < self.shape.n_cols,
            "entry ({row}, {col}) of a {}×{} block",
            self.shape.n_rows,
            self.shape.n_cols
        );
        // shapes are far below u32::MAX rows or columns (a block is rows × columns)
        let i = match &mut self.index {
            Index::Dense => row * self.shape.n_cols + col,
            Index::Sparse { row_ptr, cols } => {
                let (a, b) = (row_ptr[row] as usize, row_ptr[row + 1] as usize);
                a + cols[a..b].binary_search(&(col as u32)).ok()?
            }
            Index::Record(list) => {
                list.push((row as u32, col as u32));
                return None;
            }
        };
        Some(i)
    }

    /// The shape (rows and columns).
    #[must_use]
    pub fn shape(&self) -> &LocalShape {
        self.shape
    }

    /// Number of rows.
    #[must_use]
    #[inline]
    pub fn n_rows(&self) -> usize {
        self.shape.n_rows
    }

    /// Number of columns.
    #[must_use]
    #[inline]
    pub fn n_cols(&self) -> usize {
        self.shape.n_cols
    }

    /// Column of component `k` of the effort at `port`.
    #[must_use]
    #[inline]
    pub fn effort_col(&self, port: usize, k: usize) -> usize {
        self.shape.effort_col(port, k)
    }

    /// Column of component `k` of the flow *into the element* at `port`.
    #[must_use]
    #[inline]
    pub fn flow_col(&self, port: usize, k: usize) -> usize {
        self.shape.flow_col(port, k)
    }

    /// Column of component `k` of signal input `i`.
    #[must_use]
    #[inline]
    pub fn input_col(&self, i: usize, k: usize) -> usize {
        self.shape.input_col(i, k)
    }

    /// Column of the element's own state `k`.
    #[must_use]
    #[inline]
    pub fn state_col(&self, k: usize) -> usize {
        self.shape.state_col(k)
    }

    /// Row of component `k` of the written slot `slot` (`Slot::Flow(p)` rows are `f_in`).
    ///
    /// # Panics
    /// If the stage does not write `slot`.
    #[must_use]
    #[inline]
    pub fn row(&self, slot: Slot, k: usize) -> usize {
        self.shape.row(slot, k)
    }

    /// Row of the derivative of the element's state `k` (in `derivative_partials`).
    #[must_use]
    #[inline]
    pub fn derivative_row(&self, k: usize) -> usize {
        debug_assert!(k < self.shape.n_rows, "state {k} of {}", self.shape.n_rows);
        k
    }

    /// Set entry (row, col).
    #[inline]
    pub fn set(&mut self, row: usize, col: usize, v: f64) {
        match self.position(row, col) {
            Some(i) => self.values[i] = v,
            None => self.outside |= v != 0.0,
        }
    }

    /// Add `v` to entry (row, col).
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        match self.position(row, col) {
            Some(i) => self.values[i] += v,
            None => self.outside |= v != 0.0,
        }
    }

    /// Entry (row, col) (0 where the block stores nothing).
    #[must_use]
    #[inline]
    pub fn get(&self, row: usize, col: usize) -> f64 {
        match &self.index {
            Index::Dense => self.values[row * self.shape.n_cols + col],
            Index::Sparse { row_ptr, cols } => {
                let (a, b) = (row_ptr[row] as usize, row_ptr[row + 1] as usize);
                cols[a..b]
                    .binary_search(&(col as u32))
                    .map_or(0.0, |k| self.values[a + k])
            }
            Index::Record(_) => 0.0,
        }
    }

    /// Set every entry to zero.
    pub fn zero(&mut self) {
        self.values.fill(0.0);
    }

    /// The values: row-major for a dense block, in structure order (row by row, columns
    /// sorted) for a sparse one.
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

    /// The direct look-up of `row` agrees with the written slots' order on a wide junction
    /// (45 ports, the common flow written to 44 of them out of port order), and a slot the
    /// stage does not write still panics.
    #[test]
    fn row_lookup_on_many_rows() {
        let ports = (0..45)
            .map(|p| PortLayout {
                offset: p,
                dim: 1,
                sign: if p % 2 == 0 { 1.0 } else { -1.0 },
                causality: PortCausality::FlowOut,
            })
            .collect();
        let layout = Layout {
            ports,
            inputs: vec![],
            outputs: vec![(0, 2)],
            state_offset: 0,
            n_states: 0,
        };
        let mut writes: Vec<Slot> = (0..45).rev().filter(|&p| p != 7).map(Slot::Flow).collect();
        writes.insert(3, Slot::Output(0));
        writes.push(Slot::Effort(7));
        let s = LocalShape::stage(&layout, &writes);
        assert_eq!(s.n_rows(), 47);
        for &(slot, first, dim) in s.rows() {
            for k in 0..dim {
                assert_eq!(s.row(slot, k), first + k, "{slot:?}");
            }
        }
        assert_eq!(s.row(Slot::Flow(44), 0), 0);
        assert_eq!(s.row(Slot::Output(0), 1), 4);
        assert_eq!(s.row(Slot::Effort(7), 0), 46);
        for unwritten in [
            Slot::Flow(7),
            Slot::Effort(0),
            Slot::Input(0),
            Slot::Flow(45),
        ] {
            let r = std::panic::catch_unwind(|| s.row(unwritten, 0));
            assert!(r.is_err(), "{unwritten:?} is not written");
        }
        assert!(
            std::panic::catch_unwind(|| LocalShape::derivatives(&layout).row(Slot::Flow(0), 0))
                .is_err()
        );
    }
}
