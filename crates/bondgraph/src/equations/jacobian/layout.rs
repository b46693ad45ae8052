//! The layout of a block before it is compiled: its local shape, the cells its rows write
//! (with their factors), the columns it writes, and the cells a local difference perturbs.

use crate::element::Slot;
use crate::local_jacobian::LocalShape;

use super::super::StateEquations;
use super::compile::{Cell, Target};

/// A block before compiling: its shape, rows (cell, factor), the columns it writes and the
/// cells a local difference reads.
pub(super) struct BlockLayout {
    pub(super) shape: LocalShape,
    pub(super) rows: Vec<(Cell, f64)>,
    pub(super) written: Vec<usize>,
    pub(super) cells: Vec<Cell>,
}

impl StateEquations {
    /// The shape, rows, written columns and differenced cells of a block.
    pub(super) fn block_layout(
        &self,
        id: usize,
        target: Target,
        causality: &[crate::bond::PortCausality],
    ) -> BlockLayout {
        let l = &self.layouts[id];
        let element = self.graph.node(id).element.as_ref();
        let own_states = (0..l.n_states).map(|k| Cell::State(l.state_offset + k));
        match target {
            Target::Stage(s) => {
                let stage = &element.stages(causality)[s];
                let shape = LocalShape::stage(l, &stage.writes);
                let mut rows = Vec::new();
                let mut written = Vec::new();
                for &(slot, _, dim) in shape.rows() {
                    for k in 0..dim {
                        match slot {
                            Slot::Effort(p) => {
                                rows.push((Cell::Effort(l.ports[p].offset + k), 1.0));
                                written.push(shape.effort_col(p, k));
                            }
                            Slot::Flow(p) => {
                                rows.push((Cell::Flow(l.ports[p].offset + k), l.ports[p].sign));
                                written.push(shape.flow_col(p, k));
                            }
                            Slot::Output(i) | Slot::Input(i) => {
                                rows.push((Cell::Signal(l.outputs[i].0 + k), 1.0));
                            }
                        }
                    }
                }
                let mut cells = Vec::new();
                for &slot in &stage.reads {
                    match slot {
                        Slot::Effort(p) => {
                            let o = l.ports[p].offset;
                            cells.extend((0..l.ports[p].dim).map(|k| Cell::Effort(o + k)));
                        }
                        Slot::Flow(p) => {
                            let o = l.ports[p].offset;
                            cells.extend((0..l.ports[p].dim).map(|k| Cell::Flow(o + k)));
                        }
                        Slot::Input(i) => cells.extend(Self::input_cells(l, i).flatten()),
                        Slot::Output(_) => {}
                    }
                }
                cells.extend(own_states);
                BlockLayout {
                    shape,
                    rows,
                    written,
                    cells,
                }
            }
            Target::Derivatives => {
                let shape = LocalShape::derivatives(l);
                let rows = (0..l.n_states)
                    .map(|k| (Cell::Derivative(l.state_offset + k), 1.0))
                    .collect();
                let mut cells = Vec::new();
                for p in &l.ports {
                    cells.extend((0..p.dim).map(|k| Cell::Effort(p.offset + k)));
                    cells.extend((0..p.dim).map(|k| Cell::Flow(p.offset + k)));
                }
                for i in 0..l.inputs.len() {
                    cells.extend(Self::input_cells(l, i).flatten());
                }
                cells.extend(own_states);
                BlockLayout {
                    shape,
                    rows,
                    written: Vec::new(),
                    cells,
                }
            }
        }
    }
}
