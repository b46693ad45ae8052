//! Linear actuators between two pins (eqs. 52–69, docs/knuckle-boom.md): length l(q) from the deformed
//! pin positions, and the matrix `τ_b = ∂l/∂q` of the MTF to the cylinders (eq. 66).
//!
//! An actuator acts along the line between its pins `a` (barrel end) and `b` (rod end); its
//! force F > 0 pushes them apart: `+F e` on b and `−F e` on a, with `e = (b − a)/l`. The
//! generalized force is `τ = Σ Pᵀ Π w` over the pins (eqs. 49, 67–68) with the wrench
//! `w = [R_0^i f; 0]` of the pin force at the pin in the pin link's frame — which is
//! `(∂l/∂q)ᵀ F` exactly, the MTF law `τ = τ_b F`, `l̇ = τ_bᵀ u` (eqs. 66, 69). The paper's
//! sine-rule expressions (eqs. 52–63) approximate the same exact distances to second order in
//! the deflection; here the distances are exact (docs/knuckle-boom.md).

use nalgebra::{DMatrix, DVector, Vector2};

use crate::arm::{z_cross, PlanarArm, Pose};
use crate::pin::{Pin, PinPoint};
use bondgraph::ParamError;

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
    pub fn check_actuator(&self, act: &LinearActuator, q: &[f64]) -> Result<(), ParamError> {
        self.check_pin(&act.a)?;
        self.check_pin(&act.b)?;
        if q.len() != self.n() {
            return Err(ParamError::shape(
                "q0",
                format!("needs {} values", self.n()),
            ));
        }
        let l = act.length(&self.pose(q));
        if !(l.is_finite() && l > 0.0) {
            return Err(ParamError::invalid(
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
    /// a column of τ_b (eqs. 66–68), without allocating. A joint that turns both pins turns
    /// the actuator as a whole and leaves its length alone: its entry is exactly zero.
    pub fn actuator_length(&self, a: &PinPoint, b: &PinPoint, gradient: &mut [f64]) -> f64 {
        let (ra, rb) = (self.pin_point_position(a), self.pin_point_position(b));
        let d = rb - ra;
        let l = d.norm();
        let e = d / l;
        gradient.fill(0.0);
        for (j, g) in gradient.iter_mut().enumerate().take(self.arm().n_links()) {
            if !(turns(a, j) && turns(b, j)) {
                *g = e.dot(&self.pin_pair_joint_column(a, b, (&ra, &rb), j));
            }
        }
        self.pin_pair_mode_columns(a, b, |k, col| gradient[k] += e.dot(&col));
        l
    }

    /// `∂(r_b − r_a)/∂q_j` for joint j, with the pins at `(r_a, r_b)`: `ẑ × (r_b − r_a)` if it
    /// turns both pins, else the motion of the one it turns.
    pub(crate) fn pin_pair_joint_column(
        &self,
        a: &PinPoint,
        b: &PinPoint,
        (ra, rb): (&Vector2<f64>, &Vector2<f64>),
        j: usize,
    ) -> Vector2<f64> {
        let o = self.pivot(j);
        match (turns(a, j), turns(b, j)) {
            (true, true) => z_cross(&(rb - ra)),
            (false, true) => z_cross(&(rb - o)),
            (true, false) => -z_cross(&(ra - o)),
            (false, false) => Vector2::zeros(),
        }
    }

    /// `∂(r_b − r_a)/∂q^b_k` for the modes of the pins' links: `column(k, ±ψ_k R_i ŷ)`.
    pub(crate) fn pin_pair_mode_columns(
        &self,
        a: &PinPoint,
        b: &PinPoint,
        mut column: impl FnMut(usize, Vector2<f64>),
    ) {
        for (pin, sign) in [(b, 1.0), (a, -1.0)] {
            if let PinPoint::Station(s) = pin {
                let (c, sn) = self.cos_sin(s.link);
                let o = self.arm().modal_offset(s.link);
                for (k, psi) in s.psi.iter().enumerate() {
                    column(o + k, sign * psi * Vector2::new(-sn, c));
                }
                if self.arm().has_geometric_stiffening() {
                    self.shortening_columns(s, |k, col| column(k, sign * col));
                }
            }
        }
    }
}

/// Whether joint j turns the pin (a pin on link i is turned by the joints j ≤ i).
pub(crate) fn turns(pin: &PinPoint, j: usize) -> bool {
    pin.station().is_some_and(|s| j <= s.link)
}
