//! [`LocalJacobian`]: the partial derivatives an element states about one of its stages (or its
//! state derivatives), in its own local variables; the evaluation plan chains them into the
//! system Jacobian ∂f/∂x.

use crate::bond::PortCausality;
use crate::element::{Element, Io, Layout, PortLayout, Slot, Source};

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
/// **Columns** are the element's local variables as it sees them through [`Io`]:
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

/// An element in isolation, at one point of its local variables: what
/// [`check_partials`] evaluates.
struct Bench<'e> {
    element: &'e dyn Element,
    layout: Layout,
    shape: LocalShape,
    effort: Vec<f64>,
    flow: Vec<f64>,
    signals: Vec<f64>,
    x: Vec<f64>,
}

impl Bench<'_> {
    fn io(&mut self) -> Io<'_> {
        Io {
            t: 0.0,
            x: &self.x,
            effort: &mut self.effort,
            flow: &mut self.flow,
            signals: &mut self.signals,
            layout: &self.layout,
        }
    }

    /// Set the storage of local column `c` to `v` (the columns' convention: `f_in` flows).
    fn set(&mut self, c: usize, v: f64) {
        let cell = self.cell(c);
        match cell {
            (0, o, _) => self.effort[o] = v,
            (1, o, s) => self.flow[o] = s * v,
            (2, o, _) => self.signals[o] = v,
            (_, o, _) => self.x[o] = v,
        }
    }

    fn get(&self, c: usize) -> f64 {
        match self.cell(c) {
            (0, o, _) => self.effort[o],
            (1, o, s) => s * self.flow[o],
            (2, o, _) => self.signals[o],
            (_, o, _) => self.x[o],
        }
    }

    /// (array, offset, sign) of local column `c`: 0 effort, 1 flow, 2 signal, 3 state.
    fn cell(&self, c: usize) -> (u8, usize, f64) {
        for (p, &(start, dim)) in self.shape.ports.iter().enumerate() {
            let port = &self.layout.ports[p];
            if c < start + dim {
                return (0, port.offset + c - start, 1.0);
            }
            if c < start + 2 * dim {
                return (1, port.offset + c - start - dim, port.sign);
            }
        }
        for (i, &(start, dim)) in self.shape.inputs.iter().enumerate() {
            if c < start + dim {
                let Source::Signal(o) = self.layout.inputs[i].0 else {
                    unreachable!("the bench feeds every input from a signal")
                };
                return (2, o + c - start, 1.0);
            }
        }
        (3, c - self.shape.states, 1.0)
    }

    /// The values of a block's rows: a stage's writes (`f_in` for flows), or the derivatives.
    fn rows(&mut self, stage: Option<usize>, shape: &LocalShape, out: &mut [f64]) {
        match stage {
            Some(s) => {
                let element = self.element;
                let mut io = self.io();
                element.eval(s, &mut io);
                for &(slot, r, dim) in shape.rows() {
                    for k in 0..dim {
                        out[r + k] = match slot {
                            Slot::Effort(p) => io.e(p, k),
                            Slot::Flow(p) => io.f_in(p, k),
                            Slot::Output(i) | Slot::Input(i) => {
                                io.signals[io.layout.outputs[i].0 + k]
                            }
                        };
                    }
                }
            }
            None => {
                let element = self.element;
                let io = self.io();
                element.derivatives(&io, out);
            }
        }
    }
}

