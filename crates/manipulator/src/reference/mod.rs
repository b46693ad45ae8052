//! [`ArmKinematics`]: the projection matrix of every mass-carrying station at one
//! configuration, computed once and shared by M (eq. 42), E (eq. 44), G (eq. 45) and the
//! reaction forces.
//!
//! The I-, C-field and reaction block of one arm all evaluate at the same q in one
//! right-hand-side evaluation, so the arm keeps the projections of the configuration it was
//! last asked for and hands them out again for the same q (compared bit for bit).

use std::sync::Arc;

use crate::arm::{PlanarArm, Pose, Station};
use crate::projection::Projection;

/// One mass-carrying station at a configuration: its projection and its inertia.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MassPoint<'a> {
    pub(crate) projection: &'a Projection,
    /// Mass (kg): `w·ρA` for a quadrature point, `m` for a point mass.
    pub(crate) mass: f64,
    /// Rotary inertia about z (kg·m²): `w·ρI`, or a point mass's own.
    pub(crate) inertia: f64,
    /// The station (link, x, mode values).
    pub(crate) station: &'a Station,
}

/// The projections of the last configuration an arm was asked for.
pub(crate) type ProjectionCache = Option<(Vec<f64>, Arc<Vec<Projection>>)>;

/// The arm at configuration q with the projection matrix of each of its mass stations.
#[derive(Clone, Debug)]
pub struct ArmKinematics<'a> {
    pub(crate) pose: Pose<'a>,
    projections: Arc<Vec<Projection>>,
}

impl PlanarArm {
    /// Kinematics at `q` (projections of every quadrature point and point mass).
    ///
    /// # Panics
    /// If `q.len() != self.n()`.
    #[must_use]
    pub fn kinematics<'a>(&'a self, q: &'a [f64]) -> ArmKinematics<'a> {
        let pose = self.pose(q);
        // A poisoned cache only means another thread panicked while filling it: refill it.
        let mut cache = self
            .projection_cache()
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let projections = match cache.as_ref() {
            Some((key, p)) if key.as_slice() == q => p.clone(),
            _ => {
                let p: Arc<Vec<Projection>> = Arc::new(
                    self.mass_stations()
                        .iter()
                        .map(|ms| Projection::at(&pose, &ms.station))
                        .collect(),
                );
                *cache = Some((q.to_vec(), p.clone()));
                p
            }
        };
        ArmKinematics { pose, projections }
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
    /// Every mass-carrying station with its projection.
    pub(crate) fn points(&self) -> impl Iterator<Item = MassPoint<'_>> {
        self.arm()
            .mass_stations()
            .iter()
            .zip(self.projections.iter())
            .map(|(ms, projection)| MassPoint {
                projection,
                mass: ms.mass,
                inertia: ms.inertia,
                station: &ms.station,
            })
    }
}
