//! # bg-solver: stiff integration of dy/dt = f(t, y)
//!
//! The integrator and its linear algebra, knowing nothing of bond graphs: a problem is
//! anything that implements the small [`OdeSystem`] trait (its size, f(t, y) and the
//! Jacobian ∂f/∂y). `bondgraph` implements it for its state equations and re-exports this
//! crate's [`radau`] module, so `bondgraph::radau::…` names the same items.
//!
//! - [`problem`]: the [`OdeSystem`] trait.
//! - [`radau`]: Radau IIA of order 5 ([`Radau5`]): one step at a time towards stop times,
//!   dense output, restarts, its step-size control and tableau.
//! - `lu` (private): the dense LU kernels of Radau's real and complex iteration matrices.
//! - `sparse` (private but for [`SparsePattern`]): the sparse LU of the same matrices
//!   (KLU's scheme: refactorised on a stored pivot order, faer's pivoted LU where it fails).

mod lu;
pub mod problem;
pub mod radau;
mod sparse;

pub use problem::{OdeSystem, SparsePattern};
pub use radau::{LinearAlgebra, Radau5, RadauError, RadauOptions, RadauStats, StepReport};
