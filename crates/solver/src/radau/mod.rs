//! Radau IIA with 3 stages (order 5, L-stable): the stiff integrator of Hairer and Wanner's
//! RADAU5, written from its description in E. Hairer, G. Wanner, *Solving Ordinary
//! Differential Equations II*, 2nd ed., Springer 1996, section IV.8.
//!
//! # The method
//! Collocation at the Radau points, with the Butcher tableau
//! ```text
//!  c            | A
//!  (4−√6)/10    | (88−7√6)/360       (296−169√6)/1800   (−2+3√6)/225
//!  (4+√6)/10    | (296+169√6)/1800   (88+7√6)/360       (−2−3√6)/225
//!  1            | (16−√6)/36         (16+√6)/36         1/9
//!  -------------+-------------------------------------------------------
//!  b            | (16−√6)/36         (16+√6)/36         1/9
//! ```
//! It is stiffly accurate (y₁ = Y₃). With zᵢ = Yᵢ − y₀ the stage equations are
//! Z = h(A⊗I)F(Z). One step:
//!
//! 1. **Simplified Newton**, transformed by T with T⁻¹A⁻¹T = diag(γ, [[α, −β], [β, α]])
//!    (γ ≈ 3.6378, α ± iβ ≈ 2.6811 ± 3.0504i): each iteration solves one real system with
//!    (γ/h)I − J and one complex system with ((α + iβ)/h)I − J, both n×n, from one LU each.
//!    J is the Jacobian at the step's start.
//! 2. **Starting values** from the previous step's collocation polynomial, extrapolated.
//! 3. **Convergence**: the rate θ = ‖ΔWₖ‖/‖ΔWₖ₋₁‖ (geometric mean after the second
//!    iteration); stop when η‖ΔWₖ‖ ≤ κ with η = θ/(1 − θ) (at the first iteration, η from the
//!    previous step, to the power 0.8). Give up, shrinking h, when θ ≥ 0.99, when the iteration
//!    limit is reached, or when the predicted error after the remaining iterations still
//!    exceeds κ.
//! 4. **Error estimate** from the embedded order-3 formula (weight γ₀ = 1/γ on f(t₀, y₀)),
//!    filtered: err = ((γ/h)I − J)⁻¹(f(t₀, y₀) + Σₖ dₖzₖ/h). On the first step and after a
//!    rejection an estimate ≥ 1 is filtered a second time, with f(t₀, y₀ + err).
//! 5. **Step size**: h_new = h / clamp(err^(1/4)/fac, 1/8, 5), fac = 0.9·(2k_max + 1)/(k + 2k_max)
//!    for k Newton iterations, and Gustafsson's predictive controller on accepted steps.
//! 6. **Reuse**: the Jacobian is kept across steps while Newton converges fast (θ ≤ 0.001 by
//!    default); it is recomputed after a slow convergence, or after a failure or rejection
//!    unless it is already current. The LU factors are kept when the proposed h_new/h lies in
//!    [1, 1.2] (h is then left unchanged).
//!
//! # Tolerances
//! A step is accepted when the RMS of errᵢ/(atolᵢ + rtol·max(|y₀ᵢ|, |y₁ᵢ|)) is at most 1. The
//! tolerances are not transformed (RADAU5 replaces rtol by 0.1·rtol^(2/3)): rtol bounds the
//! local error *estimate* of the order-3 embedded formula, which over-estimates the error of
//! the order-5 solution, so for smooth problems the global error is usually at or below rtol
//! and falls faster than rtol (the tests measure it).
//!
//! The Jacobian threshold θ ≤ 0.001 suits cheap analytic Jacobians; with finite-difference
//! Jacobians (n right-hand sides each) set [`RadauOptions::jacobian_theta`] to about 0.1,
//! which trades Jacobians for a few more Newton iterations.
//!
//! # Using it
//! [`Radau5::new`], then [`Radau5::step`] in a loop towards a stop time (an event or the end),
//! [`Radau5::interpolate`] for output and root location inside the last step, and
//! [`Radau5::restart`] after a discontinuity. Integration runs forward in time only.
//!
//! ```
//! use bg_solver::radau::{OdeSystem, Radau5, RadauOptions};
//! use nalgebra::DMatrix;
//!
//! /// y' = −k·y, with k switched by the caller.
//! struct Decay { k: f64 }
//! impl OdeSystem for Decay {
//!     fn n(&self) -> usize { 1 }
//!     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) { dy[0] = -self.k * y[0]; }
//!     fn jacobian(&mut self, _t: f64, _y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
//!         jac[(0, 0)] = -self.k;
//!     }
//! }
//!
//! let mut sys = Decay { k: 1.0 };
//! let options = RadauOptions { rtol: 1e-8, atol: vec![1e-12], ..RadauOptions::default() };
//! let mut radau = Radau5::new(&mut sys, 0.0, &[1.0], options)?;
//! let mut y_half = [0.0];
//! for (t_stop, k_after) in [(1.0, 10.0), (2.0, 10.0)] {
//!     // Step onto the event (or the end); output rows come from the dense output.
//!     while !radau.step(&mut sys, t_stop)?.reached_stop {
//!         if (radau.t_prev()..=radau.t()).contains(&0.5) {
//!             radau.interpolate(0.5, &mut y_half)?;
//!         }
//!     }
//!     sys.k = k_after; // the event: a parameter switch
//!     radau.restart(None)?;
//! }
//! assert!((y_half[0] - (-0.5f64).exp()).abs() < 1e-7);
//! assert!((radau.y()[0] - (-1.0f64 - 10.0).exp()).abs() < 1e-9);
//! # Ok::<(), bg_solver::radau::RadauError>(())
//! ```
//!
//! # Files
//! `tableau.rs` derives every constant from A and c; `integrator.rs` sets up, steps,
//! interpolates and restarts; the LU is the crate's `lu/` (dense storage,
//! numerically found zeros skipped, complex on separate real/imaginary planes); `stages.rs`
//! does one attempt (factorisation, Newton, error estimate, collocation polynomial);
//! `controller.rs` chooses step sizes; `error.rs` holds [`RadauError`].
//!
//! # Allocation
//! None after [`Radau5::new`]: every buffer, both LU factorisations and the Jacobian matrix
//! are allocated once. The LU is our own (partial pivoting, in place on preallocated
//! column-major storage, `lu.rs`), because nalgebra's `LU::new` takes the matrix by value and
//! allocates its permutation on every call. Checked with a counting allocator: 0 allocations
//! in 1 169 steps, 3 restarts and 1 169 interpolations of Van der Pol.

