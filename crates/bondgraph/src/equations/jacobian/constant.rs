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
        // exactly ±1: only then is the product the column's gradient bit for bit
        let unit = c.abs().to_bits() == 1.0_f64.to_bits();
        if unit && patterns[r].len() == src.span.len as usize {
            *a = Some(Src {
                span: src.span,
                scale: c,
            });
        }
    }
    alias
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // a fixed, valid test model
    use nalgebra::DMatrix;

    use super::Src;
    use crate::{assign_causality, BondGraph, Capacitor, Resistor, StateEquations, ZeroJunction};

    /// A capacitor `c` discharging through `n` resistors `r_k = k + 1` on one 0-junction
    /// (2·(n + 1) local columns: a wide block for n ≥ 16).
    fn discharge(c: f64, n: usize) -> StateEquations {
        let mut g = BondGraph::new();
        g.add("cap", Capacitor::new(c, 1.0).unwrap()).unwrap();
        g.add("node", ZeroJunction).unwrap();
        g.connect_names("node", "cap").unwrap();
        for k in 0..n {
            let name = format!("r{k}");
            g.add(&name, Resistor::new(k as f64 + 1.0).unwrap())
                .unwrap();
            g.connect_names("node", &name).unwrap();
        }
        StateEquations::new(assign_causality(g).unwrap()).unwrap()
    }

    /// The junction's stages are compiled once, its shared efforts alias the capacitor's
    /// gradient, and the Jacobian and every probe's gradient are still right:
    /// dq/dt = −Σₖ q/(c·rₖ), and each resistor's effort q/c.
    #[test]
    fn junction_shares_alias_and_constant_blocks_keep_the_jacobian() {
        let (c, n) = (0.5, 20);
        let eqs = discharge(c, n);
        let mut jac = DMatrix::zeros(0, 0);
        eqs.jacobian(0.0, &[0.8], &mut jac);
        let exact: f64 = -(0..n).map(|k| 1.0 / (c * (k as f64 + 1.0))).sum::<f64>();
        assert!(
            (jac[(0, 0)] - exact).abs() <= 1e-14 * exact.abs(),
            "{} vs {exact}",
            jac[(0, 0)]
        );
        {
            let compiled = eqs.compiled();
            let code = &compiled.0;
            let constant = code.blocks.iter().filter(|b| b.constant.is_some()).count();
            // junction stages, capacitor and resistors: every block but none
            assert_eq!(constant, code.blocks.len(), "constant blocks");
            // the n resistor efforts share the capacitor's effort gradient (one place)
            let shared = |s: &Src| {
                let same = code.slots.iter().filter(|o| o.span == s.span);
                same.count()
            };
            let most = code.slots.iter().map(shared).max().unwrap();
            assert_eq!(most, n + 1, "slots on one gradient");
        }
        // every probe against differences (the aliased efforts included)
        let names = eqs.probe_names();
        let probes: Vec<_> = names.iter().map(|p| eqs.probe(p).unwrap()).collect();
        let (mut a, mut out) = (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0));
        eqs.output_jacobian(0.0, &[0.8], &probes, &mut a, &mut out);
        for (k, name) in names.iter().enumerate() {
            let read = |q: f64| {
                eqs.evaluate(0.0, &[q]);
                eqs.read(probes[k], 0.0, &[q])
            };
            let fd = (read(0.8 + 1e-6) - read(0.8 - 1e-6)) / 2e-6;
            let err = (out[(k, 0)] - fd).abs() / fd.abs().max(1.0);
            assert!(err < 1e-7, "{name}: {} vs {fd}", out[(k, 0)]);
        }
    }
}
