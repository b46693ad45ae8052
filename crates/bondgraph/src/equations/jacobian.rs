//! The exact Jacobian ∂f/∂x, assembled through the evaluation plan (forward mode).
//!
//! The plan is evaluated in `rhs` order while every effort, flow and signal scalar carries its
//! gradient with respect to x. After a stage is evaluated, the gradients of the scalars it
//! wrote follow by the chain rule from its local partials ([`Element::stage_partials`]) and
//! the gradients of its columns; the state-derivative rows follow likewise from
//! [`Element::derivative_partials`]. An element that gives no partials is differenced
//! *locally*: each scalar its stage reads (or, for the derivatives, every port variable,
//! input and own state) is perturbed, only that stage is re-run, and the difference of its
//! writes is chained like an analytic partial.
//!
//! The chain rule is compiled once (`compile`): each gradient is stored on its sparsity
//! pattern (the states it depends on), and each entry of a local block becomes a run of
//! `gradient[d] += value · gradient[s]` updates in a flat list. A Jacobian is then one pass
//! of the plan and of that list (`pass`); it writes a dense matrix or the values of a
//! sparse pattern (`sparse`) alike, and allocates nothing. Nothing in it is n wide: the
//! work of a Jacobian is the number of nonzero partials times the pattern sizes they carry.
//!
//! - `compile`: the plan of updates, gradient patterns, local-block structures.
//! - `constant`: the partials of elements that say they are constant, asked for once.
//! - `layout`: a block's shape, rows and cells before it is compiled.
//! - `pass`: one pass of the plan carrying gradients, local differences.
//! - `sparse`: the sparsity pattern and the sparse target.
//! - `outputs`: ∂y/∂x and ∂y/∂u of any probe (linearisation).

use std::cell::RefMut;

use bg_solver::SparsePattern;
use nalgebra::DMatrix;

mod compile;
mod constant;
mod layout;
mod outputs;
mod pass;
mod sparse;

pub(super) use compile::Compiled;
use pass::{Pass, Work};

use super::StateEquations;

/// The compiled Jacobian of the `rhs` plan and its buffers, made by the first call.
#[derive(Debug, Default)]
pub(super) struct JacobianState {
    compiled: Option<(Compiled, Work)>,
}

/// Where the derivative rows go.
enum Out<'a> {
    Dense(&'a mut DMatrix<f64>),
    Sparse(&'a SparsePattern, &'a mut [f64]),
}

impl StateEquations {
    /// The Jacobian compiled for the `rhs` plan (at t = 0 and the initial state, the first
    /// time it is asked for) and its work buffers.
    fn compiled(&self) -> RefMut<'_, (Compiled, Work)> {
        RefMut::map(self.jac.borrow_mut(), |j| {
            j.compiled.get_or_insert_with(|| {
                let c = self.compile(&self.rhs_order, &[], 0.0, &self.initial_state(), None);
                let w = Work::new(&c, &self.states);
                (c, w)
            })
        })
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
    /// One pass over the plan (the cost of about one `rhs`), plus one multiply-add per
    /// nonzero local partial and state its column depends on, plus one or two
    /// re-evaluations of a stage per scalar it reads for every element that gives no
    /// partials. Allocates only on the first call.
    pub fn jacobian(&self, t: f64, x: &[f64], jac: &mut DMatrix<f64>) {
        let n = self.states.len();
        if jac.shape() != (n, n) {
            *jac = DMatrix::zeros(n, n);
        }
        // the storage as one slice: a memset, not nalgebra's element iterator
        jac.as_mut_slice().fill(0.0);
        self.jacobian_into(t, x, &mut Out::Dense(jac));
    }

    /// One pass of the plan carrying gradients: the derivative rows into `out` (dense or on
    /// a sparse pattern). If an element set a partial outside the structure compiled for it
    /// (or switched between giving partials and not), the plan is compiled again at (t, x)
    /// with the wider structure and the pass repeated — allocating, once per such change.
    fn jacobian_into(&self, t: f64, x: &[f64], out: &mut Out<'_>) {
        let mut compiled = self.compiled();
        let (code, work) = &mut *compiled;
        let mut ws = self.ws.borrow_mut();
        if Pass::run(self, code, work, &mut ws, t, x) {
            drop(ws);
            let wider = self.compile(&self.rhs_order, &[], t, x, Some(code));
            *work = Work::new(&wider, &self.states);
            *code = wider;
            let mut ws = self.ws.borrow_mut();
            Pass::run(self, code, work, &mut ws, t, x);
        }
        pass::write_rows(code, work, out);
    }
}