mod controller;
mod error;
mod integrator;
mod linear;
mod sensitivity;
mod stages;
mod tableau;

/// The Jacobian's matrix type, re-exported so that implementing [`OdeSystem`] needs no
/// direct dependency on nalgebra.
pub use crate::problem::DMatrix;

use controller::Controller;
pub use error::RadauError;
pub use sensitivity::{Sensitivities, SensitivityRhs};
use tableau::Tableau;

pub use crate::problem::{OdeSystem, SparsePattern};
use linear::Linear;
pub use linear::{LinearAlgebra, SPARSE_MAX_DENSITY, SPARSE_MIN_STATES};

/// Integrator settings.
#[derive(Clone, Debug)]
pub struct RadauOptions {
    /// Relative tolerance, in (0, 1): see the module doc for what it bounds.
    pub rtol: f64,
    /// Absolute tolerances, one per state, or a single value for all; each > 0.
    pub atol: Vec<f64>,
    /// First step size; `None` chooses one from f(t₀, y₀) and one more rhs evaluation.
    pub h0: Option<f64>,
    /// Largest step size.
    pub h_max: f64,
    /// Newton iterations per step before the step is retried smaller (RADAU5: 7).
    pub max_newton_iterations: usize,
    /// Newton stopping tolerance κ, relative to the error tolerance; `None`:
    /// max(10ε/rtol, min(0.03, √rtol)).
    pub newton_tol: Option<f64>,
    /// Convergence rate θ above which the Jacobian is recomputed for the next step (RADAU5:
    /// 0.001). Larger values (0.1) save Jacobians when they are expensive: on the knuckle-boom
    /// crane (38 states, finite-difference Jacobians) 0.1 needed 3–7× fewer Jacobians and
    /// ran 1.3–1.7× faster than 0.001 at rtol 1e-3 to 1e-6.
    pub jacobian_theta: f64,
    /// Dense or sparse Jacobian and LU, or chosen by size and density (the default).
    pub linear_algebra: LinearAlgebra,
}

