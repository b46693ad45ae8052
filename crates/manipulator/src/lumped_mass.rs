//! Lumped cylinder masses (section 4.2, Fig. 4) and their Jacobian `J_c` (eqs. 70–77).
//!
//! A lumped mass (a piston or a barrel) sits at a pin on a link. The scene chooses how it
//! moves: tied to its pin by an x/y spring–damper (the paper's model: its own momentum, the
//! spring and damper bonds 03/04, gravity bond 07), rigidly attached (then it is simply a
//! point mass of the link), or left out. For the springs, the pin velocities are
//! `J_c u` with `J_c = [N_c P_{0,h/h}^0]` stacked over the pins (eq. 71), `N_c = [0 I₂ 0]`
//! (eq. 72) picking the frame-0 linear velocity out of the frame-0 projection (eq. 73).

use nalgebra::DMatrix;

use crate::arm::{PlanarArm, Pose};
use crate::pin::{Pin, PinPoint};
use bondgraph::ParamError;

/// A point mass at a pin on a link.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LumpedMass {
    /// Where it sits (must be on a link).
    pub pin: Pin,
    /// Mass (kg), > 0.
    pub mass: f64,
}

impl PlanarArm {
    /// Check a lumped mass sits on a link and has a positive mass.
    pub fn check_lumped_mass(&self, m: &LumpedMass) -> Result<(), ParamError> {
        ParamError::positive("lumped mass", m.mass)?;
        match m.pin {
            Pin::Ground(_) => Err(ParamError::shape(
                "lumped mass",
                "a lumped mass on the ground does not move: leave it out",
            )),
            pin => self.check_pin(&pin),
        }
    }

    /// The velocity Jacobian of a pin in frame 0 (2×n; zero for a ground pin).
    #[must_use]
    pub fn pin_jacobian(&self, pose: &Pose<'_>, pin: &Pin) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(2, self.n());
        if let Ok(PinPoint::Station(s)) = self.resolve_pin(pin) {
            pose.point_jacobian(&s, |k, col| {
                j[(0, k)] = col.x;
                j[(1, k)] = col.y;
            });
        }
        j
    }

    /// `J_c` of eq. 71 (2m × n) for pins `pins`.
    #[must_use]
    pub fn lumped_mass_jacobian(&self, pose: &Pose<'_>, pins: &[Pin]) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(2 * pins.len(), self.n());
        for (k, pin) in pins.iter().enumerate() {
            j.rows_mut(2 * k, 2)
                .copy_from(&self.pin_jacobian(pose, pin));
        }
        j
    }
}
