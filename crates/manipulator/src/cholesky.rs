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

/// `$sized::<N>(args)` for the sizes of the arms met in practice (n ≤ 16: the loops unrolled
/// with constant bounds), `$general(n, args)` above; the same operations in the same order.
macro_rules! sized {
    ($n:expr, $sized:ident, $general:ident, ($($arg:expr),*)) => {
        match $n {
            1 => $sized::<1>($($arg),*),
            2 => $sized::<2>($($arg),*),
            3 => $sized::<3>($($arg),*),
            4 => $sized::<4>($($arg),*),
            5 => $sized::<5>($($arg),*),
            6 => $sized::<6>($($arg),*),
            7 => $sized::<7>($($arg),*),
            8 => $sized::<8>($($arg),*),
            9 => $sized::<9>($($arg),*),
            10 => $sized::<10>($($arg),*),
            11 => $sized::<11>($($arg),*),
            12 => $sized::<12>($($arg),*),
            13 => $sized::<13>($($arg),*),
            14 => $sized::<14>($($arg),*),
            15 => $sized::<15>($($arg),*),
            16 => $sized::<16>($($arg),*),
            n => $general(n, $($arg),*),
        }
    };
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
        let (m, u, inv) = (m.as_slice(), &mut self.u[..], &mut self.inv_diag[..]);
        self.ok = sized!(n, factor_n, factor_impl, (m, u, inv));
        self.ok
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
    pub(crate) fn solve_from(&self, first: usize, b: &mut [f64]) {
        let n = self.n;
        if !self.ok {
            b.fill(f64::NAN);
            return;
        }
        let (u, inv) = (&self.u[..], &self.inv_diag[..]);
        sized!(n, solve_n, solve_impl, (u, inv, first, b));
    }
}

fn factor_n<const N: usize>(m: &[f64], u: &mut [f64], inv: &mut [f64]) -> bool {
    factor_impl(N, m, u, inv)
}

/// `M = UᵀU` column by column (`m` column-major n×n, lower triangle read): row j of U from
/// `U[j, j] = √(M[j, j] − U[..j, j]·U[..j, j])`, `U[j, i] = (M[i, j] − U[..j, i]·U[..j, j]) / U[j, j]`.
#[inline(always)]
fn factor_impl(n: usize, m: &[f64], u: &mut [f64], inv: &mut [f64]) -> bool {
    let (m, u, inv) = (&m[..n * n], &mut u[..n * n], &mut inv[..n]);
    for j in 0..n {
        let (head, tail) = u.split_at_mut((j + 1) * n);
        let col_j = &mut head[j * n..];
        let d = m[j * n + j] - dot(&col_j[..j], &col_j[..j]);
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let ujj = d.sqrt();
        col_j[j] = ujj;
        let r = 1.0 / ujj;
        inv[j] = r;
        let col_j = &col_j[..j];
        let m_j = &m[j * n..(j + 1) * n];
        // U[j, i] for i > j (row j of U, in column i)
        for (col_i, &mij) in tail.chunks_exact_mut(n).zip(&m_j[j + 1..]) {
            col_i[j] = (mij - dot(&col_i[..j], col_j)) * r;
        }
    }
    true
}

fn solve_n<const N: usize>(u: &[f64], inv: &[f64], first: usize, b: &mut [f64]) {
    solve_impl(N, u, inv, first, b);
}

/// `Uᵀ y = b` from `first` on, then `U x = y`, in place.
#[inline(always)]
fn solve_impl(n: usize, u: &[f64], inv: &[f64], first: usize, b: &mut [f64]) {
    let (u, inv, b) = (&u[..n * n], &inv[..n], &mut b[..n]);
    for i in first..n {
        let col = &u[i * n..i * n + i];
        b[i] = (b[i] - dot(&col[first..], &b[first..i])) * inv[i];
    }
    for k in (0..n).rev() {
        let col = &u[k * n..k * n + k];
        let xk = b[k] * inv[k];
        b[k] = xk;
        for (bi, uik) in b[..k].iter_mut().zip(col) {
            *bi -= uik * xk;
        }
    }
}

