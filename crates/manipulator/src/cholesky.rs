//! The Cholesky factor `M = L Lᵀ` of a symmetric positive definite matrix, computed in a
//! buffer allocated once: one factorisation of the mass matrix per configuration serves
//! both `u = M⁻¹p` and `u̇ = M⁻¹(ṗ − Ṁu)` (eq. 43). Sizes are small (n ≤ ~25), so the plain
//! column-by-column algorithm is the right one.

use nalgebra::DMatrix;

/// A reusable Cholesky factorisation of an n×n matrix.
#[derive(Clone, Debug)]
pub(crate) struct Cholesky {
    /// The lower triangle holds L; the strict upper triangle is not used.
    l: DMatrix<f64>,
    ok: bool,
}

impl Cholesky {
    /// Room for n×n matrices.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            l: DMatrix::zeros(n, n),
            ok: false,
        }
    }

    /// Factor `m` (only its lower triangle is read); false if it is not positive definite.
    ///
    /// # Panics
    /// If `m` has another shape than the buffer.
    pub(crate) fn factor(&mut self, m: &DMatrix<f64>) -> bool {
        let n = self.l.nrows();
        assert_eq!(m.shape(), (n, n), "matrix of another size");
        self.ok = false;
        for j in 0..n {
            let mut d = m[(j, j)];
            for k in 0..j {
                d -= self.l[(j, k)] * self.l[(j, k)];
            }
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            let ljj = d.sqrt();
            self.l[(j, j)] = ljj;
            for i in j + 1..n {
                let mut s = m[(i, j)];
                for k in 0..j {
                    s -= self.l[(i, k)] * self.l[(j, k)];
                }
                self.l[(i, j)] = s / ljj;
            }
        }
        self.ok = true;
        true
    }

    /// `b ← M⁻¹ b` with the last factor (NaN if it failed).
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.l.nrows();
        if !self.ok {
            b.fill(f64::NAN);
            return;
        }
        for i in 0..n {
            let s: f64 = (0..i).map(|k| self.l[(i, k)] * b[k]).sum();
            b[i] = (b[i] - s) / self.l[(i, i)];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| self.l[(k, i)] * b[k]).sum();
            b[i] = (b[i] - s) / self.l[(i, i)];
        }
    }
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
        let mut bad = m.clone();
        bad[(2, 2)] = -1.0;
        assert!(!c.factor(&bad));
        c.solve_in_place(&mut b);
        assert!(b.iter().all(|v| v.is_nan()));
    }
}