impl Default for RadauOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: vec![1e-8],
            h0: None,
            h_max: f64::INFINITY,
            max_newton_iterations: 7,
            newton_tol: None,
            jacobian_theta: 0.001,
            linear_algebra: LinearAlgebra::Auto,
        }
    }
}

/// Work done so far.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RadauStats {
    /// Accepted steps.
    pub steps: usize,
    /// Steps rejected by the error test.
    pub rejected: usize,
    /// Right-hand-side evaluations by the integrator (not those inside `jacobian`).
    pub rhs_evaluations: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// Factorisations, each one real and one complex n×n LU.
    pub lu_decompositions: usize,
    /// Newton iterations (each costs 3 rhs evaluations and one real plus one complex solve).
    pub newton_iterations: usize,
    /// Steps retried smaller because Newton diverged, converged too slowly or hit a
    /// non-finite value.
    pub newton_failures: usize,
    /// Singular iteration matrices (the step is retried at half the size).
    pub singular: usize,
}

/// One accepted step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Start of the step.
    pub t_prev: f64,
    /// End of the step (the integrator's new time).
    pub t: f64,
    /// Whether the step ended exactly on `t_stop`.
    pub reached_stop: bool,
    /// Attempts rejected (error test, Newton, singular matrix) before this one was accepted.
    pub retries: usize,
}

/// Keep h (and the LU) when the controller proposes h_new/h in this band.
const KEEP_H: (f64, f64) = (1.0, 1.2);
/// Consecutive singular iteration matrices before giving up.
const MAX_SINGULAR: usize = 5;

/// What made the last attempt fail, for the error reported when h becomes too small.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Failure {
    ErrorTest,
    Newton,
}

/// The Radau IIA (order 5) integrator; see the module doc.
#[derive(Clone, Debug)]
pub struct Radau5 {
    n: usize,
    tab: Tableau,
    rtol: f64,
    atol: Vec<f64>,
    h_max: f64,
    nit: usize,
    fnewt: f64,
    thet: f64,

    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// f(t, y), valid when `f0_valid`.
    f0: Vec<f64>,
    f0_valid: bool,
    /// Step size of the next attempt.
    h: f64,
    /// Length of the last accepted step (scales the collocation polynomial).
    h_last: f64,
    /// Divided differences of the last step's collocation polynomial, in s = (t − t₁)/h.
    cont: [Vec<f64>; 3],
    has_poly: bool,

    z: [Vec<f64>; 3],
    w: [Vec<f64>; 3],
    fk: [Vec<f64>; 3],
    dw_real: Vec<f64>,
    /// Real and imaginary parts of the complex system's right-hand side and solution.
    dw_re: Vec<f64>,
    dw_im: Vec<f64>,
    ytmp: Vec<f64>,
    scal: Vec<f64>,
    err_v: Vec<f64>,
    err_f: Vec<f64>,

    /// The Jacobian and the two iteration matrices, dense or sparse.
    lin: Linear,
    /// The Jacobian was evaluated at the current (t, y).
    jac_current: bool,
    need_jac: bool,
    /// The step size the LU factors belong to.
    lu_h: Option<f64>,

    /// η of the Newton stopping test, carried from step to step.
    faccon: f64,
    /// Convergence rate of the last Newton iteration.
    theta: f64,
    /// Step-size controller.
    ctrl: Controller,
    /// The last attempt was rejected.
    reject: bool,

    stats: RadauStats,
}
