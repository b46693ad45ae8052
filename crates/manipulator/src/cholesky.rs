//! The Cholesky factor `M = L Lᵀ` of a symmetric positive definite matrix, computed in a
//! buffer allocated once: one factorisation of the mass matrix per configuration serves
//! both `u = M⁻¹p` and `u̇ = M⁻¹(ṗ − Ṁu)` (eq. 43). Sizes are small (n ≤ ~25), so the plain
//! column-by-column algorithm is the right one.

use nalgebra::DMatrix;

/// A reusable Cholesky factorisation of an n×n matrix.
#[derive(Clone, Debug)]
pub(crate) struct Cholesky {
    n: usize,
    /// `U = Lᵀ`, column-major: column j holds row j of L, so every inner product below runs
    /// over contiguous memory. The strict lower triangle is not used.
    u: Vec<f64>,
    /// `1 / U[j, j]`: the solves multiply instead of dividing.
    inv_diag: Vec<f64>,
    ok: bool,
}

impl Cholesky {
    /// Room for n×n matrices.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            u: vec![0.0; n * n],
            inv_diag: vec![0.0; n],
            ok: false,
        }
    }

    /// Factor `m` (only its lower triangle is read); false if it is not positive definite.
    ///
    /// # Panics
    /// If `m` has another shape than the buffer.
    pub(crate) fn factor(&mut self, m: &DMatrix<f64>) -> bool {
        let n = self.n;
        assert_eq!(m.shape(), (n, n), "matrix of another size");
        self.ok = false;
        for j in 0..n {
            let tail = &mut self.u[j * n..];
            let col_j = &mut tail[..n];
            let d = m[(j, j)] - dot(&col_j[..j], &col_j[..j]);
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            let ujj = d.sqrt();
            col_j[j] = ujj;
            let inv = 1.0 / ujj;
            self.inv_diag[j] = inv;
            // U[j, i] = (M[i, j] − U[..j, i]·U[..j, j]) / U[j, j] for i > j (row j of U).
            for i in j + 1..n {
                let (left, right) = tail.split_at_mut((i - j) * n);
                let s = dot(&right[..j], &left[..j]);
                right[j] = (m[(i, j)] - s) * inv;
            }
        }
        self.ok = true;
        true
    }

    /// `b ← M⁻¹ b` with the last factor (NaN if it failed).
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) {
        self.solve_from(0, b);
    }

    /// Column k of M⁻¹ into `b` (length n).
    pub(crate) fn inverse_column(&self, k: usize, b: &mut [f64]) {
        b.fill(0.0);
        b[k] = 1.0;
        self.solve_from(k, b);
    }

    /// `b ← M⁻¹ b` for a `b` whose entries before `first` are +0: the forward substitution
    /// starts at `first`. The same numbers as from 0: the skipped entries stay +0, and the
    /// skipped products are zeros that change no sum (`0 − (±0) = +0` where all are zero).
    fn solve_from(&self, first: usize, b: &mut [f64]) {
        let n = self.n;
        if !self.ok {
            b.fill(f64::NAN);
            return;
        }
        // Uᵀ y = b
        for i in first..n {
            let col = &self.u[i * n..(i + 1) * n];
            b[i] = (b[i] - dot(&col[first..i], &b[first..i])) * self.inv_diag[i];
        }
        // U x = y
        for k in (0..n).rev() {
            let col = &self.u[k * n..(k + 1) * n];
            let xk = b[k] * self.inv_diag[k];
            b[k] = xk;
            for (bi, uik) in b[..k].iter_mut().zip(&col[..k]) {
                *bi -= uik * xk;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_positive_definite_system_and_refuses_an_indefinite_one() {
        let a = DMatrix::from_fn(5, 5, |i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let m = &a * a.transpose() + DMatrix::identity(5, 5);
        let x = nalgebra::DVector::from_fn(5, |i, _| i as f64 - 1.5);
        let mut b = (&m * &x).as_slice().to_vec();
        let mut c = Cholesky::new(5);
        assert!(c.factor(&m));
        c.solve_in_place(&mut b);
        for (got, want) in b.iter().zip(x.iter()) {
            assert!((got - want).abs() < 1e-13);
        }
        // a column of M⁻¹ by the shortened forward substitution: the same bits
        for k in 0..5 {
            let (mut full, mut short) = (vec![0.0; 5], vec![f64::NAN; 5]);
            full[k] = 1.0;
            c.solve_in_place(&mut full);
            c.inverse_column(k, &mut short);
            assert!(full
                .iter()
                .zip(&short)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        let mut bad = m.clone();
        bad[(2, 2)] = -1.0;
        assert!(!c.factor(&bad));
        c.solve_in_place(&mut b);
        assert!(b.iter().all(|v| v.is_nan()));
    }
}
