//! The partials of an element that says they are constant
//! ([`Element::partials_are_constant`]: a junction's ±1, a transformer's constant ratio),
//! asked for once when the plan is compiled: each Jacobian then applies the nonzero ones'
//! updates straight away, without asking the element or scanning its local block.

use crate::element::{Element, Io};
use crate::local_jacobian::{Index, LocalJacobian, LocalShape};

use super::compile::{Cell, Entries, Src, Storage, Target};

/// A nonzero partial of an element whose partials are constant, compiled once: the entry's
/// updates `updates[first..end]` and its factor `value · fac`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Constant {
    pub(super) first: u32,
    pub(super) end: u32,
    pub(super) c: f64,
}

/// The nonzero partials of a block whose element says they are constant, asked for once (in
/// storage order, each with its factor), or `None` if the element gives none or sets one
/// outside the block's structure (the pass then asks at every Jacobian, as for any other).
pub(super) fn constant_partials(
    element: &dyn Element,
    target: Target,
    io: &Io<'_>,
    shape: &LocalShape,
    e: &Entries,
) -> Option<Vec<Constant>> {
    let mut values = vec![0.0; e.len];
    let (index, mask) = match &e.storage {
        Storage::Dense(mask) => (Index::Dense, mask.as_ref()),
        Storage::Sparse(row_ptr, cols) => (Index::Sparse { row_ptr, cols }, None),
    };
    let mut jac = LocalJacobian::on(shape, &mut values, index);
    let gives = match target {
        Target::Stage(s) => element.stage_partials(s, io, &mut jac),
        Target::Derivatives => element.derivative_partials(io, &mut jac),
    };
    if !gives || jac.outside() {
        return None;
    }
    let mut list = Vec::new();
    for (i, &v) in values.iter().enumerate() {
        if v == 0.0 {
            continue;
        }
        let (first, end) = (e.first[i], e.first[i + 1]);
        if first == end {
            if mask.is_some_and(|m| !m[i]) {
                return None;
            }
            // a row that aliases a column, or a column of no gradient
            continue;
        }
        list.push(Constant {
            first,
            end,
            c: v * e.fac[i],
        });
    }
    Some(list)
}

/// Per row of a block whose element's partials are constant (each row on the pattern of the
/// columns it reads): the gradient it aliases, if its only nonzero partial is one column's,
/// with a factor of ±1 and the row on exactly that column's pattern. Then
/// `g[row] = 0 + c·g[col]` is `c·g[col]` bit for bit, and the row needs no place of its own.
pub(super) fn aliases(
    element: &dyn Element,
    target: Target,
    io: &Io<'_>,
    shape: &LocalShape,
    rows: &[(Cell, f64)],
    col_srcs: &[Src],
    patterns: &[Vec<u32>],
) -> Vec<Option<Src>> {
    let mut alias = vec![None; rows.len()];
    let nc = shape.n_cols();
    let mut values = vec![0.0; shape.len()];
    let mut jac = LocalJacobian::on(shape, &mut values, Index::Dense);
    let gives = match target {
        Target::Stage(s) => element.stage_partials(s, io, &mut jac),
        Target::Derivatives => element.derivative_partials(io, &mut jac),
    };
    if !gives || jac.outside() || nc == 0 {
        return alias;
    }
    for (r, (row, a)) in values.chunks_exact(nc).zip(&mut alias).enumerate() {
        if matches!(rows[r].0, Cell::Derivative(_)) {
            continue;
        }
        let mut nonzero = row.iter().enumerate().filter(|(_, v)| **v != 0.0);
        let (Some((col, &v)), None) = (nonzero.next(), nonzero.next()) else {
            continue;
        };
        let src = col_srcs[col];
        // the factor as the updates would apply it: value · (row factor · column factor)
        let c = v * (rows[r].1 * src.scale);
        if (c == 1.0 || c == -1.0) && patterns[r].len() == src.span.len as usize {
            *a = Some(Src {
                span: src.span,
                scale: c,
            });
        }
    }
    alias
}
