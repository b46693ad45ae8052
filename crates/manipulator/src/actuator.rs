//! Linear actuators between two pins (eqs. 52–69, design page): length l(q) from the deformed
//! pin positions, and the matrix `τ_b = ∂l/∂q` of the MTF to the cylinders (eq. 66).
//!
//! An actuator acts along the line between its pins `a` (barrel end) and `b` (rod end); its
//! force F > 0 pushes them apart: `+F e` on b and `−F e` on a, with `e = (b − a)/l`. The
//! generalized force is `τ = Σ Pᵀ Π w` over the pins (eqs. 49, 67–68) with the wrench
//! `w = [R_0^i f; 0]` of the pin force at the pin in the pin link's frame — which is
//! `(∂l/∂q)ᵀ F` exactly, the MTF law `τ = τ_b F`, `l̇ = τ_bᵀ u` (eqs. 66, 69). The paper's
//! sine-rule expressions (eqs. 52–63) approximate the same exact distances to second order in
//! the deflection; here the distances are exact (design page).

use nalgebra::{DMatrix, DVector, Vector2};

use crate::arm::{PlanarArm, Pose};
use crate::error::ManipulatorError;
use crate::pin::{Pin, PinPoint};

/// A linear actuator (hydraulic cylinder) between pins `a` and `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearActuator {
    /// Barrel end.
    pub a: Pin,
    /// Rod end.
    pub b: Pin,
}

impl LinearActuator {
    /// An actuator from pin `a` to pin `b`.
    #[must_use]
    pub fn new(a: Pin, b: Pin) -> Self {
        Self { a, b }
    }
    /// Length `l = |b − a|` (m).
    #[must_use]
    pub fn length(&self, pose: &Pose<'_>) -> f64 {
        (pose.pin_position(&self.b) - pose.pin_position(&self.a)).norm()
    }
    /// Unit vector from a to b in frame 0 (the direction in which F pushes b).
    #[must_use]
    pub fn direction(&self, pose: &Pose<'_>) -> Vector2<f64> {
        let d = pose.pin_position(&self.b) - pose.pin_position(&self.a);
        d / d.norm()
    }
}

impl PlanarArm {
    /// Check an actuator's pins lie on the arm and are apart in the configuration `q`.
    pub fn check_actuator(&self, act: &LinearActuator, q: &[f64]) -> Result<(), ManipulatorError> {
        self.check_pin(&act.a)?;
        self.check_pin(&act.b)?;
        if q.len() != self.n() {
            return Err(ManipulatorError::shape(
                "q0",
                format!("needs {} values", self.n()),
            ));
        }
        let l = act.length(&self.pose(q));
        if !(l.is_finite() && l > 0.0) {
            return Err(ManipulatorError::invalid(
                "actuator length",
                l,
                "> 0: the pins coincide",
            ));
        }
        Ok(())
    }

    /// The generalized force `Pᵀ Π w = (∂r/∂q)ᵀ f` of a point force `f` (frame 0) at `pin`
    /// (eq. 49); zero for a ground pin.
    #[must_use]
    pub fn generalized_force(&self, pose: &Pose<'_>, pin: &Pin, f: &Vector2<f64>) -> DVector<f64> {
        let mut tau = DVector::zeros(self.n());
        if let Ok(p) = self.resolve_pin(pin) {
            pose.add_pin_force(&p, f, tau.as_mut_slice());
        }
        tau
    }

    /// `τ_b` (n × n_act) of eqs. 66–68: column c is the generalized force of a unit force in
    /// actuator c, which equals `∂l_c/∂q`.
    #[must_use]
    pub fn actuator_jacobian(&self, pose: &Pose<'_>, acts: &[LinearActuator]) -> DMatrix<f64> {
        let mut t = DMatrix::zeros(self.n(), acts.len());
        for (c, act) in acts.iter().enumerate() {
            if let (Ok(a), Ok(b)) = (self.resolve_pin(&act.a), self.resolve_pin(&act.b)) {
                let _ = pose.actuator_length(&a, &b, t.column_mut(c).as_mut_slice());
            }
        }
        t
    }
}

impl Pose<'_> {
    /// The length `l = |b − a|` of an actuator between resolved pins, with its gradient
    /// `∂l/∂q = (∂r_b/∂q − ∂r_a/∂q)ᵀ e` (e = (b − a)/l) written into `gradient` (length n):
    /// a column of τ_b (eqs. 66–68), without allocating.
    pub fn actuator_length(&self, a: &PinPoint, b: &PinPoint, gradient: &mut [f64]) -> f64 {
        let d = self.pin_point_position(b) - self.pin_point_position(a);
        let l = d.norm();
        let e = d / l;
        gradient.fill(0.0);
        self.add_pin_force(b, &e, gradient);
        self.add_pin_force(a, &-e, gradient);
        l
    }
}