/// Check an element's analytic partials ([`Element::stage_partials`],
/// [`Element::derivative_partials`]) against central differences of its own `eval` and
/// `derivatives`, at one point of its local variables: the test every element with partials
/// should have.
///
/// # Arguments
/// * `element` — the element.
/// * `ports` — per port: dimension, half-arrow sign (+1 into the element, −1 away) and
///   causality.
/// * `point` — a value for every local column, in [`LocalJacobian`]'s column order (efforts,
///   flows in, inputs, states). Entries a stage writes are overwritten by that stage.
///
/// Each column is stepped by ∛ε·max(|v|, 1e-3): give columns whose natural scale is large
/// (pressures) values of that scale, not zero.
///
/// # Returns
/// The number of blocks (stages, then the derivatives if the element has states) that gave
/// partials, or the first entry that differs:
/// `|J − J_fd|·s_c > 1e-6·(|J_fd|·s_c + maxₖ |J_fd,rk|·s_k)` with `s_c = max(|v_c|, 1e-3)`.
pub fn check_partials(
    element: &dyn Element,
    ports: &[(usize, f64, PortCausality)],
    point: &[f64],
) -> Result<usize, String> {
    let mut layout = Layout::default();
    let mut off = 0;
    for &(dim, sign, causality) in ports {
        layout.ports.push(PortLayout {
            offset: off,
            dim,
            sign,
            causality,
        });
        off += dim;
    }
    let mut n_signals = 0;
    for s in element.signal_inputs() {
        layout.inputs.push((Source::Signal(n_signals), s.dim));
        n_signals += s.dim;
    }
    for s in element.signal_outputs() {
        layout.outputs.push((n_signals, s.dim));
        n_signals += s.dim;
    }
    layout.n_states = element.states().len();
    let columns = LocalShape::columns(&layout);
    if point.len() != columns.n_cols {
        return Err(format!(
            "{} values for {} local columns",
            point.len(),
            columns.n_cols
        ));
    }
    let mut bench = Bench {
        element,
        shape: columns,
        effort: vec![0.0; off],
        flow: vec![0.0; off],
        signals: vec![0.0; n_signals],
        x: vec![0.0; layout.n_states],
        layout,
    };
    let reset = |b: &mut Bench<'_>| {
        for (c, &v) in point.iter().enumerate() {
            b.set(c, v);
        }
    };
    let causality: Vec<PortCausality> = ports.iter().map(|p| p.2).collect();
    let stages = element.stages(&causality);
    let mut blocks: Vec<(Option<usize>, LocalShape)> = stages
        .iter()
        .enumerate()
        .map(|(s, st)| (Some(s), LocalShape::stage(&bench.layout, &st.writes)))
        .collect();
    if bench.layout.n_states > 0 {
        blocks.push((None, LocalShape::derivatives(&bench.layout)));
    }
    let mut given = 0;
    for (stage, shape) in &blocks {
        let (m, nc) = (shape.n_rows(), shape.n_cols());
        let mut values = vec![0.0; shape.len()];
        reset(&mut bench);
        let mut base = vec![0.0; m];
        bench.rows(*stage, shape, &mut base);
        let ok = {
            let mut jac = LocalJacobian::new(shape, &mut values);
            let io = bench.io();
            match stage {
                Some(s) => element.stage_partials(*s, &io, &mut jac),
                None => element.derivative_partials(&io, &mut jac),
            }
        };
        if !ok {
            continue;
        }
        given += 1;
        let mut fd = vec![0.0; m * nc];
        let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
        let scale: Vec<f64> = point.iter().map(|v| v.abs().max(1e-3)).collect();
        for c in 0..nc {
            reset(&mut bench);
            let v = bench.get(c);
            let h = crate::element::central_step(v, 1e-3);
            bench.set(c, v + h);
            bench.rows(*stage, shape, &mut plus);
            reset(&mut bench);
            bench.set(c, v - h);
            bench.rows(*stage, shape, &mut minus);
            for r in 0..m {
                fd[r * nc + c] = (plus[r] - minus[r]) / (2.0 * h);
            }
        }
        for r in 0..m {
            let row = (0..nc)
                .map(|k| fd[r * nc + k].abs() * scale[k])
                .fold(0.0, f64::max);
            for c in 0..nc {
                let (a, d) = (values[r * nc + c], fd[r * nc + c]);
                if (a - d).abs() * scale[c] > 1e-6 * (d.abs() * scale[c] + row) || a.is_nan() {
                    return Err(format!(
                        "{} {}: ∂(row {r})/∂(column {c}) = {a:e}, central differences {d:e}",
                        element.kind(),
                        stage.map_or("derivatives".to_owned(), |s| format!("stage {s}")),
                    ));
                }
            }
        }
    }
    Ok(given)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{CausalRule, PortSpec, Ports};

    /// e = f_in², with a partial `2·f_in·scale`.
    #[derive(Debug)]
    struct Square(f64);

    impl Element for Square {
        fn kind(&self) -> &str {
            "square"
        }
        fn ports(&self) -> Ports {
            Ports::Fixed(vec![PortSpec::new("1", 1)])
        }
        fn causal_rule(&self, _: usize) -> CausalRule {
            CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
        }
        fn eval(&self, _: usize, io: &mut Io<'_>) {
            let f = io.f_in(0, 0);
            io.set_e(0, 0, f * f);
        }
        fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
            let (r, c) = (jac.row(Slot::Effort(0), 0), jac.flow_col(0, 0));
            jac.set(r, c, 2.0 * io.f_in(0, 0) * self.0);
            true
        }
    }

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

    #[test]
    fn check_partials_accepts_right_and_names_wrong_partials() {
        let port = [(1, -1.0, PortCausality::EffortOut)];
        assert_eq!(check_partials(&Square(1.0), &port, &[0.0, 1.3]), Ok(1));
        let e = check_partials(&Square(1.01), &port, &[0.0, 1.3]).unwrap_err();
        assert!(e.contains("stage 0") && e.contains("column 1"), "{e}");
        assert!(check_partials(&Square(1.0), &port, &[0.0]).is_err());
    }
}
