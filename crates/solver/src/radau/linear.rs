//! The linear algebra of a step: the Jacobian J and the two iteration matrices
//! (γ/h)I − J and ((α + iβ)/h)I − J, dense (our LU kernels, `crate::lu`) or sparse
//! (`crate::sparse`: refactorised on a stored pivot order, faer's pivoted sparse LU where
//! that order fails), chosen once per integrator.

use nalgebra::{Complex, DMatrix};

use super::OdeSystem;
use crate::lu::{ComplexLu, RealLu};
use crate::sparse::{SparseLu, SparsePattern};

/// Which linear algebra Radau's Newton iteration uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearAlgebra {
    /// Dense n×n Jacobian and LU (fastest for small or dense systems).
    Dense,
    /// The Jacobian on its sparsity pattern ([`OdeSystem::jacobian_pattern`]) and a sparse
    /// LU reusing its symbolic analysis; dense if the system gives no pattern.
    Sparse,
    /// Sparse when the system gives a pattern with at least [`SPARSE_MIN_STATES`] states and
    /// a density of at most [`SPARSE_MAX_DENSITY`], dense otherwise.
    #[default]
    Auto,
}

impl LinearAlgebra {
    /// From its name in a model file: `dense`, `sparse` or `auto`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "dense" => Some(Self::Dense),
            "sparse" => Some(Self::Sparse),
            "auto" => Some(Self::Auto),
            _ => None,
        }
    }
    /// The name [`Self::from_name`] reads.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Dense => "dense",
            Self::Sparse => "sparse",
            Self::Auto => "auto",
        }
    }
}

/// `Auto` uses the sparse path from this many states (the measured crossover: see
/// docs/performance.md).
pub const SPARSE_MIN_STATES: usize = 120;
/// `Auto` uses the sparse path only for Jacobians at most this dense (stored entries / n²).
pub const SPARSE_MAX_DENSITY: f64 = 0.2;

/// The matrices of the chosen path.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
pub(super) enum Linear {
    Dense {
        jac: DMatrix<f64>,
        real: RealLu,
        complex: ComplexLu,
    },
    Sparse(Box<Sparse>),
}

#[derive(Clone)]
pub(super) struct Sparse {
    pattern: SparsePattern,
    /// J on the pattern's slots.
    values: Vec<f64>,
    /// Scratch for systems that only give a dense Jacobian (empty until then).
    dense: DMatrix<f64>,
    real: SparseLu<f64>,
    complex: SparseLu<Complex<f64>>,
}

impl std::fmt::Debug for Linear {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Dense { jac, .. } => write!(f, "Dense({}×{})", jac.nrows(), jac.ncols()),
            Self::Sparse(s) => write!(
                f,
                "Sparse(n = {}, nnz = {}, L+U nnz = {}/{}, real {:?}, complex {:?})",
                s.pattern.n(),
                s.pattern.nnz(),
                s.real.factor_nnz(),
                s.complex.factor_nnz(),
                s.real.counts(),
                s.complex.counts()
            ),
        }
    }
}

impl Linear {
    /// The path `choice` gives for `sys`.
    pub(super) fn new(sys: &impl OdeSystem, n: usize, choice: LinearAlgebra) -> Self {
        let pattern = match choice {
            LinearAlgebra::Dense => None,
            LinearAlgebra::Sparse => sys.jacobian_pattern(),
            LinearAlgebra::Auto if n >= SPARSE_MIN_STATES => sys
                .jacobian_pattern()
                .filter(|p| p.density() <= SPARSE_MAX_DENSITY),
            LinearAlgebra::Auto => None,
        };
        let sparse = pattern.filter(|p| p.n() == n).and_then(|pattern| {
            let real = SparseLu::new(&pattern).ok()?;
            let complex = SparseLu::new(&pattern).ok()?;
            Some(Sparse {
                values: vec![0.0; pattern.nnz()],
                pattern,
                dense: DMatrix::zeros(0, 0),
                real,
                complex,
            })
        });
        match sparse {
            Some(s) => Self::Sparse(Box::new(s)),
            None => Self::Dense {
                jac: DMatrix::zeros(n, n),
                real: RealLu::new(n),
                complex: ComplexLu::new(n),
            },
        }
    }

    /// Whether the sparse path is in use.
    pub(super) fn is_sparse(&self) -> bool {
        matches!(self, Self::Sparse(_))
    }

    /// Evaluate J at (t, y).
    pub(super) fn jacobian(&mut self, sys: &mut impl OdeSystem, t: f64, y: &[f64], fy: &[f64]) {
        match self {
            Self::Dense { jac, .. } => sys.jacobian(t, y, fy, jac),
            Self::Sparse(s) => {
                sys.jacobian_sparse(t, y, fy, &s.pattern, &mut s.values, &mut s.dense);
            }
        }
    }

    /// Form and factorise (γ/h)I − J and ((α + iβ)/h)I − J; `Err` if either is singular.
    pub(super) fn factorise(&mut self, gamma: f64, shift: Complex<f64>) -> Result<(), ()> {
        match self {
            Self::Dense { jac, real, complex } => {
                let jac = jac.as_slice();
                real.set_shifted(gamma, jac);
                real.factor().map_err(|_| ())?;
                complex.set_shifted(shift, jac);
                complex.factor().map_err(|_| ())
            }
            Self::Sparse(s) => {
                s.real
                    .factor(&s.pattern, gamma, &s.values)
                    .map_err(|_| ())?;
                s.complex
                    .factor(&s.pattern, shift, &s.values)
                    .map_err(|_| ())
            }
        }
    }

    /// Solve with the real matrix in place.
    pub(super) fn solve_real(&mut self, b: &mut [f64]) {
        match self {
            Self::Dense { real, .. } => real.solve(b),
            Self::Sparse(s) => s.real.solve(b),
        }
    }

    /// Solve with the complex matrix in place, b = re + i·im.
    pub(super) fn solve_complex(&mut self, re: &mut [f64], im: &mut [f64]) {
        match self {
            Self::Dense { complex, .. } => complex.solve(re, im),
            Self::Sparse(s) => s.complex.solve(re, im),
        }
    }
}
