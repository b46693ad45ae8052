//! The problem the integrators solve, dy/dt = f(t, y): a small trait, knowing nothing of
//! where the equations come from (the way diffsol separates its `OdeEquations` from its
//! methods). `bondgraph` implements it for its state equations.

/// The dense Jacobian's matrix type, re-exported so that implementing [`OdeSystem`] needs no
/// direct dependency on nalgebra.
pub use nalgebra::DMatrix;

/// What the integrator needs from the equations dy/dt = f(t, y).
pub trait OdeSystem {
    /// Number of states.
    fn n(&self) -> usize;
    /// dy = f(t, y).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    /// The dense Jacobian ∂f/∂y at (t, y) into the n×n `jac`. `fy` = f(t, y), already
    /// evaluated, for finite differences (which then cost n right-hand sides, not n + 1).
    fn jacobian(&mut self, t: f64, y: &[f64], fy: &[f64], jac: &mut DMatrix<f64>);
}
