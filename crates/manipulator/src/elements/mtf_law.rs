//! The matrix-MTF law shared by the actuator and lumped-mass transformers, in the core's
//! convention (`bondgraph::MatrixTransformer`): `e₁ = T e₂`, `f_in₂ = −Tᵀ f_in₁`. Power is
//! conserved for every T: `e₁ᵀf_in₁ + e₂ᵀf_in₂ = e₂ᵀTᵀf_in₁ − e₂ᵀTᵀf_in₁ = 0`.

use bondgraph::{Io, LocalJacobian, Slot, Stage};
use nalgebra::DMatrix;

/// Stage 0 writes e₁ from e₂, stage 1 writes f₂ from f₁; both read the modulating signal
/// input 0.
pub(crate) fn stages() -> Vec<Stage> {
    vec![
        Stage {
            writes: vec![Slot::Effort(0)],
            reads: vec![Slot::Effort(1), Slot::Input(0)],
        },
        Stage {
            writes: vec![Slot::Flow(1)],
            reads: vec![Slot::Flow(0), Slot::Input(0)],
        },
    ]
}

/// `e₁ = T e₂` (as `bondgraph::apply_effort`: each row summed from column 0 on), by
/// columns: `acc` (length ≥ the rows of T, no allocation) takes every row's running sum.
pub(crate) fn set_effort(io: &mut Io<'_>, t: &DMatrix<f64>, acc: &mut [f64]) {
    let acc = &mut acc[..t.nrows()];
    times(t, io.effort(1), acc);
    for (i, &e) in acc.iter().enumerate() {
        io.set_e(0, i, e);
    }
}

/// `f_in₂ = −Tᵀ f_in₁` (as `bondgraph::apply_flow`: each column summed from row 0 on);
/// `acc` has length ≥ the columns of T (no allocation).
pub(crate) fn set_flow(io: &mut Io<'_>, t: &DMatrix<f64>, acc: &mut [f64]) {
    let acc = &mut acc[..t.ncols()];
    // f_in₁ = sign · (bond flow)
    transpose_times(t, io.flow(0), io.sign(0), acc);
    for (j, &f) in acc.iter().enumerate() {
        io.set_f_in(1, j, -f);
    }
}

/// `acc = T x`: `acc_i = Σ_j T_ij x_j` summed over j from 0 on (from −0, as `Iterator::sum`),
/// one contiguous column of T at a time.
fn times(t: &DMatrix<f64>, x: &[f64], acc: &mut [f64]) {
    acc.fill(-0.0);
    for (col, &xj) in t.as_slice().chunks_exact(t.nrows().max(1)).zip(x) {
        for (a, tij) in acc.iter_mut().zip(col) {
            *a += tij * xj;
        }
    }
}

/// `acc = Tᵀ (s x)`: `acc_j = Σ_i T_ij (s x_i)` summed over i from 0 on (from −0).
fn transpose_times(t: &DMatrix<f64>, x: &[f64], s: f64, acc: &mut [f64]) {
    for (a, col) in acc
        .iter_mut()
        .zip(t.as_slice().chunks_exact(t.nrows().max(1)))
    {
        let mut sum = -0.0;
        for (tij, xi) in col.iter().zip(x) {
            sum += tij * (s * xi);
        }
        *a = sum;
    }
}

/// `∂e₁/∂e₂ = T` (the modulation's partials are the caller's).
pub(crate) fn effort_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    bondgraph::effort_partials(jac, t);
}

/// `∂f_in₂/∂f_in₁ = −Tᵀ` (the modulation's partials are the caller's).
pub(crate) fn flow_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    bondgraph::flow_partials(jac, t);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn by_columns_gives_the_bits_of_the_row_sums() {
        let mut state = 0x0123_4567_89AB_CDEF_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            match state % 9 {
                0 => 0.0,
                1 => -0.0,
                _ => (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0,
            }
        };
        for rows in 1..=12 {
            for cols in 1..=7 {
                let t = DMatrix::from_fn(rows, cols, |_, _| next());
                let x: Vec<f64> = (0..cols).map(|_| next()).collect();
                let y: Vec<f64> = (0..rows).map(|_| next()).collect();
                let mut acc = vec![f64::NAN; rows.max(cols)];
                // as bondgraph::apply_effort and apply_flow (with io.f_in = sign · flow) sum
                times(&t, &x, &mut acc[..rows]);
                for (i, a) in acc[..rows].iter().enumerate() {
                    let want: f64 = (0..cols).map(|j| t[(i, j)] * x[j]).sum();
                    assert_eq!(a.to_bits(), want.to_bits());
                }
                for sign in [1.0, -1.0] {
                    transpose_times(&t, &y, sign, &mut acc[..cols]);
                    for (j, a) in acc[..cols].iter().enumerate() {
                        let want: f64 = (0..rows).map(|i| t[(i, j)] * (sign * y[i])).sum();
                        assert_eq!(a.to_bits(), want.to_bits());
                    }
                }
            }
        }
    }
}