/// `Σ a_k b_k` summed from k = 0 on, as `Iterator::sum` does (from −0).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = -0.0;
    for (x, y) in a.iter().zip(b) {
        s += x * y;
    }
    s
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

    /// The factor and solves as written before the sized loops (left in as the reference).
    mod reference {
        use nalgebra::DMatrix;

        fn dot(a: &[f64], b: &[f64]) -> f64 {
            a.iter().zip(b).map(|(x, y)| x * y).sum()
        }

        pub(super) fn factor(m: &DMatrix<f64>, u: &mut [f64], inv_diag: &mut [f64]) -> bool {
            let n = m.nrows();
            for j in 0..n {
                let tail = &mut u[j * n..];
                let col_j = &mut tail[..n];
                let d = m[(j, j)] - dot(&col_j[..j], &col_j[..j]);
                if !(d > 0.0 && d.is_finite()) {
                    return false;
                }
                let ujj = d.sqrt();
                col_j[j] = ujj;
                let inv = 1.0 / ujj;
                inv_diag[j] = inv;
                for i in j + 1..n {
                    let (left, right) = tail.split_at_mut((i - j) * n);
                    let s = dot(&right[..j], &left[..j]);
                    right[j] = (m[(i, j)] - s) * inv;
                }
            }
            true
        }

        pub(super) fn solve_from(u: &[f64], inv_diag: &[f64], first: usize, b: &mut [f64]) {
            let n = inv_diag.len();
            for i in first..n {
                let col = &u[i * n..(i + 1) * n];
                b[i] = (b[i] - dot(&col[first..i], &b[first..i])) * inv_diag[i];
            }
            for k in (0..n).rev() {
                let col = &u[k * n..(k + 1) * n];
                let xk = b[k] * inv_diag[k];
                b[k] = xk;
                for (bi, uik) in b[..k].iter_mut().zip(&col[..k]) {
                    *bi -= uik * xk;
                }
            }
        }
    }

    /// xorshift64*: a uniform number in [−1, 1), now and then an exact ±0.
    fn next(state: &mut u64) -> f64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        let r = state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        match r % 13 {
            0 => 0.0,
            1 => -0.0,
            _ => (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0,
        }
    }

    fn same_bits(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn sized_loops_give_the_bits_of_the_plain_ones() {
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        // sizes with unrolled loops (1..=16) and the general path above
        for n in 1..=20 {
            for round in 0..25 {
                let a = DMatrix::from_fn(n, n, |_, _| next(&mut state));
                let mut m = &a * a.transpose() + DMatrix::identity(n, n) * (0.01 * round as f64);
                // junk in the upper triangle, which is not read
                for j in 1..n {
                    m[(0, j)] = f64::NAN;
                }
                if round == 24 && n > 2 {
                    m[(n - 2, n - 2)] = -1.0; // not positive definite
                }
                let (mut u, mut inv) = (vec![0.0; n * n], vec![0.0; n]);
                let want = reference::factor(&m, &mut u, &mut inv);
                let mut c = Cholesky::new(n);
                assert_eq!(c.factor(&m), want, "n = {n}, round {round}");
                if !want {
                    continue;
                }
                // the upper triangle (the strict lower one is not used)
                for j in 0..n {
                    assert!(same_bits(&c.u[j * n..=j * n + j], &u[j * n..=j * n + j]));
                }
                assert!(same_bits(&c.inv_diag, &inv));
                for first in 0..n {
                    let mut b: Vec<f64> = (0..n).map(|_| next(&mut state)).collect();
                    b[..first].fill(0.0);
                    let mut want = b.clone();
                    reference::solve_from(&u, &inv, first, &mut want);
                    c.solve_from(first, &mut b);
                    assert!(same_bits(&b, &want), "n = {n}, first = {first}");
                }
            }
        }
    }
}
