//! [`ArmKinematics`]: the projection matrix of every mass-carrying station at one
//! configuration, computed once and shared by M (eq. 42), E (eq. 44) and G (eq. 45).

use crate::arm::{PlanarArm, Pose, Station};
use crate::projection::Projection;

/// One mass-carrying station at a configuration: its projection and its inertia.
#[derive(Clone, Debug)]
pub(crate) struct MassPoint {
    pub(crate) projection: Projection,
    /// Mass (kg): `w·ρA` for a quadrature point, `m` for a point mass.
    pub(crate) mass: f64,
    /// Rotary inertia about z (kg·m²): `w·ρI`, or a point mass's own.
    pub(crate) inertia: f64,
    /// The station (link, x, mode values).
    pub(crate) station: Station,
}

/// The arm at configuration q with the projection matrix of each of its mass stations.
#[derive(Clone, Debug)]
pub struct ArmKinematics<'a> {
    pub(crate) pose: Pose<'a>,
    pub(crate) points: Vec<MassPoint>,
}

impl PlanarArm {
    /// Kinematics at `q` (projections of every quadrature point and point mass).
    ///
    /// # Panics
    /// If `q.len() != self.n()`.
    #[must_use]
    pub fn kinematics<'a>(&'a self, q: &'a [f64]) -> ArmKinematics<'a> {
        let pose = self.pose(q);
        let points = self
            .mass_stations()
            .iter()
            .map(|ms| MassPoint {
                projection: Projection::at(&pose, &ms.station),
                mass: ms.mass,
                inertia: ms.inertia,
                station: ms.station.clone(),
            })
            .collect();
        ArmKinematics { pose, points }
    }
}

impl<'a> ArmKinematics<'a> {
    /// The configuration.
    #[must_use]
    pub fn pose(&self) -> &Pose<'a> {
        &self.pose
    }
    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &'a PlanarArm {
        self.pose.arm()
    }
}
