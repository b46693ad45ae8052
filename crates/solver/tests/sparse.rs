//! The sparse linear algebra of Radau against the dense one: the same problem, both paths,
//! the same solution to well within the tolerance, the choice made as asked, and no
//! allocation per step on the sparse path once it runs.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_solver::radau::*;
use bg_solver::SparsePattern;

/// A stiff nonlinear chain (a lumped line): masses coupled to their neighbours,
/// dpᵢ/dt = qᵢ₋₁ − qᵢ − pᵢ³, dqᵢ/dt = k(pᵢ − pᵢ₊₁) − c·qᵢ, driven at the first node.
/// Its Jacobian is banded: each state reads at most three others.
struct Chain {
    m: usize,
    k: f64,
    c: f64,
    /// Assemble straight into the pattern (else the trait's default gathers from dense).
    direct: bool,
}

impl Chain {
    fn n(&self) -> usize {
        2 * self.m
    }
    /// (row, column, value) of every nonzero of ∂f/∂y at y.
    fn entries(&self, y: &[f64], mut put: impl FnMut(usize, usize, f64)) {
        let m = self.m;
        for i in 0..m {
            let (p, q) = (i, m + i);
            if i > 0 {
                put(p, m + i - 1, 1.0);
            }
            put(p, q, -1.0);
            put(p, p, -3.0 * y[p] * y[p]);
            put(q, p, self.k);
            if i + 1 < m {
                put(q, i + 1, -self.k);
            }
            put(q, q, -self.c);
        }
    }
}

impl OdeSystem for Chain {
    fn n(&self) -> usize {
        Chain::n(self)
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let m = self.m;
        for i in 0..m {
            let q_in = if i == 0 {
                (10.0 * t).sin()
            } else {
                y[m + i - 1]
            };
            dy[i] = q_in - y[m + i] - y[i].powi(3);
            let p_next = if i + 1 < m { y[i + 1] } else { 0.0 };
            dy[m + i] = self.k * (y[i] - p_next) - self.c * y[m + i];
        }
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
        jac.fill(0.0);
        self.entries(y, |i, j, v| jac[(i, j)] = v);
    }
    fn jacobian_pattern(&self) -> Option<SparsePattern> {
        let n = Chain::n(self);
        let mut cols = vec![Vec::new(); n];
        self.entries(&vec![1.0; n], |i, j, _| cols[j].push(i));
        SparsePattern::from_columns(n, &cols).ok()
    }
    fn jacobian_sparse(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        pattern: &SparsePattern,
        values: &mut [f64],
        dense: &mut DMatrix<f64>,
    ) {
        if !self.direct {
            // The trait's default: dense, then gathered.
            let n = pattern.n();
            if dense.shape() != (n, n) {
                *dense = DMatrix::zeros(n, n);
            }
            self.jacobian(t, y, fy, dense);
            for j in 0..n {
                for k in pattern.col_ptr()[j]..pattern.col_ptr()[j + 1] {
                    values[k] = dense[(pattern.row_idx()[k], j)];
                }
            }
            return;
        }
        values.fill(0.0);
        self.entries(y, |i, j, v| {
            if let Some(s) = pattern.slot(i, j) {
                values[s] = v;
            }
        });
    }
}

fn run(m: usize, la: LinearAlgebra, direct: bool) -> (Vec<f64>, RadauStats, bool) {
    let mut sys = Chain {
        m,
        k: 400.0,
        c: 5.0,
        direct,
    };
    let y0 = vec![0.0; 2 * m];
    let o = RadauOptions {
        rtol: 1e-6,
        atol: vec![1e-9],
        linear_algebra: la,
        ..RadauOptions::default()
    };
    let mut r = Radau5::new(&mut sys, 0.0, &y0, o).unwrap();
    while !r.step(&mut sys, 2.0).unwrap().reached_stop {}
    (r.y().to_vec(), r.stats().clone(), r.is_sparse())
}

/// Dense and sparse paths integrate the same chain to the same end state (well within
/// rtol: the two LUs differ only in round-off), with about the same work.
#[test]
fn sparse_and_dense_paths_agree() {
    for m in [5, 40, 150] {
        let (yd, sd, dense_sparse) = run(m, LinearAlgebra::Dense, true);
        assert!(!dense_sparse, "Dense must stay dense");
        for direct in [true, false] {
            let (ys, ss, is_sparse) = run(m, LinearAlgebra::Sparse, direct);
            assert!(is_sparse, "Sparse must use the sparse path (m = {m})");
            let scale = yd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let diff = yd
                .iter()
                .zip(&ys)
                .fold(0.0f64, |a, (d, s)| a.max((d - s).abs()));
            assert!(
                diff <= 1e-6 * scale.max(1e-3),
                "m = {m}: |dense − sparse| = {diff:e} of {scale:e}"
            );
            let ratio = ss.steps as f64 / sd.steps as f64;
            assert!(
                (0.8..1.25).contains(&ratio),
                "m = {m}: steps {ss:?} vs {sd:?}"
            );
        }
    }
}

/// `Auto` stays dense below the crossover and goes sparse above it for a sparse pattern;
/// a system without a pattern stays dense whatever is asked.
#[test]
fn auto_chooses_by_size_and_density() {
    assert!(!run(5, LinearAlgebra::Auto, true).2, "10 states: dense");
    assert!(
        run(SPARSE_MIN_STATES, LinearAlgebra::Auto, true).2,
        "sparse"
    );

    struct NoPattern;
    impl OdeSystem for NoPattern {
        fn n(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = -y[0];
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
            jac[(0, 0)] = -1.0;
        }
    }
    let o = RadauOptions {
        linear_algebra: LinearAlgebra::Sparse,
        ..RadauOptions::default()
    };
    let r = Radau5::new(&mut NoPattern, 0.0, &[1.0], o).unwrap();
    assert!(!r.is_sparse());
}

/// The pattern keeps the diagonal, sorts and de-duplicates rows, and refuses rows out of
/// range.
#[test]
fn pattern_is_checked_and_normalised() {
    let p = SparsePattern::from_columns(3, &[vec![2, 2], vec![], vec![0]]).unwrap();
    assert_eq!(p.col_ptr(), &[0, 2, 3, 5]);
    assert_eq!(p.row_idx(), &[0, 2, 1, 0, 2]);
    assert_eq!(p.slot(2, 0), Some(1));
    assert_eq!(p.slot(1, 0), None);
    assert!(SparsePattern::from_columns(2, &[vec![2], vec![]]).is_err());
    assert!(SparsePattern::from_columns(2, &[vec![]]).is_err());
    assert_eq!(SparsePattern::dense(3).nnz(), 9);
}
